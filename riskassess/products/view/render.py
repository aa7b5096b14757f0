"""Pictures of a :class:`~riskassess.products.view.scene.Scene`: 3-D snapshots (PNG) and an animation (GIF).

Drawn with matplotlib's ``mplot3d`` on the Agg canvas. Why not pyvista/VTK: off-screen VTK
needs an OpenGL context (OSMesa or EGL wheels, or an X server such as xvfb), which a plain CI
container or a fresh Debian lacks and which fails in ways a report should not (a crash in the
GL driver, a black image). Agg is pure software, already needed by the report's plots, and
draws the same picture on every machine. Its painter's sort is per collection, not per pixel,
which is good enough for a net around a few bodies.

Colours: threads by tension on the ``plasma`` map (slack: its darkest end); bodies light grey;
released pieces cyan, outside the ``plasma`` colours so that they stay recognisable; bullets black.
"""
from __future__ import annotations

import io
from pathlib import Path

import matplotlib
from matplotlib.animation import PillowWriter
from matplotlib.cm import ScalarMappable
from matplotlib.colors import LightSource, Normalize
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from riskassess.products.view.scene import Instant, Scene, decimation

TENSION_CMAP = "plasma"
BODY_COLOR = "#c8c8c8"
RELEASED_COLOR = "#17becf"   # matplotlib 'tab:cyan'
#: Viewing direction (deg): elevation and azimuth of the camera around the LVLH axes.
VIEW_ELEV, VIEW_AZIM = 22.0, -58.0


def tension_norm(scene: Scene) -> Normalize:
    """Colour scale of the thread tension (N): 0 to :meth:`Scene.tension_scale` (higher: top colour).

    Parameters
    ----------
    scene : Scene
        The run's scene.
    """
    return Normalize(0.0, max(scene.tension_scale(), 1e-9), clip=True)


def _axes(ax, scene: Scene):
    """Equal-scaled LVLH axes around the whole run, the report's camera."""
    low, high = scene.bounds()
    centre, half = 0.5 * (low + high), 0.5 * (high - low).max() * 1.02
    ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
           zlim=(centre[2] - half, centre[2] + half), xlabel="x radial (m)", ylabel="y along-track (m)",
           zlabel="z cross-track (m)")
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(VIEW_ELEV, VIEW_AZIM)
    ax.tick_params(labelsize=6, pad=0)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.label.set_size(7)
        axis.labelpad = -2
    return ax


def draw_frame(ax, scene: Scene, f: int, norm: Normalize) -> list:
    """Bodies (released ones cyan), threads coloured by tension and bullets of snapshot ``f``;
    returns the artists drawn (an animation removes them before the next frame).

    Parameters
    ----------
    ax : mpl_toolkits.mplot3d.axes3d.Axes3D
        3-D axes in LVLH (m).
    scene : Scene
        The run's scene.
    f : int
        Net snapshot index.
    norm : matplotlib.colors.Normalize
        Tension colour scale (N), from :func:`tension_norm`.
    """
    light = LightSource(azdeg=315, altdeg=45)
    released = scene.released(f)
    artists = []
    for k, (_, faces) in enumerate(scene.meshes):
        color = RELEASED_COLOR if released[k] else BODY_COLOR
        artists.append(ax.add_collection3d(Poly3DCollection(
            scene.body_vertices(f, k)[faces], facecolors=color, edgecolors=color, linewidths=0.2, shade=True,
            lightsource=light)))
    x = scene.positions[f]
    colors = matplotlib.colormaps[TENSION_CMAP](norm(scene.tension[f]))
    artists.append(ax.add_collection3d(Line3DCollection(x[scene.threads], colors=colors, linewidths=1.1)))
    bullets = x[len(x) - scene.n_bullets:]
    artists.append(ax.scatter(*bullets.T, s=6, color="k", depthshade=False))
    return artists


def _colorbar(fig, norm: Normalize, axes) -> None:
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=TENSION_CMAP), ax=axes, orientation="horizontal",
                       fraction=0.035, pad=0.03, aspect=40, shrink=0.6, extend="max")
    bar.set_label("thread tension (N)", size=7)
    bar.ax.tick_params(labelsize=6)


def _title(scene: Scene, f: int, label: str) -> str:
    released = [n for n, r in zip(scene.body_names, scene.released(f)) if r]
    text = f"{label}, t = {scene.time[f]:.3f} s"
    return text + (f"\nreleased (cyan): {', '.join(released)}" if released else "")


def snapshots_png(scene: Scene, instants: list[Instant], width_in: float, dpi: float) -> bytes:
    """The given instants two per row, one tension colour scale; PNG bytes.

    Parameters
    ----------
    scene : Scene
        The run's scene.
    instants : list of Instant
        The snapshots to draw, one panel each.
    width_in : float
        Figure width (inch).
    dpi : float
        Resolution (dots per inch).
    """
    norm = tension_norm(scene)
    cols = min(2, len(instants))
    rows = -(-len(instants) // cols)
    fig = Figure(figsize=(width_in, rows * 0.5 * width_in * 0.95 + 0.6), layout="constrained")
    axes = []
    for n, instant in enumerate(instants):
        ax = _axes(fig.add_subplot(rows, cols, n + 1, projection="3d"), scene)
        draw_frame(ax, scene, instant.frame, norm)
        ax.set_title(_title(scene, instant.frame, instant.label), fontsize=7.5)
        axes.append(ax)
    _colorbar(fig, norm, axes)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


def write_animation(scene: Scene, path: Path, max_frames: int = 30, size_in: float = 3.6, dpi: float = 80,
                    fps: float = 8.0) -> int:
    """The capture as an animated GIF at ``path`` (at most ``max_frames`` evenly spread snapshots,
    the first and last included); returns the number of frames written.

    Parameters
    ----------
    scene : Scene
        The run's scene.
    path : Path
        Destination ``.gif`` file (written directly; callers go through a temporary folder).
    max_frames : int
        Most frames, >= 2.
    size_in : float
        Width of the animation (inch); the height is 0.5 inch more.
    dpi : float
        Resolution (dots per inch).
    fps : float
        Frames per second of the GIF.
    """
    frames = decimation(scene.n_frames, max_frames)
    norm = tension_norm(scene)
    fig = Figure(figsize=(size_in, size_in + 0.5), layout="constrained")
    ax = _axes(fig.add_subplot(projection="3d"), scene)
    _colorbar(fig, norm, [ax])
    ax.set_title(_title(scene, int(frames[-1]), "capture"), fontsize=7)
    fig.canvas.draw()
    fig.set_layout_engine("none")   # laid out once: the frames differ only in their artists
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi):
        for f in frames:
            artists = draw_frame(ax, scene, int(f), norm)
            ax.set_title(_title(scene, int(f), "capture"), fontsize=7)
            writer.grab_frame()
            for artist in artists:
                artist.remove()
    return len(frames)
