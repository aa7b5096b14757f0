"""Compile the numba kernels ahead of the first run (``install.sh`` calls ``python -m riskassess.warmup``).

numba keeps what it compiled in a disk cache keyed by the sources (:mod:`multibody.jit_cache`) and by the
checkout's folder, so a fresh install or clone compiles every kernel once. Left to the first run, that
is about 1 min of kernels compiled at import (their signatures are given: the towing and diagnosis
plants, the thrust laws) before any case is read, plus about 2 min for the impact path's kernels at
the first step (measured 2026-11-27 on one core: 62 s and 136 s). Doing it here, in two processes at
once (one per part, so neither compiles what the other does), moves that wait out of the first
``riskassess run`` and out of every test worker.

Parts:
- ``import``: imports the command-line interface and every case kind's schema and loader (the towing and
  diagnosis packages, which the CLI loads only for their own commands), which compiles every kernel with a
  stated signature;
- ``impact``: runs the shipped ``cases/envisat_small.toml`` for 0.06 s (the net's flight to the target
  plus one contact) into a temporary folder, without the diagnosis packages, which compiles the impact
  path's kernels (net step, contact, recorder row) with the types every impact case uses.

Nothing is written outside the user's numba cache and the system's temporary folder.
"""
from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The shipped case whose first steps compile the impact path (relative to the project folder).
WARMUP_CASE = Path("cases") / "envisat_small.toml"
#: Simulated time of the warm-up run (s): past the net's 0.05 s flight to the target, so contact runs.
WARMUP_END_TIME_S = 0.06
PARTS = ("import", "impact")


def compile_at_import() -> None:
    """Import the CLI and every case kind's schema and loader: the kernels with stated signatures compile now."""
    import riskassess.cli  # noqa: F401
    from riskassess.stages.kinds import KINDS, schema_and_loader

    for kind in KINDS:
        schema_and_loader(kind)


def compile_impact_path(project: Path) -> None:
    """Run the shipped small Envisat case for :data:`WARMUP_END_TIME_S` in a temporary folder.

    Parameters
    ----------
    project : Path
        The project folder (holds ``cases/``).
    """
    from riskassess.stages.run import run_case

    with tempfile.TemporaryDirectory(prefix="adr-warmup-") as tmp:
        case = Path(tmp) / WARMUP_CASE.name
        case.write_text(warmup_case_text(project))
        run_case(case, Path(tmp) / "out")


def warmup_case_text(project: Path) -> str:
    """The shipped :data:`WARMUP_CASE` with its ``end_time`` set to :data:`WARMUP_END_TIME_S`.

    Parameters
    ----------
    project : Path
        The project folder (holds ``cases/``).

    Returns
    -------
    str
        TOML text of the shortened case.
    """
    text = (project / WARMUP_CASE).read_text()
    text, count = re.subn(r"(?m)^end_time\s*=.*$", f"end_time = {WARMUP_END_TIME_S}", text)
    if count != 1:
        raise RuntimeError(f"{WARMUP_CASE}: expected one 'end_time = ...' line to shorten, found {count}")
    return text


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=PARTS, help="one part in this process (default: both, in parallel)")
    args = parser.parse_args(argv)
    project = Path(__file__).resolve().parents[1]
    if args.part == "import":
        compile_at_import()
        return 0
    if args.part == "impact":
        compile_impact_path(project)
        return 0
    start = time.perf_counter()
    print("compiling the numba kernels once (a few minutes on first install) ...", flush=True)
    children = [subprocess.Popen([sys.executable, "-m", "riskassess.warmup", "--part", part],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                for part in PARTS]
    failed = []
    for part, child in zip(PARTS, children):
        _, err = child.communicate()
        if child.returncode != 0:
            failed.append(part)
            print(f"warm-up part '{part}' failed (exit {child.returncode}); the first run will compile "
                  f"instead:\n{err[-2000:]}", file=sys.stderr)
    print(f"kernels compiled in {time.perf_counter() - start:.0f} s", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
