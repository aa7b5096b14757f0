"""Case files are rejected with a message naming the file, the key and what is allowed."""
from pathlib import Path

import numpy as np
import pytest

from riskassess.stages.kinds import load_any_case
from riskassess.cases.impact import CaseError, load_case

CASES = Path(__file__).resolve().parents[3] / "cases"
REFERENCE = (CASES / "envisat_net_impact.toml").read_text()


def _load_modified(tmp_path, old, new):
    assert old in REFERENCE, old
    path = tmp_path / "bad.toml"
    path.write_text(REFERENCE.replace(old, new, 1))
    with pytest.raises(CaseError) as info:
        load_case(path)
    return str(info.value)


def test_shipped_cases_are_valid():
    # Every case file a user copies loads with its own stage's schema; the four kinds are all shipped.
    kinds = {path.name: load_any_case(path)[0] for path in CASES.glob("*.toml")}
    assert kinds["envisat_net_impact.toml"] == "impact" and kinds["zenit2_towing.toml"] == "towing"
    assert kinds["approach_mu_min_time.toml"] == "approach"
    assert kinds["diagnose_tumbling_rigid.toml"] == "diagnosis"


def test_reference_case_matches_paper_tables():
    case = load_case(CASES / "envisat_net_impact.toml")
    # seed paper Table 1 / Table 2
    assert case.net.side_length == 30.0 and case.net.nodes_per_side == 35
    assert case.net.thread.stiffness == 62308.25 and case.net.thread.damping == 1.58
    assert case.bullets.mass == 1.786 and case.launch.velocity == 20.0
    assert case.contact.stiffness == 1.622e8 and case.contact.exponent == 1.5
    assert (case.contact.mu_static, case.contact.mu_kinetic) == (0.19, 0.152)


@pytest.mark.parametrize("old, new, expected", [
    ('mass = 350.0', 'mass = -350.0', "target.bodies[1].mass: Input should be greater than 0. Got -350.0"),
    ('stiffness = 62308.25', 'stiffness = 0.0', "net.thread.stiffness: Input should be greater than 0"),
    ('velocity = 20.0', 'velocity = "20 m/s"', "launch.velocity: Input should be a valid number"),
    ('side_length = 30.0', 'side_length = 30.0\nsidelength = 3', "net.sidelength: unknown key"),
    ('diameter = 0.002', 'diameter = 2.0', "net.thread.diameter: Input should be less than or equal to 0.05"),
    ('altitude = 770e3', 'altitude = 770', "orbit.altitude: Input should be greater than or equal to 100000"),
    ('child = "solar_array"', 'child = "solar_panel"', "joint 'solar_array_hinge': child 'solar_panel' is not a body"),
    ('torsional_stiffness = 5.0e4', 'torsional_stiffness = -1.0', "torsional_stiffness: Input should be greater than or equal to 0"),
    ('stiffness = 1.622e8', 'stiffness = -1.622e8', "contact.stiffness: Input should be greater than 0"),
])
def test_bad_values_name_file_key_and_allowed_range(tmp_path, old, new, expected):
    message = _load_modified(tmp_path, old, new)
    assert str(tmp_path / "bad.toml") in message
    assert expected in message


def test_net_that_cannot_reach_is_rejected(tmp_path):
    message = _load_modified(tmp_path, "aim_point = [0.0, 0.0, 7.0]", "aim_point = [40.0, 0.0, 7.0]")
    assert "launch.direction" in message and "misses the target" in message
    message = _load_modified(tmp_path, "distance = 3.0 ", "distance = 1000.0 ")
    assert "launch.distance" in message and "end_time" in message
    message = _load_modified(tmp_path, "distance = 3.0 ", "distance = 1.0 ")
    assert "launch.distance" in message and "inside the target" in message


def test_missing_mesh_file_is_named(tmp_path):
    message = _load_modified(tmp_path, 'kind = "box"\nsize = [3.375, 3.75, 7.875]',
                             'kind = "mesh"\nfile = "envisat_body.stl"')
    assert "target.bodies[0].shapes[0]" in message


def test_cli_reports_a_bad_case_before_running(tmp_path, capsys):
    from riskassess.cli import main

    path = tmp_path / "bad.toml"
    path.write_text(REFERENCE.replace("mass = 1.786", "mass = -1.786", 1))
    out = tmp_path / "run"
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "bullets.mass: Input should be greater than 0. Got -1.786" in err
    assert not out.exists(), "nothing is written for a case that does not validate"


@pytest.mark.parametrize("old, new, expected", [
    ('joint = "ka_band_hinge"', 'joint = "ka_hinge"',
     "weak location 'ka_band_hinge': joint 'ka_hinge' is not in target.joints"),
    ('outer_diameter = 0.1, wall = 0.002', 'outer_diameter = 0.1, wall = 0.2',
     "structures.weak_locations[2].section: circular_tube: wall must be in (0, outer_diameter/2 = 0.05 m]"),
    ('allowable_moment = [200.0, 1000.0]', 'allowable_moment = [1000.0, 200.0]',
     "structures.weak_locations[0].allowable_moment: a range is [low, high] with low <= high"),
    ('release = "low"', 'release = "sometimes"', "structures.release: Input should be 'low', 'nominal', 'high' or 'never'"),
    ('material = { ultimate_normal = 570e6, ultimate_shear = 330e6 }', '',
     "structures.weak_locations[1]: 'section' and 'material' come together"),
])
def test_bad_weak_locations_are_named(tmp_path, old, new, expected):
    message = _load_modified(tmp_path, old, new)
    assert expected in message


@pytest.mark.parametrize("cutoff, expected", [
    # the step is 1e-4 s: a cut-off within 1/10 of its 5 kHz Nyquist frequency (multibody.load_filter.NYQUIST_FRACTION)
    (600.0, "a load filter at 600 Hz needs simulation.step <= 8.33333e-05 s"),
    # the output samples the filtered load 20 times per period of the cut-off, as a modal reading
    # (structures.modal_load.SAMPLES_PER_MODE_PERIOD)
    (150.0, "a load filter at 150 Hz needs simulation.output_rate >= 3000 Hz"),
])
def test_a_load_filter_the_step_or_output_cannot_carry_is_refused(tmp_path, cutoff, expected):
    assert expected in _load_modified(tmp_path, 'release = "low"', f'release = "low"\nload_filter_hz = {cutoff}')


def test_case_format_doc_is_current():
    """docs/case-format.md is generated from the models; regenerate with python -m riskassess.cases.doc."""
    from riskassess.cases.doc import render

    assert (CASES.parent / "docs" / "case-format.md").read_text() == render()


def test_every_numeric_input_states_its_unit():
    """The report lists every input with its unit, read from the field descriptions: a numeric
    field without a recognisable SI unit in its description would show a blank unit."""
    import typing

    from pydantic import BaseModel

    from riskassess.cases import impact as c
    from riskassess.cases.doc import field_unit

    def numeric(annotation) -> bool:
        if annotation in (int, float):
            return True
        return any(numeric(a) for a in typing.get_args(annotation) if a is not type(None))

    models = [m for m in vars(c).values() if isinstance(m, type) and issubclass(m, BaseModel)
              and m.__module__ == c.__name__]
    unitless = [f"{m.__name__}.{name}" for m in models for name, field in m.model_fields.items()
                if numeric(field.annotation) and name != "kind" and not field_unit(field)]
    assert unitless == []


def test_input_rows_of_the_reference_case_carry_units():
    from riskassess.cases.doc import input_rows

    rows = {key: (value, unit) for key, value, unit, _ in input_rows(load_case(CASES / "envisat_net_impact.toml"))}
    assert rows["launch.velocity"] == ("20", "m/s")                  # [paper T1]
    assert rows["contact.stiffness"] == ("1.622e+08", "N/m^exponent")  # [paper T2]
    assert rows["target.bodies[solar_array].mass"] == ("350", "kg")
    assert rows["target.joints[solar_array_hinge].torsional_stiffness"][1] == "N m/rad"
    assert rows["target.bodies[main_body].shapes[0]"][0].startswith("box: size [")


def test_monte_carlo_table_is_checked_on_load(tmp_path):
    """[monte_carlo] uncertain: the KEY=DIST(params) grammar of --uncertain, checked when the case loads
    (before any run), each key once."""
    text = (CASES / "envisat_small.toml").read_text()
    good = text + '\n[monte_carlo]\nuncertain = ["contact.mu_kinetic=uniform(0.1,0.19)"]\n'
    path = tmp_path / "mc.toml"
    path.write_text(good)
    assert load_case(path).monte_carlo.uncertain == ["contact.mu_kinetic=uniform(0.1,0.19)"]
    for entry, message in (('"contact.mu_kinetic=gauss(0.1,0.2)"', "DIST one of uniform(low, high)"),
                           ('"contact.mu_kinetic=uniform(0.2,0.1)"', "needs low < high"),
                           ('"a=uniform(0,1)", "a=uniform(0,2)"', "each key appears once")):
        path.write_text(text + f"\n[monte_carlo]\nuncertain = [{entry}]\n")
        with pytest.raises(CaseError) as err:
            load_case(path)
        assert "monte_carlo.uncertain" in str(err.value) and message in str(err.value)


def test_perception_model_is_known_by_default_and_checked(tmp_path):
    perception = CASES / "tang2023_debris_perception.toml"
    assert load_case(perception).perception.model == "known"
    path = tmp_path / "case.toml"
    path.write_text(perception.read_text().replace("seed = 0", 'seed = 0\nmodel = "mesh"', 1))
    with pytest.raises(CaseError, match=r"case.toml: perception.model: Input should be 'known' or 'none'"):
        load_case(path)


@pytest.mark.parametrize("budget, expected", [
    ("search_cpu_per_frame = 0.0", r"case.toml: perception.registration.search_cpu_per_frame: Input should be greater than 0"),
    ("search_cpu_per_run = -1.0", r"case.toml: perception.registration.search_cpu_per_run: Input should be greater than or equal to 0"),
    ("search_cpu_per_frame = 20.0\nsearch_cpu_per_run = 10.0",
     r"case.toml: perception.registration: search_cpu_per_frame \(20.0 s\) must not exceed search_cpu_per_run \(10.0 s\)"),
])
def test_search_budget_has_defaults_and_is_checked(tmp_path, budget, expected):
    # The lost-track search budget (docs/perception.md, "Search budget"): stated defaults, and a bad
    # value named with its key before any scan is made.
    perception = CASES / "tang2023_debris_perception.toml"
    registration = load_case(perception).perception.registration
    assert (registration.search_cpu_per_frame, registration.search_cpu_per_run) == (15.0, 300.0)
    path = tmp_path / "case.toml"
    path.write_text(perception.read_text().replace("[perception.registration]", "[perception.registration]\n" + budget, 1))
    with pytest.raises(CaseError, match=expected):
        load_case(path)


def test_launch_sag_builds_the_bowl_and_keeps_the_launch_momentum(tmp_path):
    """launch.sag (off by default): the case's net is multibody.net.bowl_net_positions of its flat net, every node
    keeps the launch velocity (so the paper's 32 mm/s momentum exchange is unchanged), and a bowl too deep for the
    net is refused with the key's name before any run."""
    import numpy as np

    from multibody.net import bowl_net_positions
    from riskassess.models.impact import build_net

    case = load_case(CASES / "envisat_paper_sequential.toml")
    assert case.launch.sag == 0.0
    flat, v_flat = build_net(case)
    bowl, v_bowl = build_net(case.model_copy(update={"launch": case.launch.model_copy(update={"sag": 2.0})}))
    assert np.array_equal(bowl.positions, bowl_net_positions(flat, case.launch.direction, 2.0))
    assert np.array_equal(v_bowl, v_flat)
    assert np.array_equal(bowl.rest_lengths, flat.rest_lengths)
    too_deep = case.model_copy(update={"launch": case.launch.model_copy(update={"sag": 15.0})})
    with pytest.raises(ValueError, match="launch.sag = 15 m"):
        build_net(too_deep)
    path = tmp_path / "sag.toml"
    path.write_text(REFERENCE.replace("velocity = 20.0 ", "sag = 2.0\nvelocity = 20.0 ", 1))
    assert load_case(path).launch.sag == 2.0


CLOSING = "\n[net.closing]\nduration_s = 5.0\nclosed_fraction = 0.1\naxial_rigidity = 55000.0\n"


@pytest.mark.parametrize("extra, expected", [
    ("delay_s = 2.0\ndelay_travel_m = 14.0\n", "at most one of 'delay_s' (s) or 'delay_travel_m' (m)"),
    ("start = 3.0\ndelay_s = 2.0\n", "a delay goes with start = 'first_contact'"),
    ("start = \"on_wrap\"\n", "net.closing.start"),
    ("closed_fraction_of = 0.1\n", "closed_fraction_of"),
    ("duration_s_typo = 1\n", "duration_s_typo"),
])
def test_closing_keys_refused_with_a_clear_error(tmp_path, extra, expected):
    message = _load_modified(tmp_path, "\n[bullets]", CLOSING + extra + "\n[bullets]")
    assert expected in message and "bad.toml" in message


def test_closing_refused_with_the_sequential_method(tmp_path):
    text = REFERENCE.replace("\n[bullets]", CLOSING + "\n[bullets]", 1).replace(
        '[simulation]\n', '[simulation]\ncoupling = "sequential"\n', 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(CaseError, match="net.closing closes the net around free debris"):
        load_case(path)


def test_closing_case_loads_with_its_defaults(tmp_path):
    path = tmp_path / "closing.toml"
    path.write_text(REFERENCE.replace("\n[bullets]", CLOSING + "\n[bullets]", 1))
    closing = load_case(path).net.closing
    assert closing.start == "first_contact" and closing.delay_s is None and closing.damping is None


TETHER = "\n[net.tether]\nstiffness = 3000.0\ndamping = 300.0\n"


@pytest.mark.parametrize("extra, expected", [
    ("axial_rigidity = 55000.0\n", "exactly one of 'stiffness' (N/m) or 'axial_rigidity' (N)"),
    ("reel_rate_m_s = 0.1\n", "a reel-in needs both 'reel_rate_m_s' (m/s) and 'reel_in_m' (m) > 0"),
    ("reel_in_m = 2.0\n", "a reel-in needs both"),
    ("start = 3.0\ndelay_travel_m = 2.0\n", "a delay goes with start = 'first_contact'"),
    ("standoff = 20.0\n", "standoff"),
])
def test_tether_keys_refused_with_a_clear_error(tmp_path, extra, expected):
    message = _load_modified(tmp_path, "\n[bullets]", TETHER + extra + "\n[bullets]")
    assert expected in message and "bad.toml" in message


@pytest.mark.parametrize("simulation, expected", [
    ('coupling = "sequential"\n', "net.tether ties the net to the chaser while it wraps free debris"),
    ('net_integration = "exudyn"\n', "net.tether's force is evaluated inside the compiled kernel"),
])
def test_tether_refused_without_free_debris_or_the_kernel(tmp_path, simulation, expected):
    text = REFERENCE.replace("\n[bullets]", TETHER + "\n[bullets]", 1).replace(
        '[simulation]\n', '[simulation]\n' + simulation, 1)
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(CaseError, match=expected):
        load_case(path)


def test_tether_case_ties_the_middle_node_to_an_anchor_behind_the_net(tmp_path):
    from multibody.net_tether import central_node
    from riskassess.models.impact import build_net, tether_spec
    path = tmp_path / "tether.toml"
    path.write_text(REFERENCE.replace("\n[bullets]", TETHER + "\n[bullets]", 1))
    case = load_case(path)
    tether = case.net.tether
    assert tether.start == "first_contact" and tether.slack_m == 0.0 and tether.reel_rate_m_s == 0.0
    net, _ = build_net(case)
    spec = tether_spec(case, net)
    n = case.net.nodes_per_side
    assert spec.node == central_node(n) and n % 2 == 1
    # the middle node of an odd grid is the grid's centre; the anchor 15 m (the default standoff) behind it
    direction = np.asarray(case.launch.direction) / np.linalg.norm(case.launch.direction)
    np.testing.assert_allclose(net.positions[spec.node], net.positions[: n * n].mean(axis=0), atol=1e-12)
    np.testing.assert_allclose(spec.anchor_lvlh, net.positions[spec.node] - 15.0 * direction, atol=1e-12)
    assert spec.stiffness == 3000.0 and spec.axial_rigidity is None and spec.start is None and spec.delay == 0.0
