"""Capture-start full-net runs re-run with recorded attitudes against their older copies (issue 27): is every entry
the older copy also has bit-identical (``np.array_equal``), and how far is the attitude integrated from the sampled
body rates (:func:`bench_omega_frames.attitude_from_rates`, what ``bench_fullnet_identify.py --reconstruct-attitudes``
gives runs cached without attitudes) from the recorded one, per body (largest angle over the samples, deg).

    python bench/check_rerun_attitudes.py --new /work/runs/fullnet_capture_attitude \\
        --old /work/runs/fullnet_capture_held 26.29 27.26

Both folders are ``bench_fullnet_identify.py --out`` folders (``DIR/capture/fullnet/rate_<r>_end_<T>_capture.npz``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_omega_frames import attitude_from_rates  # noqa: E402

BODIES = ("chaser", "debris")     # the order of the start state's body_to_inertial


def run_file(folder, rate: str, end: int) -> Path:
    """Cached capture-start run of ``rate`` (deg/s, as written in the file name) in a bench --out ``folder``."""
    return Path(folder) / "capture" / "fullnet" / f"rate_{rate}_end_{end}_capture.npz"


def largest_attitude_error_deg(run, dt: float) -> dict:
    """Largest angle (deg) between the attitude integrated from the run's sampled body rates and the recorded one,
    per body (chaser, debris); ``dt`` the sample interval (s)."""
    errors = {}
    for index, body in enumerate(BODIES):
        recorded_to_inertial = run[f"{body}_to_inertial"]
        rebuilt_to_inertial = attitude_from_rates(run["start_body_to_inertial"][index], run[f"{body}_omega_body"], dt)
        relative = np.einsum("kji,kjl->kil", rebuilt_to_inertial, recorded_to_inertial)   # rebuilt^T recorded
        errors[body] = float(np.degrees(np.linalg.norm(Rotation.from_matrix(relative).as_rotvec(), axis=1)).max())
    return errors


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("rates", nargs="+", help="spin rates as in the file names (deg/s, e.g. 9.60)")
    parser.add_argument("--new", required=True, help="folder of the re-run runs (with attitudes)")
    parser.add_argument("--old", required=True, help="folder of the older copies")
    parser.add_argument("--end", type=int, default=300)
    parser.add_argument("--dt", type=float, default=0.1, help="sample interval (s), the case's output interval")
    args = parser.parse_args()
    for rate in args.rates:
        new, old = np.load(run_file(args.new, rate, args.end)), np.load(run_file(args.old, rate, args.end))
        common = [k for k in old.files if k in new.files and k != "wall_s"]
        differing = [k for k in common if not np.array_equal(new[k], old[k])]
        errors = largest_attitude_error_deg(new, args.dt)
        print(f"{rate} deg/s: {len(common)} common entries, differing: {', '.join(differing) or 'none'}; "
              f"attitude from rates vs recorded: chaser {errors['chaser']:.4f} deg, debris {errors['debris']:.4f} deg "
              f"(largest over {len(new['debris_to_inertial'])} samples)")


if __name__ == "__main__":
    main()
