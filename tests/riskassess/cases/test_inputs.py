"""Every case loader checks every input at the edge (issue 20, items 4, 6, 9 and 10).

Each test writes a shipped case with one change and asserts the exact message: a CaseError naming
the file, the key and what is allowed. The limits asserted are the module constants of
riskassess/cases/inputs.py and riskassess/diagnosis/measured.py (their reasons are stated there).
"""
import re
from pathlib import Path

import numpy as np
import pytest

from riskassess.cases.inputs import MEASURED_FILE_LIMIT
from riskassess.diagnosis.measured import MeasuredDataError, read_measured
from riskassess.products.measured import write_measured
from riskassess.cases.approach import ApproachCase
from riskassess.cases.impact import CaseError, load_case, load_model
from riskassess.cases.inputs import (CASE_FILE_LIMIT, CASE_NAME_PATTERN, ITEM_NAME_PATTERN, JSON_FILE_LIMIT,
                                    MAX_NESTING, MESH_FILE_LIMIT, read_toml)
from riskassess.stages.kinds import load_any_case
from riskassess.cli import main
from riskassess.diagnosis.cases import load_diagnosis_case
from riskassess.cases.towing import TowingCase

CASES = Path(__file__).resolve().parents[3] / "cases"
IMPACT, TOWING = "envisat_small.toml", "zenit2_towing.toml"
HINGED, DIAGNOSE_TOWING, APPROACH = "diagnose_hinged_appendage.toml", "diagnose_towing.toml", "approach_mu_min_time.toml"
LOADERS = {IMPACT: load_case, TOWING: lambda p: load_model(p, TowingCase), HINGED: load_diagnosis_case,
           DIAGNOSE_TOWING: load_diagnosis_case, APPROACH: lambda p: load_model(p, ApproachCase)}


def _sparse(path, size):
    """A file of ``size`` bytes that takes no space on disk (nothing is written)."""
    with open(path, "wb") as f:
        f.truncate(size)


def _case(tmp_path, shipped, old="", new="", name="case.toml") -> Path:
    """The shipped case ``shipped`` with ``old`` replaced by ``new`` once, written to tmp_path (with the
    towing case a towing diagnosis names beside it)."""
    text = (CASES / shipped).read_text()
    assert old in text, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    (tmp_path / TOWING).write_text((CASES / TOWING).read_text())
    return path


def _message(load, path) -> str:
    with pytest.raises(CaseError) as info:
        load(path)
    return str(info.value)


def _refused(tmp_path, shipped, old, new) -> str:
    path = _case(tmp_path, shipped, old, new)
    message = _message(LOADERS[shipped], path)
    assert message.startswith(f"{path}: "), message
    assert _message(lambda p: load_any_case(p)[1], path) == message, "riskassess validate says the same"
    return message


# ---------------------------------------------------------------------------- 9: finite floats
@pytest.mark.parametrize("shipped, old, new, expected", [
    (IMPACT, "mass = 350.0", "mass = inf", "target.bodies[1].mass: Input should be a finite number. Got inf instead"),
    (IMPACT, "stiffness = 1.622e8", "stiffness = nan", "contact.stiffness: Input should be a finite number. Got nan instead"),
    (IMPACT, "damping = 1.58", "damping = inf", "net.thread.damping: Input should be a finite number. Got inf instead"),
    (IMPACT, "mu_static = 0.19", "mu_static = -inf",
     "contact.mu_static: Input should be a finite number. Got -inf instead"),
    (IMPACT, "direction = [0.0, 1.0, 0.0]", "direction = [0.0, nan, 0.0]",
     "launch.direction[1]: Input should be a finite number. Got nan instead"),
    # the "SVD did not converge": a NaN hinge angle
    (IMPACT, "torsional_damping = 1.4e3", "torsional_damping = 1.4e3\ninitial_angle = nan",
     "target.joints[0].initial_angle: Input should be a finite number. Got nan instead"),
    (IMPACT, "mass = 350.0", 'mass = "nan"', "target.bodies[1].mass: Input should be a valid number. Got 'nan' instead"),
    (IMPACT, "mass = 350.0", 'mass = "inf"', "target.bodies[1].mass: Input should be a valid number. Got 'inf' instead"),
    (TOWING, "attitude_quaternion = [0.50637,", "attitude_quaternion = [nan,",
     "chaser.attitude_quaternion[0]: Input should be a finite number. Got nan instead"),
    (TOWING, "damping = 300.0", "damping = inf", "main_tether.damping: Input should be a finite number. Got inf instead"),
    (HINGED, "initial_angle = 0.4", "initial_angle = nan",
     "hinge.initial_angle: Input should be a finite number. Got nan instead"),
    (DIAGNOSE_TOWING, "fit_step = 0.02", "fit_step = inf",
     "fit_step: Input should be a finite number. Got inf instead"),
    (APPROACH, "max = 12.0", "max = inf", "thrust.max: Input should be a finite number. Got inf instead"),
])
def test_non_finite_numbers_are_refused(tmp_path, shipped, old, new, expected):
    assert expected in _refused(tmp_path, shipped, old, new)


# ---------------------------------------------------------------------------- strict types
@pytest.mark.parametrize("shipped, old, new, expected", [
    (IMPACT, "velocity = 20.0", 'velocity = "0.2"', "launch.velocity: Input should be a valid number. Got '0.2' instead"),
    (IMPACT, "bending = false", 'bending = "no"', "net.thread.bending: Input should be a valid boolean. Got 'no' instead"),
    (IMPACT, "bending = false", "bending = 0", "net.thread.bending: Input should be a valid boolean. Got 0 instead"),
    (IMPACT, "nodes_per_side = 15", "nodes_per_side = 15.0",
     "net.nodes_per_side: Input should be a valid integer. Got 15.0 instead"),
    (IMPACT, "mass = 350.0", "mass = true", "target.bodies[1].mass: Input should be a valid number. Got True instead"),
    (TOWING, "enabled = true\nk_gain", 'enabled = "yes"\nk_gain',   # [attitude_control]'s (not [lateral]'s) flag
     "attitude_control.enabled: Input should be a valid boolean"),
    (APPROACH, "final_at_rest = false", "final_at_rest = 1",
     "collocation.final_at_rest: Input should be a valid boolean. Got 1 instead"),
])
def test_types_are_strict(tmp_path, shipped, old, new, expected):
    assert expected in _refused(tmp_path, shipped, old, new)


def test_toml_integers_are_taken_for_floats(tmp_path):
    case = load_case(_case(tmp_path, IMPACT, "mass = 350.0", "mass = 350"))
    assert case.target.bodies[1].mass == 350.0 and isinstance(case.target.bodies[1].mass, float)


# ---------------------------------------------------------------------------- 9: duplicate names
@pytest.mark.parametrize("shipped, old, new, expected", [
    (IMPACT, 'name = "asar"', 'name = "solar_array"',
     "target.bodies: each body needs its own name; repeated: 'solar_array' (items 1 and 2)"),
    (IMPACT, 'name = "asar_mount"', 'name = "solar_array_hinge"',
     "target.joints: each joint needs its own name; repeated: 'solar_array_hinge' (items 0 and 1)"),
    (IMPACT, 'name = "ka_band_hinge"                # location 3:', 'name = "asar_mount" #',
     "structures.weak_locations: each weak location needs its own name; repeated: 'asar_mount' (items 1 and 2)"),
])
def test_duplicate_names_are_refused(tmp_path, shipped, old, new, expected):
    assert expected in _refused(tmp_path, shipped, old, new)


def test_duplicate_effects_are_refused(tmp_path):
    effect = '\n[[effects]]\nid = "sensor_bias"\nparameters = {}\n'
    path = _case(tmp_path, HINGED)
    path.write_text(path.read_text() + effect + effect)
    assert "effects: each effect needs its own id; repeated: 'sensor_bias' (items 0 and 1)" in \
        _message(load_diagnosis_case, path)


# ---------------------------------------------------------------------------- 4: names
NAME_RULE = ("a case name is 1 to 64 letters, digits, '.', '_' or '-', starting with a letter or digit "
             "(it names the output folder runs/<name>)")


@pytest.mark.parametrize("shipped", [IMPACT, TOWING, HINGED, DIAGNOSE_TOWING, APPROACH])
@pytest.mark.parametrize("bad", ["../../escaped", "/tmp/abs", "", "a/b", ".hidden", "-rf", "x" * 65, "[red]x"])
def test_case_name_is_a_safe_folder_name(tmp_path, shipped, bad):
    old = f'name = "{Path(shipped).stem}"'
    message = _refused(tmp_path, shipped, old, f'name = "{bad}"')
    assert f"name: {NAME_RULE}. Got {bad!r} instead" in message


@pytest.mark.parametrize("bad", ["[link=x]", "$x^{$", "x[/red]", "1st", "a b", ""])
def test_item_names_are_tokens(tmp_path, bad):
    message = _refused(tmp_path, IMPACT, 'name = "asar"', f'name = "{bad}"')
    assert ("target.bodies[2].name: a name is 1 to 64 letters, digits, '.', '_' or '-', starting with a letter. "
            f"Got {bad!r} instead") in message


def test_shipped_case_and_item_names_conform():
    names = [re.findall(r'^name = "([^"]*)"', (path.read_text()), re.M) for path in CASES.glob("*.toml")]
    assert all(re.fullmatch(CASE_NAME_PATTERN, n[0]) and all(re.fullmatch(ITEM_NAME_PATTERN, m) for m in n[1:])
               for n in names), names
    assert len(names) == 21       # every shipped case was read


def test_control_characters_in_description_are_refused(tmp_path):
    message = _refused(tmp_path, IMPACT, 'description = "', 'description = "\\u001b[2J')
    assert "description: control character '\\x1b' in text; only printable text, newlines and tabs" in message


# ---------------------------------------------------------------------------- 6, 10: the case file itself
def test_case_file_must_be_a_regular_file(tmp_path):
    assert _message(read_toml, "/dev/zero") == \
        "/dev/zero: the case file is not a regular file (a device, pipe or socket); a file is expected"
    assert _message(read_toml, tmp_path) == f"{tmp_path}: the case file is a directory; a file is expected"
    assert _message(read_toml, tmp_path / "none.toml") == f"{tmp_path / 'none.toml'}: no such case file"


def test_case_file_size_is_limited(tmp_path):
    path = tmp_path / "big.toml"
    _sparse(path, CASE_FILE_LIMIT + 1)
    assert _message(read_toml, path) == f"{path}: the case file is 1,000,001 bytes; at most 1,000,000 bytes are read"


def test_non_utf8_case_file_is_named(tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes('name = "d\xe9bris"\n'.encode("latin-1"))
    # byte 9 is the 0xe9 of the Latin-1 e-acute: 'name = "d' is 9 bytes
    assert _message(read_toml, path) == f"{path}: not UTF-8 text: byte 9 is 0xe9 (save the case file as UTF-8)"


@pytest.mark.parametrize("depth, expected", [
    (MAX_NESTING + 1, f"tables or arrays nested {MAX_NESTING + 1} levels deep; at most {MAX_NESTING} are allowed"),
    (5000, f"tables or arrays nested too deeply; at most {MAX_NESTING} levels"),   # RecursionError in tomllib
])
def test_nesting_depth_is_bounded(tmp_path, depth, expected):
    path = tmp_path / "deep.toml"
    path.write_text("a = " + "[" * (depth - 1) + "]" * (depth - 1) + "\n")   # the top-level table is level 1
    assert _message(read_toml, path) == f"{path}: {expected}"


def test_validate_cli_refuses_dev_zero(capsys):
    assert main(["validate", "/dev/zero"]) == 2
    assert "/dev/zero: the case file is not a regular file" in capsys.readouterr().err


# ---------------------------------------------------------------------------- 6: files a case names
MESH = ('kind = "box"\nsize = [3.375, 3.75, 7.875]', 'kind = "mesh"\nfile = "{}"')


@pytest.mark.parametrize("file, expected", [
    ("/etc/passwd", "must be relative to the case file; an absolute path is not allowed. Got '/etc/passwd' instead"),
    ("../body.stl", "must be in the case file's folder or below it; a '..' component is not allowed. Got "
                    "'../body.stl' instead"),
    ("meshes/../../body.stl", "must be in the case file's folder or below it; a '..' component is not allowed"),
    ("", "must name a file; it is empty"),
])
def test_mesh_paths_stay_below_the_case(tmp_path, file, expected):
    message = _refused(tmp_path, IMPACT, MESH[0], MESH[1].format(file))
    assert "target.bodies[0].shapes[0].file: " in message and expected in message


@pytest.mark.parametrize("make, expected", [
    (lambda p: p.mkdir(), "mesh file 'body.stl' is a directory; a file is expected"),
    (lambda p: p.symlink_to("/dev/zero"), "mesh file 'body.stl' is not a regular file (a device, pipe or socket); "
                                          "a file is expected"),
    (lambda p: _sparse(p, MESH_FILE_LIMIT + 1),
     "mesh file 'body.stl' is 200,000,001 bytes; at most 200,000,000 bytes are read"),
    (lambda p: None, "mesh file 'body.stl' not found (paths are relative to the case file)"),
])
def test_mesh_file_is_a_regular_file_under_the_limit(tmp_path, make, expected):
    path = _case(tmp_path, IMPACT, *MESH)
    path.write_text(path.read_text().replace('file = "{}"', 'file = "body.stl"'))
    make(tmp_path / "body.stl")
    assert f"{path}: target.bodies[0].shapes[0].file: {expected}" in _message(load_case, path)


PERCEIVED = ('name = "debris"', 'name = "debris"\nmass_properties_from = "{}"')


def _perceived_case(tmp_path, source):
    """cases/tang2023_debris_perception.toml with its one body's mass properties from ``source``."""
    text = (CASES / "tang2023_debris_perception.toml").read_text()
    text = re.sub(r"^(mass|center_of_mass|inertia) = .*\n", "", text, flags=re.M)
    path = tmp_path / "case.toml"
    path.write_text(text.replace(*[PERCEIVED[0], PERCEIVED[1].format(source)]))
    return path


@pytest.mark.parametrize("source, make, expected", [
    ("dz", lambda p: p.symlink_to("/dev/zero"),
     "perception result 'dz' is not a regular file (a device, pipe or socket); a file is expected"),
    ("run", lambda p: p.mkdir(), "perception result 'run' is a directory; a file is expected"),
    ("big.json", lambda p: _sparse(p, JSON_FILE_LIMIT + 1),
     "perception result 'big.json' is 10,000,001 bytes; at most 10,000,000 bytes are read"),
    ("/dev/zero", lambda p: None, "perception result '/dev/zero' must be relative to the case file"),
    ("../p.json", lambda p: None, "perception result '../p.json' must be in the case file's folder or below it"),
    ("list.json", lambda p: p.write_text("[1, 2]"), "'list.json' is not a perception.json (a JSON object is expected)"),
    ("deep.json", lambda p: p.write_text("[" * 100000 + "]" * 100000), "'deep.json' is not a perception.json"),
])
def test_mass_properties_from_is_checked(tmp_path, source, make, expected):
    path = _perceived_case(tmp_path, source)
    if not source.startswith("/"):
        make(tmp_path / source)
    message = _message(load_case, path)
    assert message.startswith(f"{path}: target.bodies[0].mass_properties_from: {expected}"), message


@pytest.mark.parametrize("towing, make, expected", [
    ("/dev/zero", None, "towing: must be relative to the case file; an absolute path is not allowed. Got "
                        "'/dev/zero' instead"),
    ("../zenit2_towing.toml", None, "towing: must be in the case file's folder or below it; a '..' component is "
                                    "not allowed. Got '../zenit2_towing.toml' instead"),
    ("dz", lambda p: p.symlink_to("/dev/zero"),
     "towing: towing case 'dz' is not a regular file (a device, pipe or socket); a file is expected"),
    ("sub", lambda p: p.mkdir(), "towing: towing case 'sub' is a directory; a file is expected"),
    ("big.toml", lambda p: _sparse(p, CASE_FILE_LIMIT + 1),
     "towing: towing case 'big.toml' is 1,000,001 bytes; at most 1,000,000 bytes are read"),
])
def test_diagnosis_towing_reference_is_checked(tmp_path, towing, make, expected):
    path = _case(tmp_path, DIAGNOSE_TOWING, 'towing = "zenit2_towing.toml"', f'towing = "{towing}"')
    if make:
        make(tmp_path / towing)
    assert f"{path}: {expected}" in _message(load_diagnosis_case, path)


def test_diagnosis_towing_reference_in_a_subfolder_loads(tmp_path):
    path = _case(tmp_path, DIAGNOSE_TOWING, 'towing = "zenit2_towing.toml"', 'towing = "towing/zenit2_towing.toml"')
    (tmp_path / "towing").mkdir()
    (tmp_path / TOWING).rename(tmp_path / "towing" / TOWING)
    assert load_diagnosis_case(path).towing_case.name == "zenit2_towing"


# ---------------------------------------------------------------------------- 7, 10: overflow
@pytest.mark.parametrize("shipped, old, new, expected", [
    (IMPACT, "outer_diameter = 0.1", "outer_diameter = 1e308",
     "structures.weak_locations[2].section.outer_diameter: Input should be less than or equal to 20. Got 1e+308 "
     "instead"),
    (IMPACT, "mass = 350.0", "mass = 1e300",
     "target.bodies[1].mass: must be within +-1e+18 (no physical input comes near it; larger values overflow the "
     "arithmetic). Got 1e+300 instead"),
    (IMPACT, "mass = 350.0", "mass = 100000000000000000000000",   # an integer beyond int64 (9.2e18)
     "target.bodies[1].mass: must be within +-1e+18"),
    (TOWING, "mu = 3.986e14", "mu = 1e300", "simulation.mu: must be within +-1e+18"),
    (HINGED, "inertia = [[500.0, 0.0, 0.0]", "inertia = [[1e300, 0.0, 0.0]",
     "main_body.inertia: [0][0] must be within +-1e+18"),
])
def test_huge_values_are_refused_with_the_key(tmp_path, shipped, old, new, expected):
    assert expected in _refused(tmp_path, shipped, old, new)


def test_arithmetic_errors_in_section_checks_name_the_key(tmp_path, monkeypatch):
    import riskassess.cases.impact

    def overflowing(section):
        raise OverflowError("math range error")

    monkeypatch.setattr(riskassess.cases.impact, "section_properties", overflowing)
    message = _message(load_case, _case(tmp_path, IMPACT))
    assert f"{tmp_path / 'case.toml'}: structures.weak_locations[1].section: math range error" in message


# ---------------------------------------------------------------------------- 6, 10: measured CSV
def _record(path, bom=False):
    """A valid measured record: 40 samples (>= MIN_SAMPLES = 30) of one angular-velocity channel."""
    time = np.arange(40) * 0.1
    write_measured(path, time, {"omega_x": 0.01 * np.sin(time)})
    if bom:
        path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())
    return path


def test_measured_csv_with_a_byte_order_mark_is_read(tmp_path):
    plain, marked = _record(tmp_path / "plain.csv"), _record(tmp_path / "marked.csv", bom=True)
    assert read_measured(marked).channels == ["omega_x"]
    assert np.array_equal(read_measured(marked).time, read_measured(plain).time)


@pytest.mark.parametrize("make, expected", [
    (lambda p: p.symlink_to("/dev/zero"),
     "the measured-data file is not a regular file (a device, pipe or socket); a file is expected"),
    (lambda p: p.mkdir(), "the measured-data file is a directory; a file is expected"),
    (lambda p: _sparse(p, MEASURED_FILE_LIMIT + 1),
     "the measured-data file is 50,000,001 bytes; at most 50,000,000 bytes are read"),
    (lambda p: p.write_bytes(b"time,omega_x\n0.0,0.1\xff\n"),
     "not UTF-8 text: byte 20 is 0xff (save the measured-data file as UTF-8)"),   # 13 + 7 bytes before it
    (lambda p: p.write_text("time,omega_x\n0.0," + "1" * 200_000 + "\n"),   # csv's default field limit: 131072
     "not a CSV file (field larger than field limit (131072))"),
    (lambda p: p.write_text("time,omega_x\n" + "".join(f"{t},inf\n" for t in range(40))),
     "row 2, column 'omega_x': 'inf' is not a finite number (leave the cell empty, or write nan, for a missing "
     "sample)"),
])
def test_measured_csv_is_checked(tmp_path, make, expected):
    path = tmp_path / "measured.csv"
    make(path)
    with pytest.raises(MeasuredDataError) as info:
        read_measured(path)
    assert str(info.value) == f"{path}: {expected}"


def test_diagnose_cli_refuses_a_device_as_measured_data(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["diagnose", str(CASES / HINGED), "--measured", "/dev/zero", "--out", str(out)]) == 2
    assert ("error: /dev/zero: the measured-data file is not a regular file (a device, pipe or socket); a file is "
            "expected") in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("sigma", [float("nan"), float("inf"), 0.0])
def test_noise_sigma_must_be_finite_and_positive(tmp_path, sigma):
    with pytest.raises(MeasuredDataError) as info:
        read_measured(_record(tmp_path / "m.csv"), {"omega_x": sigma})
    assert str(info.value) == f"--noise omega_x: sigma must be finite and > 0. Got {sigma} instead"


def test_diagnose_output_folder_holds_the_towing_case(tmp_path):
    # the extended case and case.toml in a diagnosis output folder name the towing case relative to
    # themselves (no absolute path), so 'riskassess diagnose' copies it there
    from riskassess.stages.diagnose import _copy_towing_reference

    path, out = _case(tmp_path, DIAGNOSE_TOWING), tmp_path / "out"
    out.mkdir()
    assert _copy_towing_reference(out, path) == [TOWING]
    (out / "case.toml").write_bytes(path.read_bytes())
    assert load_diagnosis_case(out / "case.toml").towing_case.name == "zenit2_towing"
    assert _copy_towing_reference(out, _case(tmp_path, HINGED, name="hinged.toml")) == []
