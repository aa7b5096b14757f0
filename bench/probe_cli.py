"""Hostile-input probes of the whole CLI: every command, fed what a careless or hostile
user would feed it, must answer with a clear error or a correct result, and never touch a file
it did not create.

Each probe runs ``riskassess.cli.main`` in-process in a scratch folder and is *handled* when

* it returns (or argparse exits with) one of the exit codes the probe allows (docs/outputs.md:
  0 done, 1 product failed, 2 invalid input or refused output, 5 failed simulation,
  6 indeterminate verdict), and
* no other exception escapes (a traceback is a failure of the tool), and
* the user's files placed around it (a "thesis" folder, a foreign SQLite file, the run folder's
  own results) are byte-identical afterwards.

Families: ``files`` (every case-taking command on /dev/zero, a folder, an empty, binary,
non-UTF-8, deeply nested, oversized, symlinked or missing file), ``values`` (every scalar of the
shipped cases replaced by NaN, inf, +-1e308, a numeric string, a boolean, -1, 0, through
``validate``; ``--per-case`` scalars per case, drawn with ``--seed``), ``options`` (out-of-range
or malformed options of every command), ``outputs`` (output folders that hold other files, other
runs, the run itself), ``runs`` (short simulations that diverge, judge nothing or sample nothing).

Usage: python3 bench/probe_cli.py [--families files values options outputs runs] [--per-case 12]
"""
from __future__ import annotations

import argparse
import contextlib
import hashlib
import io
import math
import os
import random
import shutil
import sqlite3
import tempfile
import tomllib
from pathlib import Path

from riskassess.cli import main

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
SMALL = CASES / "envisat_small.toml"
CASE_COMMANDS = {"validate": [], "run": [], "assess": [], "perceive": [], "tow": [], "identify": [],
                 "approach": [], "diagnose": ["--measured", str(CASES / "data" / "hinged_appendage_friction.csv")]}
BAD_VALUES = [math.nan, math.inf, -math.inf, 1e308, -1e308, "0.2", True, -1, 0]


def run_probe(argv: list[str], allowed: set[int]) -> tuple[bool, str]:
    """(handled, what happened) of ``riskassess argv``."""
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(argv)
    except SystemExit as exc:          # argparse's usage errors
        code = exc.code if isinstance(exc.code, int) else 2
    except BaseException as exc:       # anything else is a traceback for the user
        return False, f"{type(exc).__name__}: {str(exc)[:160]}"
    message = (err.getvalue().strip().splitlines() or [""])[-1][:160]
    return code in allowed, f"exit {code}: {message}"


def fingerprint(*paths: Path) -> str:
    """Hash of every file under ``paths`` (names and bytes): the user's files must not change."""
    digest = hashlib.sha256()
    for root in paths:
        for p in sorted(Path(root).rglob("*")) if Path(root).is_dir() else [Path(root)]:
            if p.is_file():
                digest.update(str(p.relative_to(root.parent)).encode() + p.read_bytes())
    return digest.hexdigest()


# ---------------------------------------------------------------------------- families
def files_family(tmp: Path):
    nested = "a = " + "[" * 5000 + "]" * 5000 + "\n"
    samples = {"dev_zero": Path("/dev/zero"), "folder": tmp / "folder", "empty.toml": tmp / "empty.toml",
               "binary.toml": tmp / "binary.toml", "latin1.toml": tmp / "latin1.toml",
               "nested.toml": tmp / "nested.toml", "big.toml": tmp / "big.toml", "link.toml": tmp / "link.toml",
               "missing.toml": tmp / "missing.toml"}
    samples["folder"].mkdir()
    samples["empty.toml"].write_bytes(b"")
    samples["binary.toml"].write_bytes(bytes(range(256)) * 8)
    samples["latin1.toml"].write_bytes('name = "d\xe9bris"\n'.encode("latin-1"))
    samples["nested.toml"].write_text(nested)
    samples["big.toml"].write_text("# padding\n" * 300_000)
    samples["link.toml"].symlink_to("/dev/zero")
    for command, extra in CASE_COMMANDS.items():
        for label, path in samples.items():
            out = [] if command == "validate" else ["--out", str(tmp / f"out_{command}_{label}")]
            yield f"{command} {label}", [command, str(path), *extra, *out], {2}


def _scalar_slots(node, prefix=""):
    items = node.items() if isinstance(node, dict) else enumerate(node)
    for key, value in items:
        path = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, (dict, list)):
            yield from _scalar_slots(value, path)
        else:
            yield path


def _set(node, path: str, value):
    *parents, last = path.split(".")
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    node[int(last) if isinstance(node, list) else last] = value


def _toml(node, prefix="") -> str:
    """A minimal TOML writer for the parsed cases (tables, arrays of tables, scalars, arrays)."""
    def scalar(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float):
            return "nan" if math.isnan(v) else ("inf" if v == math.inf else "-inf" if v == -math.inf else repr(v))
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, list):
            return "[" + ", ".join(scalar(x) for x in v) + "]"
        return repr(v)

    lines, tables = [], []
    for key, value in node.items():
        if isinstance(value, dict):
            tables.append((key, value, False))
        elif isinstance(value, list) and value and all(isinstance(x, dict) for x in value):
            tables.append((key, value, True))
        else:
            lines.append(f"{key} = {scalar(value)}")
    text = "\n".join(lines) + "\n"
    for key, value, many in tables:
        name = f"{prefix}.{key}" if prefix else key
        for item in (value if many else [value]):
            text += f"\n[[{name}]]\n" if many else f"\n[{name}]\n"
            text += _toml(item, name)
    return text


def values_family(tmp: Path, per_case: int, seed: int):
    rng = random.Random(seed)
    copy = tmp / "cases"
    shutil.copytree(CASES, copy)  # mutated cases sit beside copies of the files they name
    for case in sorted(copy.glob("*.toml")):
        parsed = tomllib.loads(case.read_text())
        slots = list(_scalar_slots(parsed))
        for slot in rng.sample(slots, min(per_case, len(slots))):
            for value in BAD_VALUES:
                mutated = tomllib.loads(case.read_text())
                _set(mutated, slot, value)
                path = copy / f"probe_{case.stem}.toml"
                path.write_text(_toml(mutated))
                yield f"validate {case.stem} {slot}={value!r}", ["validate", str(path)], {0, 2}


def options_family(tmp: Path):
    sweep = ["sweep", str(SMALL), "--store", str(tmp / "store" / "results.sqlite")]
    for opts in (["--workers", "0"], ["--workers", "-1"], ["--confidence", "1.5"], ["--confidence", "nan"],
                 ["--reliability", "0"], ["--vary", "launch.velocity=1:2"], ["--vary", "launch.velocity=1:2:0"],
                 ["--vary", "launch.velocity=1:2:10000000"], ["--vary", "launch.velocity=nan:1:3"],
                 ["--vary", "no.such.key=1:2:3"], ["--monte-carlo", "-1"], ["--uncertain", "launch.velocity=normal(1)"],
                 ["--uncertain", "launch.velocity=uniform(2,1)"], ["--seed", "-5"]):
        yield f"sweep {' '.join(opts)}", [*sweep, *opts], {2}
    yield "export-vtk --every 0", ["export-vtk", str(tmp), "--every", "0"], {2}
    for noise in ("x=nan", "x=-1", "x=abc", "=1"):
        yield f"diagnose --noise {noise}", ["diagnose", str(CASES / "diagnose_hinged_appendage.toml"), "--measured",
                                             str(CASES / "data" / "hinged_appendage_friction.csv"), "--noise", noise,
                                             "--out", str(tmp / "diag")], {2}
    yield "identify --optimizers bogus", ["identify", str(CASES / "zenit2_towing.toml"), "--optimizers", "bogus"], {2}
    yield "identify --cost f3", ["identify", str(CASES / "zenit2_towing.toml"), "--cost", "f3"], {2}
    yield "sweep-status on a 0-byte file", ["sweep-status", str(_file(tmp / "zero.sqlite", b""))], {2}
    yield "sweep-status on garbage", ["sweep-status", str(_file(tmp / "garbage.sqlite", b"SQLite format 3\0" + b"x" * 99))], {2}
    yield "sweep-status on a folder", ["sweep-status", str(tmp)], {2}


def _file(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def _short_case(tmp: Path, name: str, **simulation) -> Path:
    text = SMALL.read_text().replace("end_time = 7.5", f"end_time = {simulation.pop('end_time', 0.3)}", 1)
    for key, value in simulation.items():
        text = "\n".join(f"{key} = {value}" if line.startswith(f"{key} = ") else line for line in text.splitlines())
    path = tmp / name  # envisat_small names no files: the copy loads from anywhere
    path.write_text(text + "\n")
    return path


def outputs_family(tmp: Path):
    """Output folders that must be refused; the 'thesis' folder and the run's results must not change."""
    case = _short_case(tmp, "short.toml")
    run = tmp / "run"
    code, _ = run_probe(["run", str(case), "--out", str(run)], {0, 6})
    thesis = tmp / "thesis"
    thesis.mkdir()
    (thesis / "chapter1.tex").write_text("\\chapter{Results}\n")
    foreign_db = _file(tmp / "other.sqlite", b"")
    with sqlite3.connect(foreign_db) as db:
        db.execute("create table notes (x)")
    guarded = [thesis, run, foreign_db]
    yield "run into the thesis folder", ["run", str(case), "--out", str(thesis)], {2}, guarded
    yield "run into an existing file", ["run", str(case), "--out", str(thesis / "chapter1.tex")], {2}, guarded
    yield "re-run without --overwrite", ["run", str(case), "--out", str(run)], {2}, guarded
    other = _short_case(tmp, "other_case.toml")
    other.write_text(other.read_text().replace('name = "envisat_small"', 'name = "other_case"'))
    yield "another case into the run folder", ["run", str(other), "--out", str(run), "--overwrite"], {2}, guarded
    yield "export-vtk into the thesis folder", ["export-vtk", str(run), "--out", str(thesis)], {2}, guarded
    yield "export-vtk into the thesis folder, --overwrite", ["export-vtk", str(run), "--out", str(thesis),
                                                             "--overwrite"], {2}, guarded
    yield "export-vtk into the run folder", ["export-vtk", str(run), "--out", str(run)], {2}, guarded
    yield "export-vtk into the run's parent", ["export-vtk", str(run), "--out", str(tmp)], {2}, guarded
    yield "report of the thesis folder", ["report", str(thesis)], {2}, guarded
    yield "sweep-status on a foreign SQLite file", ["sweep-status", str(foreign_db)], {2}, guarded
    yield "sweep with a foreign SQLite store", ["sweep", str(case), "--store", str(foreign_db),
                                                "--vary", "launch.velocity=10:20:2"], {2}, guarded


def runs_family(tmp: Path):
    yield "diverging step 1e-2 s", ["assess", str(_short_case(tmp, "d.toml", end_time=0.6, step="1e-2",
                                                              output_rate="100.0")), "--out", str(tmp / "d")], {5}
    yield "end_time before skip_initial", ["assess", str(_short_case(tmp, "e.toml", end_time=0.2)),
                                           "--out", str(tmp / "e")], {6}
    yield "output_rate 1e-300", ["assess", str(_short_case(tmp, "o.toml", end_time=0.4, output_rate="1e-300")),
                                 "--out", str(tmp / "o")], {0, 6}
    yield "end_time 1e6 s", ["run", str(_short_case(tmp, "h.toml", end_time="1e6")), "--out", str(tmp / "h")], {2}
    yield "end_time inf", ["run", str(_short_case(tmp, "i.toml", end_time="inf")), "--out", str(tmp / "i")], {2}


# ---------------------------------------------------------------------------- driver
def main_probes(families: list[str], per_case: int, seed: int) -> int:
    totals = {}
    unhandled = []
    with tempfile.TemporaryDirectory(prefix="riskassess-probe-") as scratch:
        cwd = os.getcwd()
        os.chdir(scratch)  # default output folders (runs/, sweeps/) land in the scratch folder
        try:
            for family in families:
                tmp = Path(scratch) / family
                tmp.mkdir()
                source = {"files": lambda: files_family(tmp), "values": lambda: values_family(tmp, per_case, seed),
                          "options": lambda: options_family(tmp), "outputs": lambda: outputs_family(tmp),
                          "runs": lambda: runs_family(tmp)}[family]()
                tried = handled = 0
                for name, argv, allowed, *extra in source:
                    guarded = extra[0] if extra else []
                    before = fingerprint(*guarded) if guarded else None
                    ok, what = run_probe(argv, allowed)
                    if guarded and fingerprint(*guarded) != before:
                        ok, what = False, f"a user's file changed ({what})"
                    tried += 1
                    handled += ok
                    if not ok:
                        unhandled.append(f"{family}: {name}: {what}")
                totals[family] = (tried, handled)
                shutil.rmtree(tmp, ignore_errors=True)
        finally:
            os.chdir(cwd)
    print(f"{'family':10s} {'tried':>6s} {'handled':>8s}")
    for family, (tried, handled) in totals.items():
        print(f"{family:10s} {tried:6d} {handled:8d}")
    print(f"{'all':10s} {sum(t for t, _ in totals.values()):6d} {sum(h for _, h in totals.values()):8d}")
    for line in unhandled:
        print("NOT HANDLED", line)
    return 1 if unhandled else 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--families", nargs="+", default=["files", "values", "options", "outputs", "runs"])
    parser.add_argument("--per-case", type=int, default=12, help="scalars mutated per shipped case (values family)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    raise SystemExit(main_probes(args.families, args.per_case, args.seed))
