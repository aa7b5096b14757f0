"""The capture in pictures: the report's 3-D snapshots, the animation, the offline viewer (in headless
Chromium), the net's integrity, and plotted values that stop where a load path is released."""
import base64
import io
import json
import re
import shutil
import subprocess

import matplotlib
import numpy as np
import pytest
from PIL import Image

from multibody.net import thread_tension_strain
from riskassess.products.report import write_report
from riskassess.products.report.capture import net_integrity_section
from riskassess.products.report.structures import while_joined
from riskassess.products.results import RunFolder
from riskassess.products.view.render import BODY_COLOR, RELEASED_COLOR, TENSION_CMAP

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def reported(assessed, tmp_path_factory):
    """A copy of the session's assessed run with its report, animation and viewer (HTML only: the PDF
    is test_report's)."""
    run = tmp_path_factory.mktemp("view") / "run"
    shutil.copytree(assessed, run)
    return write_report(run, pdf=False)


def _rgb(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"), float)


def _near(pixels: np.ndarray, colors: np.ndarray, tolerance: float = 12.0) -> np.ndarray:
    """Per pixel: within ``tolerance`` (RGB 0-255, Euclidean) of one of ``colors``."""
    flat = pixels.reshape(-1, 3)
    best = np.full(len(flat), np.inf)
    for c in colors:
        best = np.minimum(best, np.linalg.norm(flat - c, axis=1))
    return best <= tolerance


#: The tension colour map sampled finely; greys (bodies, axes, text) are far from all of it.
PLASMA = np.array(matplotlib.colormaps[TENSION_CMAP](np.linspace(0, 1, 64)))[:, :3] * 255


def _assert_a_scene(pixels: np.ndarray, min_net_fraction: float) -> None:
    """Not blank (varied pixels, much of the image not white) and the net's colours present."""
    assert pixels.std() > 20
    assert (pixels.min(axis=2) < 235).mean() > 0.05
    assert _near(pixels, PLASMA).mean() > min_net_fraction


def test_report_snapshots_show_the_net_by_tension_and_the_released_piece(reported):
    html = reported.html.read_text()
    png = re.search(r'<figure id="fig-capture">\s*<img src="data:image/png;base64,([^"]+)"', html)
    pixels = _rgb(base64.b64decode(png.group(1)))
    # the net's threads are ~1 px lines over four panels: a few tenths of a per cent of the image
    _assert_a_scene(pixels, 0.003)
    cyan = np.array(matplotlib.colors.to_rgb(RELEASED_COLOR)) * 255
    # shaded faces of the released piece: darker or lighter tones of its cyan, same hue
    hue = matplotlib.colors.rgb_to_hsv(pixels / 255)
    cyan_hue = matplotlib.colors.rgb_to_hsv(cyan / 255)[0]
    assert ((np.abs(hue[..., 0] - cyan_hue) < 0.02) & (hue[..., 1] > 0.5)).mean() > 0.002
    grey = np.array(matplotlib.colors.to_rgb(BODY_COLOR))
    assert grey.std() == 0   # bodies are neutral grey, never mistaken for the net's colours
    section = html[html.index('<section id="capture"'):]
    for label in ("first contact", "peak contact load", "release of solar_array", "end"):
        assert f"<td>{label}</td>" in section


def test_animation_is_a_gif_of_the_capture(reported):
    gif = Image.open(reported.views.animation)
    assert gif.format == "GIF" and gif.n_frames == reported.views.animation_frames >= 10
    gif.seek(gif.n_frames // 2)
    _assert_a_scene(np.asarray(gif.convert("RGB"), float), 0.002)
    manifest = json.loads((reported.html.parent / "manifest.json").read_text())
    assert {"capture.gif", "viewer.html"} <= set(manifest["products"])


@pytest.mark.skipif(CHROMIUM is None, reason="needs Debian's chromium (./install.sh --test installs it)")
def test_viewer_loads_offline_without_errors_and_draws_the_scene(reported, tmp_path):
    viewer = reported.views.viewer
    text = viewer.read_text()
    assert not re.search(r'(src|href)\s*=\s*"(https?:|//)', text)   # nothing fetched at view time
    flags = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
             "--disable-component-update", "--no-first-run", f"--user-data-dir={tmp_path / 'profile'}",
             "--enable-logging=stderr", "--v=0", "--window-size=1000,700", "--virtual-time-budget=5000"]
    dom = subprocess.run(flags + ["--dump-dom", viewer.as_uri()], capture_output=True, text=True, timeout=120,
                         check=False)
    assert 'data-status="drawn"' in dom.stdout, dom.stdout[-2000:] + dom.stderr[-2000:]
    assert int(re.search(r'data-items="(\d+)"', dom.stdout).group(1)) > 100
    console = [line for line in dom.stderr.splitlines() if "CONSOLE" in line or "Uncaught" in line]
    assert not console, console
    shot = tmp_path / "viewer.png"
    done = subprocess.run(flags + [f"--screenshot={shot}", viewer.as_uri()], capture_output=True, text=True,
                          timeout=120, check=False)
    assert shot.is_file(), done.stderr[-2000:]
    _assert_a_scene(_rgb(shot.read_bytes()), 0.005)


def test_net_integrity_lists_threads_over_the_breaking_load(assessed, tmp_path):
    run_dir = tmp_path / "run"
    shutil.copytree(assessed, run_dir)
    net = np.load(run_dir / "net.npz")
    tension, _ = thread_tension_strain(net["positions_lvlh"], net["velocities_lvlh"], net["threads"],
                                       net["rest_lengths"], net["stiffness"], net["damping"])
    peak = tension.max(axis=0)
    breaking = float(np.quantile(peak, 0.98))   # a load a few threads reach
    expected_over = int((peak >= breaking).sum())
    assert expected_over >= 1
    without = net_integrity_section(RunFolder(run_dir))
    assert any("not assessed" in getattr(b, "text", "") for b in without.blocks)
    case = json.loads((run_dir / "case.json").read_text())
    case["net"]["thread"]["breaking_load"] = breaking
    (run_dir / "case.json").write_text(json.dumps(case))
    section = net_integrity_section(RunFolder(run_dir))
    alarm = next(b for b in section.blocks if getattr(b, "kind", "") == "alarm")
    assert alarm.text.startswith(f"NET DAMAGE: {expected_over} thread(s)")
    listed = next(b for b in section.blocks if getattr(b, "caption", "").startswith("Threads at or over"))
    assert len(listed.rows) == min(expected_over, 20)
    assert listed.rows[0][1] == f"{peak.max():.4g}"


def test_no_demand_is_plotted_after_its_release(assessed):
    run = RunFolder(assessed)
    loc = next(loc for loc in run.structures["locations"] if loc["released_at_s"] is not None)
    t = run.structures_series["time"]
    raw = run.structures_series[f"{loc['name']}/moment"]
    shown = while_joined(t, raw, loc)
    after = t > loc["released_at_s"]
    assert after.any() and np.isnan(shown[after]).all()
    assert np.array_equal(shown[~after], raw[~after])
    assert (raw[after] == 0).all()   # what the plot drew before: a released joint reads 0 N m


def test_report_states_one_unit_per_quantity(reported):
    html = reported.html.read_text()
    for mixed in ("mm/s", "deg/s", "(kN)", "kN m", "(deg)"):
        assert mixed not in html, mixed
    motion = html[html.index('<section id="debris-motion"'):]
    assert "final velocity change (m/s, LVLH)" in motion and "(rad/s, body frame)" in motion
