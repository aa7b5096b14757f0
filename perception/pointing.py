"""Where the chaser's pan-tilt LiDAR mount looks while the net captures the debris.

The mount aims at the debris' CoM predicted from its registered track: the CoM of the good frames
(a body point of frame B, found by the observation's CoM line) carried forward in a straight line
by the CoM velocity fitted over the last good frames. The velocity is kept through a lost track, so
the boresight follows a debris the net has pushed off even while its registration fails (the net
wrapped on it, too few returns). Aiming at the last good pose instead, standing still, lost the
featured debris for good: its track failed at 0.7 s, it left at 3.15 m/s, and the chaser, still
closing on the old aim point, turned its boresight away (0 returns from 2 to 12 s,
docs/perception.md).

While the track is lost the debris is looked for among the returns the predicted net does not
explain: the ball of the body's size holding most of them (:func:`debris_blob`); the next frame
aims at its centre, and only its returns are offered to the registration's search (the stage).
When a lost track's frame shows no return that could be the debris, the next frame widens the
look: the boresight steps through :data:`SEARCH_ELEVATIONS`, offsets towards and away from the
mount's up axis about the predicted direction (the field of view is narrow in elevation, 30 deg on
the paper's C-Fans-256, and 150 deg wide in azimuth). A frame that sees returns again goes back to
the predicted direction.

Frame: the stage's world frame, the collision run's LVLH. The straight-line carry ignores the
relative-orbit terms: with a circular orbit (n ~ 1.1e-3 rad/s in LEO) the Coriolis acceleration
2 n v moves a body flying at 3 m/s by n v t^2 ~ 0.3 m in 10 s, 0.6 deg at the 30 m it has reached
then, far inside the beam; with ``orbit.kind = "none"`` the frame is inertial and the carry exact
for a free body.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: The CoM velocity is fitted over the good frames at most this long (s) before the last one, and
#: at most VELOCITY_FRAMES of them: during the contact the velocity changes within ~1 s, so only
#: the latest frames say how the debris leaves.
VELOCITY_WINDOW = 0.5
VELOCITY_FRAMES = 5
#: Search pattern of a lost track that sees nothing (rad): the boresight's elevation about the
#: predicted direction at the 1st, 2nd, ... consecutive frame that saw nothing, cycled. It stays on
#: the prediction for the first two (the debris may be hidden behind the net for a frame or two),
#: then widens in 20 deg steps, back on the prediction between them. With the paper's 30 deg field
#: of view the steps overlap by 10 deg and the pattern covers +-70 deg of elevation (+-75 deg in
#: azimuth is the sensor's own field); one cycle takes 11 frames (1.1 s at 10 Hz).
SEARCH_ELEVATIONS = np.radians([0.0, 0.0, 20.0, -20.0, 0.0, 40.0, -40.0, 0.0, 55.0, -55.0, 0.0])


#: Mean-shift steps of :func:`debris_blob` (each moves the centre to the mean of the returns within
#: the body's radius of it; it settles in 3-5 on a compact body).
BLOB_STEPS = 10


def debris_blob(points_world, starts_world, radius) -> tuple[np.ndarray | None, np.ndarray]:
    """The debris among a frame's returns when its track is lost: the ball of the body's ``radius``
    (m) holding the most returns, found by mean shift (flat kernel) from each start and from the
    returns' centroid. The net's threads spread their returns over metres; the debris packs tens of
    thousands into one body's size. One start is not enough: from a CoM carried at the velocity
    the debris had in the contact (still rising), the shift settled on a patch of net threads
    (1 300-1 700 returns) beside the debris' 10 000-20 000 (featured debris, 2.1-3.6 s).

    Parameters
    ----------
    points_world : (n, 3) float
        Returns not taken as net, world frame (m).
    starts_world : sequence of (3,) float or None
        Where the debris may be (m, world), e.g. its carried CoM and where it was last seen; None
        entries are skipped.
    radius : float
        Radius of the debris about its centre (m).

    Returns
    -------
    centre : (3,) float or None
        Centre of the ball (m, world); None without returns.
    inside : (n,) bool
        Returns within ``radius`` of it.
    """
    points = np.asarray(points_world, float)
    if len(points) == 0:
        return None, np.zeros(0, bool)
    best, best_inside = None, np.zeros(len(points), bool)
    for start in [points.mean(axis=0)] + [s for s in starts_world if s is not None]:
        centre, inside = _mean_shift(points, np.asarray(start, float), radius)
        if inside.sum() > best_inside.sum():
            best, best_inside = centre, inside
    return best, best_inside


def _mean_shift(points, centre, radius) -> tuple[np.ndarray, np.ndarray]:
    """Flat-kernel mean shift of ``centre`` (3,) over ``points`` (n, 3) (m): the ball's centre and
    the points in it (empty when the ball holds none)."""
    inside = np.zeros(len(points), bool)
    for _ in range(BLOB_STEPS):
        inside = np.einsum("ij,ij->i", points - centre, points - centre) <= radius**2
        if not inside.any():
            break
        moved = points[inside].mean(axis=0)
        settled = np.linalg.norm(moved - centre) < 1e-3 * radius
        centre = moved
        if settled:
            break
    return centre, np.einsum("ij,ij->i", points - centre, points - centre) <= radius**2


def _turned_towards(direction, up, angle) -> np.ndarray:
    """``direction`` (3,) turned by ``angle`` (rad) towards ``up`` (3,) (in their common plane)."""
    d = direction / np.linalg.norm(direction)
    normal = up - (up @ d) * d
    norm = np.linalg.norm(normal)
    if norm < 1e-9:   # up along the line of sight: no elevation defined, keep the direction
        return d
    return np.cos(angle) * d + np.sin(angle) * normal / norm


@dataclass
class Pointing:
    """Aim of the pan-tilt mount (module docstring): CoM track, carried velocity, search state.

    Parameters
    ----------
    com_body : (3,) float
        The debris CoM in the tracker's frame B (m): the point whose track the mount follows.

    Attributes
    ----------
    times : list of float
        Times of the good frames (s).
    com_world : list of (3,) float
        CoM at those frames, world frame (m).
    velocity_world : (3,) float
        Last fitted CoM velocity, world frame (m/s); zero until two good frames.
    lost : bool
        The last frame's registration failed.
    misses : int
        Consecutive frames of a lost track in which nothing that could be the debris was seen.
    seen_world : (3,) float or None
        Centre of the debris' returns in the last frame of a lost track that saw it (m, world).
    """

    com_body: np.ndarray
    times: list = field(default_factory=list)
    com_world: list = field(default_factory=list)
    velocity_world: np.ndarray = field(default_factory=lambda: np.zeros(3))
    lost: bool = False
    misses: int = 0
    seen_world: np.ndarray | None = None

    def record(self, time_s, body_to_world, seen, seen_world=None) -> None:
        """Take one frame's result.

        Parameters
        ----------
        time_s : float
            Frame time (s).
        body_to_world : (4, 4) float or None
            The registered pose B -> world (m), None when the registration failed.
        seen : bool
            The frame had returns that could be the debris (enough returns off the predicted net).
        seen_world : (3,) float, optional
            Centre of those returns (m, world; :func:`debris_blob`): a lost track aims there next.
        """
        self.lost = body_to_world is None
        self.seen_world = None if seen_world is None or not seen else np.asarray(seen_world, float)
        if self.lost:
            self.misses = 0 if seen else self.misses + 1
            return
        self.misses = 0
        self.times.append(float(time_s))
        self.com_world.append(body_to_world[:3, :3] @ self.com_body + body_to_world[:3, 3])
        self._fit_velocity()

    def _fit_velocity(self) -> None:
        """Least-squares CoM velocity over the latest good frames (VELOCITY_WINDOW, VELOCITY_FRAMES);
        the previous one is kept while fewer than two are in the window (just re-acquired)."""
        times = np.asarray(self.times[-VELOCITY_FRAMES:])
        keep = times >= times[-1] - VELOCITY_WINDOW - 1e-9
        if keep.sum() < 2:
            return
        t = times[keep] - times[keep].mean()
        positions = np.asarray(self.com_world[-VELOCITY_FRAMES:])[keep]
        self.velocity_world = t @ (positions - positions.mean(axis=0)) / (t @ t)

    def predicted_com(self, time_s) -> np.ndarray | None:
        """The CoM at ``time_s`` (s), world frame (m): the last good one carried in a straight line at
        the fitted velocity; None before any good frame.

        Parameters
        ----------
        time_s : float
            Time (s).

        Returns
        -------
        (3,) float or None
        """
        if not self.times:
            return None
        return self.com_world[-1] + self.velocity_world * (time_s - self.times[-1])

    def aim(self, time_s, sensor_world, up_world) -> np.ndarray | None:
        """Point to aim the boresight at (m, world): the predicted CoM while the track holds; in a
        lost track, the centre of the debris' returns of the last frame when it saw them, else the
        predicted CoM, after frames that saw nothing turned by the search pattern's next elevation
        towards the mount's up axis.

        Parameters
        ----------
        time_s : float
            Time of the frame to be taken (s).
        sensor_world : (3,) float
            Sensor origin, world frame (m).
        up_world : (3,) float
            The mount's up axis (the sensor's +z before aiming), world frame.

        Returns
        -------
        (3,) float or None
            Aim point, world frame (m); None before any good frame (keep the body-fixed mount).
        """
        com = self.predicted_com(time_s)
        if com is None or not self.lost:
            return com
        if self.misses == 0:   # lost, but the debris was seen: look where it was seen
            return com if self.seen_world is None else self.seen_world
        offset = com - sensor_world
        angle = SEARCH_ELEVATIONS[(self.misses - 1) % len(SEARCH_ELEVATIONS)]
        return sensor_world + np.linalg.norm(offset) * _turned_towards(offset, np.asarray(up_world, float), angle)
