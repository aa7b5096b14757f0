"""Every benchmark script still imports against the current packages (a layout move broke
bench/bench_impact.py once without any test noticing) and has a ``main`` to run."""
import importlib.util
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"


@pytest.mark.parametrize("script", sorted(BENCH.glob("*.py")), ids=lambda p: p.name)
def test_bench_script_imports(script):
    name = f"bench_{script.stem}"
    spec = importlib.util.spec_from_file_location(name, script)
    module = importlib.util.module_from_spec(spec)
    # registered as importlib's recipe does: a dataclass under "from __future__ import annotations" looks its
    # module up in sys.modules while the class is made
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)      # top level only: every script guards main()
    finally:
        sys.modules.pop(name, None)
    assert callable(getattr(module, "main", None)), f"{script.name} has no main()"


def test_step_refinement_springs_alone_is_minus_k_times_the_joint_offset():
    """bench_step_refinement.py's springs-alone reading: for a joint whose parent sits at rest at the origin and
    whose child is moved by a known offset and turned by a known rotation, the springs' load on the child is
    -k (offset, rotation) in the joint frame (Hooke's law, per axis; the joint frame here turned 90 deg about z
    from LVLH, so the offset's components swap)."""
    from types import SimpleNamespace

    import numpy as np

    spec = importlib.util.spec_from_file_location("bench_step_refinement", BENCH / "bench_step_refinement.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    turn_z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])      # joint frame in the parent body
    system = SimpleNamespace(joint_to_parent=[turn_z], joint_point_parent_body=[np.array([1.0, 0.0, 0.0])],
                             joint_point_child_body=[np.array([-1.0, 0.0, 0.0])])
    offset_lvlh = np.array([1e-3, -2e-3, 3e-3])
    series = {"body_com_lvlh": np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0] + offset_lvlh]]),
              "body_to_lvlh": np.array([[np.eye(3), np.eye(3)]]),
              "joint_rotation_joint": np.array([[[1e-4, -2e-4, 5e-5]]])}
    stiffness = np.array([[1e6, 2e6, 3e6, 1e5, 2e5, 3e5]])
    force, moment = module.elastic_reaction_joint(system, [(0, 1)], stiffness, series)
    offset_joint = turn_z.T @ offset_lvlh                      # (-2e-3, -1e-3, 3e-3)
    assert np.allclose(force[0, 0], -stiffness[0, :3] * offset_joint, rtol=1e-12, atol=0.0)
    assert np.allclose(moment[0, 0], -stiffness[0, 3:] * series["joint_rotation_joint"][0, 0], rtol=1e-12, atol=0.0)


def _bench_module(name):
    spec = importlib.util.spec_from_file_location(f"bench_{name}", BENCH / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        sys.modules.pop(spec.name, None)
    return module


def test_wrapping_level_hub_wrench_keeps_the_total_wrench():
    """bench_wrapping_level.py's ``hub_loads`` moves every body's contact onto the main body: statics says the total
    force and the total moment about any point are unchanged (here about the main body's CoM, checked to 1e-9
    relative on random loads, positions and attitudes), and the other bodies carry nothing."""
    import numpy as np

    module = _bench_module("bench_wrapping_level")
    rng = np.random.default_rng(3)
    k, nb = 4, 3
    q, r = np.linalg.qr(rng.normal(size=(k, nb, 3, 3)))
    to_lvlh = q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[..., None, :]    # orthonormal
    to_lvlh[..., 2] *= np.linalg.det(to_lvlh)[..., None]                      # proper rotations
    wall = {"contact_force_lvlh": rng.normal(size=(k, nb, 3)), "contact_moment_body": rng.normal(size=(k, nb, 3)),
            "body_to_lvlh": to_lvlh, "body_com_lvlh": rng.normal(size=(k, nb, 3))}
    force, moment_body = module.hub_wrench(wall, 1)
    com = wall["body_com_lvlh"][:, 1:2]
    moment_lvlh = np.einsum("kbij,kbj->kbi", to_lvlh, wall["contact_moment_body"])
    expected = (moment_lvlh + np.cross(wall["body_com_lvlh"] - com, wall["contact_force_lvlh"])).sum(axis=1)
    assert np.allclose(force.sum(axis=1), wall["contact_force_lvlh"].sum(axis=1), rtol=1e-9, atol=1e-12)
    assert np.allclose(np.einsum("kij,kj->ki", to_lvlh[:, 1], moment_body[:, 1]), expected, rtol=1e-9, atol=1e-12)
    assert not force[:, [0, 2]].any() and not moment_body[:, [0, 2]].any()


def test_wrapping_level_plot_band_reads_a_sine_amplitude():
    """The plot band (per 7.5 ms column the largest |value|) of a 50 Hz sine of amplitude 1.5 kN sampled at 40 kHz
    is its amplitude within 1 % in the median column (|sin| repeats every 10 ms, so 3 columns in 4 hold a peak and
    the others at least cos(pi / 8) = 0.92 of it), and 1 ms block means keep the sine's mean (0) and RMS (A / sqrt 2,
    less 0.4 % for the averaging) within 1 %."""
    import numpy as np

    module = _bench_module("bench_wrapping_level")
    t = np.arange(1, 300001) * 2.5e-5
    values = np.stack([1500.0 * np.sin(2 * np.pi * 50.0 * t)] * 3, axis=1)
    band = module.plot_band(t, values, (1.0, 7.5))
    assert abs(band["largest"][0] - 1500.0) < 15.0
    assert abs(band["median"][0] - 1500.0) < 15.0
    assert min(band["p90"]) >= 0.92 * 1500.0
    _, means = module.block_means(t, values, 1e-3)
    assert abs(means[:, 0].mean()) < 15.0
    assert abs(np.sqrt((means[:, 0] ** 2).mean()) - 1500.0 / np.sqrt(2)) < 0.01 * 1500.0 / np.sqrt(2)


def test_scan_to_map_constants_entry_is_checked_and_typed():
    """bench_scan_to_map.py --constants: an entry sets only the scan-to-map constants it names, each with the
    module's own type (an iteration cap stays an int), and a name the module does not tune is refused by name."""
    module = _bench_module("bench_scan_to_map")
    assert module._constants("") == {}
    chosen = module._constants("FINE_POINTS=2000, SETTLED=1e-3")
    assert chosen == {"FINE_POINTS": 2000, "SETTLED": 1e-3}
    assert isinstance(chosen["FINE_POINTS"], int)
    with pytest.raises(SystemExit, match="'FOO=1' is not NAME=VALUE"):
        module._constants("FOO=1")


def test_wrapping_level_scaled_wall_keeps_the_appendages_attached():
    """bench_wrapping_level.py's walls of another size: the main body's box x 4/3 (Envisat's full envelope) moves each
    appendage with its joint to the same place of the scaled surface (the ASAR mount on the -y face at y = -2.5 m,
    the array hinge 4/3 of its old offset), keeps each appendage's offsets from its joint, its masses, and scales
    the inertias by the factor squared; appendages x 0.75 shrink about their joints (the ASAR 7.5 x 1.125 m)."""
    import numpy as np

    module = _bench_module("bench_wrapping_level")
    case = module.item_case("nominal")
    big = module.scaled_target(case, 4.0 / 3.0, 1.0)
    bodies = {b.name: b for b in big.target.bodies}
    joints = {j.name: j for j in big.target.joints}
    old = {b.name: b for b in case.target.bodies}
    assert np.allclose(bodies["main_body"].shapes[0].size, [4.5, 5.0, 10.5])
    assert np.allclose(joints["asar_mount"].position, [0.0, -2.5, 0.0])
    assert np.allclose(bodies["asar"].shapes[0].center, [0.0, -2.5 - 0.078, 0.0])
    assert np.allclose(joints["solar_array_hinge"].position, [0.0, 0.0, 4.4375 * 4.0 / 3.0])
    assert np.allclose(np.array(bodies["solar_array"].center_of_mass) - joints["solar_array_hinge"].position,
                       [0.0, 0.0, 11.5875 - 4.4375])
    assert all(bodies[n].mass == old[n].mass for n in bodies)
    assert np.allclose(bodies["main_body"].inertia, np.array(old["main_body"].inertia) * 16.0 / 9.0)
    assert np.allclose(bodies["asar"].inertia, old["asar"].inertia)
    small = {b.name: b for b in module.scaled_target(case, 1.0, 0.75).target.bodies}
    assert np.allclose(small["asar"].shapes[0].size, [1.125, 0.117, 7.5])
    assert np.allclose(small["ka_band_dish"].shapes[0].center, [1.6875 + 0.75 * 1.95, 0.0, -3.0])


def test_data_length_table_states_the_worst_error_and_the_data_used_per_observation_time():
    """bench_perception.py's Table 4 (data length): per observation time, the worst |error| over the seeds
    (not the last seed's, not a signed maximum), the data used as the stage reports it (observation plus
    the free flight after the collision, perception.json ``observation_time_s``), the range of the stated
    1-sigma in % (mass_std / mass, C's std / C), and a not-observable seed counted, never read as a small
    error. The answers are hand-made, so each expected cell is the arithmetic below."""
    spec = importlib.util.spec_from_file_location("bench_perception_table", BENCH / "bench_perception.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)

    def answer(seed, data_s, mass_error, moment_error, mass_std_kg, c_std_kg_m2, ratio_errors, cpu_s):
        return {"bench_seed": seed, "not_observable": None, "observation_time_s": data_s,
                "mass_error_percent": mass_error, "inertia_error_percent": moment_error,
                "mass_kg": 2000.0, "mass_std_kg": mass_std_kg,
                "principal_moments_kg_m2": [700.0, 600.0, 500.0], "principal_moments_std_kg_m2": [1.0, 1.0, c_std_kg_m2],
                "inertia_ratio_error_percent": ratio_errors, "bench_cpu_s": cpu_s}

    lost = {"bench_seed": 2, "not_observable": "after the collision: no free flight",
            "inertia_ratio_error_percent": [0.9, -1.1], "bench_cpu_s": 300.0}
    answers = [("none", 10.0, answer(0, 21.5, 0.30, 0.40, 4.0, 2.5, [0.2, -0.35], 200.0)),
               ("none", 10.0, answer(1, 22.0, 0.10, 0.45, 2.0, 5.0, [-0.5, 0.1], 250.0)),
               ("none", 10.0, lost),
               ("none", 20.0, answer(0, 31.5, 0.05, 0.20, 6.0, 5.0, [0.07, 0.12], 360.0))]
    rows = [line for line in module.data_length_table(answers).splitlines() if line.startswith("| none")]
    # mass 1-sigma: 4/2000 = 0.20 %, 2/2000 = 0.10 %; C's: 2.5/500 = 0.50 %, 5/500 = 1.00 %;
    # ratios: the worst |error| over every run, the not-observable one included (its track was made): 1.1 %
    assert rows[0] == ("| none | 10 | 0 1 2 (1 not observable) | 21.5-22.0 | 0.300 | 0.10-0.20 | 0.450 | 0.50-1.00 "
                       "| 1.100 | 200-300 |")
    assert rows[1] == "| none | 20 | 0 | 31.5 | 0.050 | 0.30 | 0.200 | 1.00 | 0.120 | 360 |"


def test_peak_convergence_replays_a_store_sample_with_the_replica_offsets(tmp_path):
    """bench_peak_convergence.py --store/--sample: the replicas of a Monte Carlo sample keep its uncertain inputs and
    offset its launch velocity by k x 1e-7 (structures.reproducibility.TWIN_OFFSET), as the case's own velocity is
    offset; ``--velocity`` replaces the stored velocity; without a store nothing is overridden."""
    import json
    import sqlite3

    module = _bench_module("bench_peak_convergence")
    store = tmp_path / "store"
    stored = {"launch.velocity": 2.0, "contact.mu_static": 0.178, "launch.aim_point[2]": 6.552}
    with sqlite3.connect(store) as con:      # the columns bench_safe_velocity_history.sample_overrides reads
        con.execute("create table runs (grid_index integer, sample integer, overrides text)")
        con.execute("insert into runs values (0, 1, ?)", (json.dumps(stored),))
    con.close()
    overrides = module.sample_overrides(store, 1)
    assert module.replica_overrides(overrides, 0, None) == stored
    replica = module.replica_overrides(overrides, 2, None)
    assert replica["launch.velocity"] == pytest.approx(2.0000004, rel=1e-15, abs=0.0)    # 2 m/s x (1 + 2e-7)
    assert {k: v for k, v in replica.items() if k != "launch.velocity"} == {k: v for k, v in stored.items()
                                                                           if k != "launch.velocity"}
    assert module.replica_overrides(overrides, 1, 1.75)["launch.velocity"] == pytest.approx(1.750000175, rel=1e-15,
                                                                                          abs=0.0)
    assert module.replica_overrides({}, 3, None) == {}


def test_safe_velocity_history_splits_the_judged_peak_at_the_row_end(capsys):
    """bench_safe_velocity_history.py --judge-until T: the peak of the h1-h3 resultant over [skip, T] and over (T, end],
    each with its time and utilization. A demand of 3-4-5 triangles' known apexes (h1 = 30, h3 = 40 N m at 2 s: 50 N m;
    h3 = 150 N m at 6 s) against a 200 N m allowable: 0.25 before T = 4 s, 0.75 after; the skipped start (a 300 N m
    spike at 0.1 s) is not judged."""
    import numpy as np

    module = _bench_module("bench_safe_velocity_history")
    time = np.arange(0.0, 8.0005, 0.001)
    moment_joint = np.zeros((time.size, 1, 3))
    moment_joint[:, 0, 0] = 30.0 * np.clip(1 - abs(time - 2.0), 0, None)
    moment_joint[:, 0, 2] = 40.0 * np.clip(1 - abs(time - 2.0), 0, None) + 150.0 * np.clip(1 - abs(time - 6.0), 0, None)
    moment_joint[100, 0, 2] = 300.0
    series = {"time": time, "joint_moment_joint": moment_joint, "joint_names": np.array(["hinge"])}
    demand = module.hinge_demand(series, "hinge")
    module.print_peaks_until(series, demand, 0.25, [4.0], 200.0)
    lines = capsys.readouterr().out.splitlines()
    assert lines == ["peak demand over [0.25, 4] s: 50.0 N m at 2.000 s, utilization 0.250",
                     "peak demand over (4, 8.00] s: 150.0 N m at 6.000 s, utilization 0.750"]


def test_peak_convergence_quantile_change_sees_the_tail_the_median_does_not():
    """bench_peak_convergence.quantile_change: the change of a quantile of the replicas' peaks and its 90 % bootstrap
    interval. Expected values by hand: numpy's linear quantile (Hyndman & Fan type 7) of 1..11 at 0.9 sits at order
    position 0.9 x 10 = 9, the value 10; every value scaled by 1.1 scales every quantile and every bootstrap draw's
    ratio only when the draws cannot differ (constant sets), so there the interval is the change itself, +10 %
    exactly (round-off only: 1e-12). Doubling the two largest of 1..11 leaves the median (6) unchanged and moves the
    0.9 quantile from 10 to 20 (+100 %)."""
    import numpy as np

    module = _bench_module("bench_peak_convergence")
    rng = np.random.default_rng(0)
    base = np.arange(1.0, 12.0)
    assert np.quantile(base, 0.9) == 10.0
    change, low, high = module.quantile_change(np.full(8, 2.0), np.full(8, 2.2), rng, 0.9)
    assert (change, low, high) == pytest.approx((0.1, 0.1, 0.1), rel=0.0, abs=1e-12)
    assert module.verdict(change, low, high) == "NOT CONVERGED"
    tail = base.copy()
    tail[-2:] *= 2.0
    median, _, _ = module.quantile_change(base, tail, rng, 0.5)
    upper, low, high = module.quantile_change(base, tail, rng, 0.9)
    assert median == 0.0
    assert upper == pytest.approx(1.0, rel=0.0, abs=1e-12)
    assert low <= upper <= high          # the interval holds the change it is drawn around
    # the median's change is the 0.5 quantile's, draw for draw (the same generator state)
    assert module.median_change(base, tail, np.random.default_rng(3)) == module.quantile_change(
        base, tail, np.random.default_rng(3), 0.5)
    assert module.statistic_name(0.5) == "median" and module.statistic_name(0.9) == "q90"
