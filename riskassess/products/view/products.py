"""Write the animation (``capture.gif``) and the viewer (``viewer.html``) next to a run's report.

Both are products of the run folder (listed under ``products`` in its manifest), written
atomically and never over a file the tool did not make (:func:`riskassess.products.outfolder.claim_product`).
"""
from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

from riskassess.products.outfolder import claim_product
from riskassess.products.results import RunFolder, atomic_write_bytes
from riskassess.products.view.render import write_animation
from riskassess.products.view.scene import scene_of
from riskassess.products.view.viewer import VIEWER_MAX_FRAMES, viewer_html

ANIMATION, VIEWER = "capture.gif", "viewer.html"


@dataclass
class ViewFiles:
    animation: Path
    animation_frames: int
    viewer: Path


def write_views(run: RunFolder, animation_frames: int = 30, viewer_frames: int = VIEWER_MAX_FRAMES) -> ViewFiles:
    """``capture.gif`` (at most ``animation_frames`` frames) and ``viewer.html`` (at most
    ``viewer_frames`` snapshots) in the run folder; :class:`~riskassess.products.results.MissingData` when the
    folder lacks the net or the bodies.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``net.npz``, ``timeseries.npz``, ``bodies.npz``).
    animation_frames : int
        Most frames of the GIF, >= 2.
    viewer_frames : int
        Most snapshots of the viewer, >= 2.

    Returns
    -------
    ViewFiles
    """
    scene = scene_of(run)
    for name in (ANIMATION, VIEWER):
        claim_product(run.path, run.manifest, name)
    with tempfile.TemporaryDirectory(dir=run.path, prefix=f".{ANIMATION}.") as tmp:
        frames = write_animation(scene, Path(tmp) / ANIMATION, animation_frames)
        atomic_write_bytes(run.path / ANIMATION, (Path(tmp) / ANIMATION).read_bytes())
    run.add_product(ANIMATION)
    title = f"Net capture: {run.manifest.get('case', run.path.name)}"
    atomic_write_bytes(run.path / VIEWER, viewer_html(scene, title, viewer_frames).encode("utf-8"))
    run.add_product(VIEWER)
    return ViewFiles(run.path / ANIMATION, frames, run.path / VIEWER)
