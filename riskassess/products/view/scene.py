"""The capture as a 3-D scene: what every picture of a run draws, read once from its run folder.

One frame per net snapshot (``net.npz``); body poses from the time-series sample nearest to it
(the same rule as the VTK export). All positions in LVLH (m), forces in N.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multibody.net import thread_tension_strain
from riskassess.products.results import MissingData, RunFolder
from riskassess.products.vtk_export import release_times_by_body
from riskassess.products.vtk_frames import nearest_samples, surface_lvlh


#: Percentile of the thread tension samples at the top of the colour scale (see Scene.tension_scale).
TENSION_SCALE_PERCENTILE = 99.5


@dataclass(frozen=True)
class Instant:
    """A moment worth a picture: ``label`` (e.g. 'first contact'), snapshot index ``frame``."""
    label: str
    frame: int
    time: float


class Scene:
    """Net, bodies and loads of a run per net snapshot.

    Attributes
    ----------
    time : (k,) float
        Snapshot times (s).
    positions : (k, n, 3) float
        Net node positions (m), LVLH; the bullets are the last ``n_bullets`` nodes.
    threads : (m, 2) int
        Node pairs of the threads.
    tension : (k, m) float
        Thread tension (N), tension-only Kelvin-Voigt law (:func:`multibody.net.thread_tension_strain`).
    node_contact_force : (k, n, 3) float or None
        Contact force on each node (N), LVLH; None for run folders written before it was recorded.
    body_names : list of str
    released_from : (nb,) float
        Time each body's piece is released (s); inf when never.
    """

    def __init__(self, run: RunFolder):
        series, net, meshes = run.timeseries, run.net, run.bodies   # a tow folder has no time series
        self.run = run
        self.time = np.asarray(net["time"], float)
        self.positions = np.asarray(net["positions_lvlh"], float)
        self.threads = np.asarray(net["threads"], np.int64)
        self.n_bullets = int(net["n_bullets"])
        self.tension, _ = thread_tension_strain(self.positions, net["velocities_lvlh"], self.threads,
                                                net["rest_lengths"], net["stiffness"], net["damping"])
        self.node_contact_force = net.get("contact_force_lvlh")
        self.body_names = [str(n) for n in series["body_names"]]
        self.meshes = []
        for k, name in enumerate(self.body_names):
            if f"vertices_{k}" not in meshes:
                raise MissingData(f"{run.path / 'bodies.npz'}: no mesh of body {k} ({name})")
            self.meshes.append((np.asarray(meshes[f"vertices_{k}"], float), np.asarray(meshes[f"faces_{k}"])))
        self.series = series
        self.sample = nearest_samples(series["time"], self.time)
        self.released_from = release_times_by_body(run, self.body_names)

    @property
    def n_frames(self) -> int:
        return len(self.time)

    def body_pose(self, f: int, k: int):
        """(body_to_lvlh (3, 3), CoM (3,) m LVLH) of body ``k`` at snapshot ``f``.

        Parameters
        ----------
        f : int
            Net snapshot index.
        k : int
            Body index (order of ``body_names``).
        """
        i = self.sample[f]
        return self.series["body_to_lvlh"][i, k], self.series["body_com_lvlh"][i, k]

    def body_vertices(self, f: int, k: int) -> np.ndarray:
        """Surface vertices (m, LVLH) of body ``k`` at snapshot ``f``.

        Parameters
        ----------
        f : int
            Net snapshot index.
        k : int
            Body index (order of ``body_names``).

        Returns
        -------
        (v, 3) float
            The body's mesh vertices (m), LVLH.
        """
        return surface_lvlh(self.meshes[k][0], *self.body_pose(f, k))

    def body_contact_force(self, f: int) -> np.ndarray:
        """(nb, 3) net contact force on each body (N, LVLH) at the sample nearest snapshot ``f``.

        Parameters
        ----------
        f : int
            Net snapshot index.
        """
        return np.asarray(self.series["contact_force_lvlh"][self.sample[f]], float)

    def released(self, f: int) -> np.ndarray:
        """(nb,) bool: the body belongs to a piece released at or before snapshot ``f``.

        Parameters
        ----------
        f : int
            Net snapshot index.
        """
        return self.time[f] >= self.released_from

    def instants(self) -> list[Instant]:
        """First contact, peak contact load, each release, end: the snapshot at or just after each."""
        s = self.series
        force = np.linalg.norm(np.asarray(s["contact_force_lvlh"], float), axis=2).sum(axis=1)
        wanted = []
        touching = np.flatnonzero(force > 0.0)
        if len(touching):
            wanted.append(("first contact", float(s["time"][touching[0]])))
            wanted.append(("peak contact load", self._peak_time(force)))
        for t in sorted(set(self.released_from[np.isfinite(self.released_from)])):
            names = [n for n, r in zip(self.body_names, self.released_from) if r == t]
            wanted.append((f"release of {'+'.join(names)}", float(t)))
        wanted.append(("end", float(self.time[-1])))
        instants = []
        for label, t in wanted:
            f = min(int(np.searchsorted(self.time, t - 1e-12)), self.n_frames - 1)
            instants.append(Instant(label, f, float(self.time[f])))
        return instants

    def tension_scale(self) -> float:
        """Top of the tension colour scale (N): the 99.5th percentile of the pulling threads' samples,
        so that one short spike (a bullet tether snapping taut) does not darken every other thread;
        the few above it take the top colour."""
        pulling = self.tension[self.tension > 0.0]
        return float(np.percentile(pulling, TENSION_SCALE_PERCENTILE)) if pulling.size else 1.0

    def _peak_time(self, force) -> float:
        """Time (s) of the peak contact force the report's contact section states (summary.json); the
        largest sum of the bodies' contact forces for folders without it."""
        try:
            return float(self.run.key(self.run.summary, "peak_contact_force_N", "time_s"))
        except MissingData:
            return float(self.series["time"][force.argmax()])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box (m, LVLH) holding the net and the bodies over the whole run."""
        points = [self.positions.reshape(-1, 3)]
        for k in range(len(self.meshes)):
            points += [self.body_vertices(f, k) for f in (0, self.n_frames // 2, self.n_frames - 1)]
        points = np.vstack(points)
        return points.min(axis=0), points.max(axis=0)


def scene_of(run: RunFolder) -> Scene:
    """The run's scene, built once per :class:`RunFolder` (the report, the animation and the viewer share it).

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``net.npz``, ``timeseries.npz``, ``bodies.npz``).
    """
    return run.cached("scene", Scene)


def decimation(n_frames: int, max_frames: int) -> np.ndarray:
    """Indices of at most ``max_frames`` evenly spread snapshots, the first and the last included.

    Parameters
    ----------
    n_frames : int
        Snapshots available.
    max_frames : int
        Most snapshots to keep, >= 2.

    Returns
    -------
    (m,) int
        Increasing snapshot indices, m <= ``max_frames``.
    """
    if max_frames < 2:
        raise ValueError(f"max_frames must be >= 2; got {max_frames}")
    if n_frames <= max_frames:
        return np.arange(n_frames)
    return np.unique(np.round(np.linspace(0, n_frames - 1, max_frames)).astype(int))
