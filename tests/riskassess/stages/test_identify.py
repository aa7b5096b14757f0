"""Sub-tether identification (riskassess/stages/identify.py) on a reduced Sec. 4.3 benchmark."""
import numpy as np
import pytest

from pymoo.core.problem import Problem

from riskassess.cases.impact import load_model
from riskassess.stages.identify import cost_f1, cost_f2, identify, training_data
from riskassess.stages.optimizers.pattern import restarted_pattern_search
from riskassess.cases.towing import Optimizers, TowingCase

CASE = "cases/zenit2_towing.toml"


@pytest.fixture
def reduced_benchmark():
    """Boonrath et al. 2024 Sec. 4.3 shrunk to test size: data from s_true = [2, 7, 2, 1] at one
    spin rate (20.44 deg/s, Table 3) over the first 15 s of towing; pattern search from a start
    off by 5-10 % in a box around the truth (whose stiffest corner keeps the step >= 1.7 ms)."""
    case = load_model(CASE, TowingCase)
    ident = case.identification.model_copy(update=dict(
        lower_bounds=[1.5, 6.0, 1.5, 0.8], upper_bounds=[2.5, 8.0, 2.3, 1.0], initial_guess=[1.85, 7.4, 1.9, 0.9],
        optimizers=case.identification.optimizers.model_copy(update=dict(pattern_evaluations=250,
                                                                         pattern_tolerance=1e-5))))
    case = case.model_copy(update=dict(identification=ident))
    end = case.simulation.start_time + 15.0
    return case, training_data(case, ident.benchmark_truth, [20.44], end), end


def test_costs_vanish_on_the_data_and_grow_off_it(reduced_benchmark):
    case, data, end = reduced_benchmark
    weights = case.identification.weights
    assert cost_f1(data[0], data[0], weights) == 0.0 and cost_f2(data[0], data[0]) == 0.0
    other = training_data(case, [2.1, 7.0, 2.0, 1.0], [20.44], end)[0]
    assert cost_f1(other, data[0], weights) > 1e-3 and cost_f2(other, data[0]) > 1e-2


class ValleyCone(Problem):
    """f(s) = ||M (s - s_apex)||, the shape of f1 near s_true on the Sec. 4.3 data (measured, docs/towing.md:
    slopes 33, 56, 4.9 and 0.13 per unit of s1..s4, i.e. s4 ~260x flatter than s1, and the k_ST-c_ST
    valley, here along s1 = s3), in the bounds of eq. (24); s4's apex inside its bounds."""

    def __init__(self, apex):
        super().__init__(n_var=4, n_obj=1, xl=np.array([1.0, 5.0, 0.0, 0.1]), xu=np.array([3.5, 11.0, 3.5, 1.0]))
        valley = np.array([[1.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
        self.metric = np.diag([4.9, 56.0, 33.0, 0.13]) @ valley / np.linalg.norm(valley, axis=1)[:, None]
        self.apex, self.evaluations = np.asarray(apex, float), []

    def _evaluate(self, x, out, *args, **kwargs):
        out["F"] = np.linalg.norm((x - self.apex) @ self.metric.T, axis=1)
        self.evaluations.extend(out["F"])


def test_pattern_search_finds_the_apex_of_a_flat_valley_reproducibly():
    apex = [2.0, 7.0, 2.0, 0.73]
    settings = Optimizers(restart_evaluations=100, pattern_tolerance=1e-6, seed=3)
    found = [restarted_pattern_search(ValleyCone(apex), [1.0, 6.0, 3.0, 0.25], settings, 0.25, 3000) for _ in range(2)]
    # The apex is exact (no simulation): the search is limited only by its step tolerance, 1e-6 of each
    # bound range, so 1e-5 relative on every component is a loose bound that still fails for a search
    # that stalls in the valley or leaves s4 where it started (0.25).
    np.testing.assert_allclose(found[0][0], apex, rtol=1e-5)
    # pymoo 0.6.2 drew each exploration order from a fresh unseeded generator: two runs could differ.
    np.testing.assert_array_equal(found[0][0], found[1][0])


@pytest.fixture(scope="module")
def small_benchmark():
    """Sec. 4.3 at unit-test size: one Table 3 rate (20.44 deg/s), the first 35 s of towing (the
    sub-tethers engage at ~28 s and pull for the rest), a box around s_true (1/5 to 1/2 of eq. 24's
    ranges), PSO with 10 particles x 8 generations polished by 200 pattern-search evaluations. Measured
    for seeds 0-9: s1-s3 within 6.6e-3 relative (c_ST worst, 1.1e-3 for k_ST); 12 x 10 with a 180
    polish once left c_ST 1.7 % off (seed 3), 150 once 1.1 % in CI."""
    case = load_model(CASE, TowingCase)
    optimizers = case.identification.optimizers.model_copy(update=dict(
        swarm_size=10, pso_generations=8, polish_evaluations=200, polish_delta=0.02))
    ident = case.identification.model_copy(update=dict(
        lower_bounds=[1.5, 6.0, 1.5, 0.6], upper_bounds=[2.5, 8.0, 2.5, 1.0], optimizers=optimizers))
    case = case.model_copy(update=dict(identification=ident))
    end = case.simulation.start_time + 35.0
    return case, training_data(case, ident.benchmark_truth, [20.44], end), end


@pytest.mark.parametrize("seed", [0, 1])
def test_pso_and_pattern_search_recover_known_sub_tether_parameters(small_benchmark, seed):
    case, data, end = small_benchmark
    settings = case.identification.optimizers.model_copy(update=dict(seed=seed))
    case = case.model_copy(update=dict(identification=case.identification.model_copy(update=dict(optimizers=settings))))
    swarm = identify(case, data, "pso", end_time=end, workers=2)
    found = identify(case, data, "polish", end_time=end, workers=2, initial_guess=swarm.s)
    truth = np.asarray(case.identification.benchmark_truth)
    assert found.cost <= swarm.cost
    # The cost is an RMSE: it grows linearly with |s - s_true|. Measured (60 s of towing, one rate):
    # 2e-3 on s1 costs 3.7e-3 and 2e-3 on s3 costs 3.7e-4, but 0.1 on s4 only 1.1e-3: m_P barely moves
    # the bodies, less still in 35 s (the paper's MADS runs also ended at s4 = 0.48 and 0.83 for a truth
    # of 1, Table 5). Measured here (seeds 0-9): s1-s3 within 0.66 %, s4 anywhere in its box (0.6-1.0). Tolerances:
    # 1 % on k_ST, l_ST0 and c_ST; s4 only inside its bounds. The full benchmark's figures: docs/towing.md.
    np.testing.assert_allclose(found.s[:3], truth[:3], rtol=1e-2)
    lower, upper = case.identification.lower_bounds[3], case.identification.upper_bounds[3]
    assert lower <= found.s[3] <= upper


@pytest.mark.slow  # not robust at this budget: seeded now, seeds 0, 1, 4 pass; 2 and 3 end with c_ST 8-9 % off (k-c valley)
def test_pattern_search_recovers_known_sub_tether_parameters(reduced_benchmark):
    case, data, end = reduced_benchmark
    found = identify(case, data, "pattern", end_time=end, workers=2)
    truth = np.asarray(case.identification.benchmark_truth)
    start_cost = found.history[0]
    # 250 evaluations (12 s) of Hooke-Jeeves: measured cost 0.036 from 0.51 and s within 2.5 % of
    # the truth (s3 worst); the bounds below fail if the search stalls or wanders (the start is
    # 5-10 % off). The 1e-3 needs more evaluations than a unit test affords (docs/towing.md).
    assert found.cost < 0.1 * start_cost
    # k_ST, l_ST0 and c_ST are observed in 15 s; the connection-point mass fraction s4 barely
    # moves the first 15 s (the thrust is still below 60 N), as the paper's MADS runs also found
    # (Table 5: s4 = 0.48 and 0.83 for truth 1): only its bounds are checked.
    np.testing.assert_allclose(found.s[:3], truth[:3], rtol=5e-2)
    assert case.identification.lower_bounds[3] <= found.s[3] <= 1.0


def test_a_diverged_twin_run_scores_inf(monkeypatch):
    """Issue 20: a lower-order run whose state went NaN must never be the identified answer (NaN
    costs compare false and would survive the swarm's selection)."""
    import numpy as np

    from riskassess.stages import identify

    nan_run = {"main_tether_tension": np.full(5, np.nan)}
    monkeypatch.setattr(identify, "simulate", lambda *args: nan_run)
    identify._init_worker(None, [{"rate_deg_s": 1.0, "main_tether_tension": np.ones(5)}], "f2", None, None)
    assert identify._run_term((np.ones(4), 0)) == np.inf


def test_optimizers_are_plug_ins_found_by_name_and_an_unknown_one_is_refused():
    """Issue 21: one file per optimizer; the case schema's and the CLI's names are the registry's."""
    from riskassess.cases.inputs import SEARCHES
    from riskassess.stages.optimizers import OPTIMIZERS

    assert set(OPTIMIZERS) == {"pso", "pattern", "polish", "mads"}
    assert set(SEARCHES) <= set(OPTIMIZERS)
    with pytest.raises(ValueError) as unknown:
        OPTIMIZERS["nelder-mead"]
    assert str(unknown.value) == "unknown optimizer 'nelder-mead'; the known optimizers are: mads, pattern, polish, pso"


def test_mads_with_the_papers_settings_finds_the_apex_of_a_flat_valley_reproducibly():
    """NOMAD's MADS (riskassess/stages/optimizers/mads.py) with Sec. 4.3's settings: 250 iterations,
    mesh tolerance 1e-6. Measured (seeds 0 and 3): about 400-480 evaluations, s1-s3 within 2.5e-4
    relative, s4 (260x flatter) within 1.3 %; the cost falls from ~80 to ~1e-3."""
    apex = np.array([2.0, 7.0, 2.0, 0.73])
    settings = Optimizers(seed=3)
    from riskassess.stages.optimizers import OPTIMIZERS

    runs = []
    for _ in range(2):
        problem = ValleyCone(apex)
        runs.append(OPTIMIZERS["mads"].search(problem, [1.0, 6.0, 3.0, 0.25], settings))
    s, cost = runs[0]
    start_cost = ValleyCone(apex).evaluate(np.array([[1.0, 6.0, 3.0, 0.25]]), return_values_of=["F"]).item()
    assert cost < 1e-4 * start_cost
    np.testing.assert_allclose(s[:3], apex[:3], rtol=1e-3)       # 4x the measured worst
    np.testing.assert_allclose(s[3], apex[3], rtol=5e-2)         # the flat direction, 4x the measured worst
    np.testing.assert_array_equal(runs[0][0], runs[1][0])        # seeded: the same search twice


def test_mads_recovers_known_sub_tether_parameters_on_the_small_benchmark(small_benchmark):
    """MADS on the Sec. 4.3 benchmark at test size (35 s, one rate) with 300 evaluations from a start
    5-10 % off. Measured: cost 0.89 -> 2.3e-3, s1-s3 within 0.2 % (c_ST worst), s4 33 % off: m_P barely
    moves the bodies (the paper's MADS ended at s4 = 0.48 and 0.83 for a truth of 1, Table 5)."""
    case, data, end = small_benchmark
    settings = case.identification.optimizers.model_copy(update=dict(mads_evaluations=300))
    ident = case.identification.model_copy(update=dict(optimizers=settings, initial_guess=[1.85, 7.4, 1.9, 0.9]))
    case = case.model_copy(update=dict(identification=ident))
    found = identify(case, data, "mads", end_time=end, workers=2)
    truth = np.asarray(ident.benchmark_truth)
    assert found.evaluations <= 300 and found.cost < 1e-2 * found.history[0]
    np.testing.assert_allclose(found.s[:3], truth[:3], rtol=1e-2)    # 5x the measured worst
    assert ident.lower_bounds[3] <= found.s[3] <= ident.upper_bounds[3]


def test_mads_refuses_a_start_outside_the_bounds_before_any_run():
    from riskassess.stages.optimizers import OPTIMIZERS

    with pytest.raises(ValueError, match="MADS: the start .* lies outside the bounds"):
        OPTIMIZERS["mads"].search(ValleyCone([2.0, 7.0, 2.0, 0.73]), [0.5, 6.0, 3.0, 0.25], Optimizers())


def test_the_benchmark_table_sets_the_papers_runs_beside_ours_and_only_the_same_runs():
    """bench/bench_identify.py prints Boonrath et al. 2024's Tables 4-5 beside our runs: its PSO beside our PSO (with or
    without the polish), its MADS from s0 beside ours from s0; nothing beside the pattern search (the paper has none),
    a MADS from a Table 6 start (the paper's benchmark starts at s0) or another truth. Values from the seed's tables."""
    from bench.bench_identify import paper_row

    benchmark = dict(truth=[2.0, 7.0, 2.0, 1.0], start=[1.0, 6.0, 3.0, 0.25])
    assert paper_row("pso+pattern", "f2", benchmark) == (0.0217, [2.0000035, 7.0000049, 2.0000158, 0.9999974])
    assert paper_row("pso", "f1", benchmark)[0] == 6.3958e-5
    assert paper_row("mads", "f1", benchmark) == (0.4960, [1.9959287, 6.9976071, 1.9901418, 0.4832296])
    assert paper_row("mads", "f2", benchmark)[1][3] == 0.8285154
    assert paper_row("pattern", "f1", benchmark) is None
    assert paper_row("mads 3", "f1", dict(benchmark, start=[3.0, 8.0, 1.0, 0.5])) is None
    assert paper_row("mads", "f1", dict(benchmark, truth=[2.137, 7.419, 1.862, 0.731])) is None
