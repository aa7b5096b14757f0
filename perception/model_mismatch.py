"""Does the debris model given to the tracker match the scanned debris? Residuals of the
registered scans against the model, judged against the sensor's range noise.

A real derelict never matches its drawings (a bent array, a lost antenna). Registered to a model
that differs from it, each scan leaves two kinds of residual that a matching model does not:

* **unexplained returns**: scan points farther than ``gate`` from the posed model's surface (the
  bent array's returns, off the drawn array);
* **unseen model surface**: returns the posed model predicts (the model ray-cast from the frame's
  sensor pose with the same LiDAR, no noise) with no scan return within ``gate`` (the lost
  antenna, the drawn array where the real one is not).

With the right model a return lies within its range noise of the surface (the point-to-surface
distance is the range error times the cosine of the incidence, at most the range error), so
beyond ``gate = GATE_SIGMAS x range noise`` plus the pose error's reach only the noise's far tail
(6e-5 at 4 sigma) and the surface the registration got wrong remain. The figures per frame, and
their median over the checked frames (robust to a few mis-registered frames), are compared with
:data:`MAX_UNEXPLAINED` and :data:`MAX_UNSEEN`.

The tracker's own registration failures are a third residual: a model that registers fewer than
:data:`MIN_REGISTERED` of the frames does not explain the scans either.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree

#: Gate of a residual, in range-noise standard deviations (-): a return of the right surface lies
#: within 4 sigma with probability 1 - 6e-5.
GATE_SIGMAS = 4.0
#: Reach of the registration's own error in the gate (m): 0.15-0.3 deg mean attitude error (mesh
#: tracker, docs/perception.md) over a 2-3 m lever is 5-15 mm.
POSE_ALLOWANCE = 0.02
#: Largest median share of scan returns the posed model leaves unexplained, and of model returns
#: not seen (-). Measured on the intact featured debris (docs/perception.md, "Wrong model"): median
#: shares under 1 %, frames up to a few % (limbs, mis-registered frames); a 15 deg bend of its 2 m
#: array or a lost 0.7 m antenna moves 5-30 % of the returns.
MAX_UNEXPLAINED = 0.03
MAX_UNSEEN = 0.03
#: Least share of observation frames the model registers (-); the intact featured debris
#: registered 75-100 %.
MIN_REGISTERED = 0.5
#: Frames between two checked frames (-): successive residuals are strongly correlated, and each
#: check casts the model once.
CHECK_EVERY = 5


def gate(range_noise: float) -> float:
    """Residual gate (m) for a LiDAR of ``range_noise`` (m, 1 sigma): GATE_SIGMAS sigma plus
    POSE_ALLOWANCE.

    Parameters
    ----------
    range_noise : float
        Range noise, 1 sigma (m).

    Returns
    -------
    float
        Distance (m) beyond which a return (or a predicted return) counts as a residual.
    """
    return GATE_SIGMAS * range_noise + POSE_ALLOWANCE


class SurfaceDistance:
    """Exact distance (m) to a triangle mesh (Open3D ray-casting scene), frame of the mesh.

    Parameters
    ----------
    vertices : (v, 3) float
        Mesh vertices (m).
    faces : (f, 3) int
        Triangles.
    """

    def __init__(self, vertices, faces):
        self._scene = o3d.t.geometry.RaycastingScene()
        self._scene.add_triangles(o3d.core.Tensor(np.asarray(vertices, np.float32)),
                                  o3d.core.Tensor(np.asarray(faces, np.uint32)))

    def __call__(self, points) -> np.ndarray:
        """Unsigned distance (n,) (m) of points (n, 3) (m, mesh frame) to the surface."""
        if len(points) == 0:
            return np.zeros(0)
        return self._scene.compute_distance(o3d.core.Tensor(np.asarray(points, np.float32))).numpy().astype(float)


def unexplained_share(scan_body, distance_to_model, gate_m) -> float:
    """Share of scan returns farther than ``gate_m`` (m) from the model surface.

    Parameters
    ----------
    scan_body : (n, 3) float
        Scan returns moved into the model frame by the registered pose (m).
    distance_to_model : SurfaceDistance
        Distance to the model surface (model frame).
    gate_m : float
        Residual gate (m).

    Returns
    -------
    float
        Share 0-1 (0 for an empty scan).
    """
    if len(scan_body) == 0:
        return 0.0
    return float(np.mean(distance_to_model(scan_body) > gate_m))


def unseen_share(predicted_world, scan_world, gate_m) -> float:
    """Share of the returns the posed model predicts with no scan return within ``gate_m`` (m).

    Parameters
    ----------
    predicted_world : (k, 3) float
        Returns of the model at the registered pose, ray-cast from the frame's sensor pose (m).
    scan_world : (n, 3) float
        The frame's scan returns (m, same frame).
    gate_m : float
        Residual gate (m).

    Returns
    -------
    float
        Share 0-1 (0 when the model predicts nothing; 1 when the scan is empty).
    """
    if len(predicted_world) == 0:
        return 0.0
    if len(scan_world) == 0:
        return 1.0
    gap, _ = cKDTree(scan_world).query(predicted_world, distance_upper_bound=gate_m)
    return float(np.mean(~np.isfinite(gap)))


@dataclass
class ModelCheck:
    """The verdict on the model from a track's residuals (shares 0-1, gate in m)."""

    frames: int                 # observation frames with returns to register
    registered: int             # frames the model registered
    checked: int                # frames whose residuals were taken
    unexplained_median: float
    unseen_median: float
    unexplained_p90: float
    unseen_p90: float
    gate_m: float

    @property
    def reasons(self) -> list[str]:
        """What the residuals say is wrong; empty when the model explains the scans."""
        out = []
        if self.registered < MIN_REGISTERED * self.frames:
            out.append(f"it registers only {self.registered} of {self.frames} frames (at least "
                       f"{100 * MIN_REGISTERED:.0f} % expected)")
        if self.checked and self.unexplained_median > MAX_UNEXPLAINED:
            out.append(f"{100 * self.unexplained_median:.1f} % of the returns lie more than {100 * self.gate_m:.0f} cm "
                       f"off its surface (median of {self.checked} frames; at most {100 * MAX_UNEXPLAINED:.0f} %)")
        if self.checked and self.unseen_median > MAX_UNSEEN:
            out.append(f"{100 * self.unseen_median:.1f} % of the surface it shows is not in the scans (median of "
                       f"{self.checked} frames; at most {100 * MAX_UNSEEN:.0f} %)")
        return out

    @property
    def mismatch(self) -> bool:
        return bool(self.reasons)

    def as_dict(self) -> dict:
        """JSON-ready figures and verdict."""
        return {"mismatch": self.mismatch, "reasons": self.reasons, "frames": self.frames,
                "registered": self.registered, "checked": self.checked, "gate_m": self.gate_m,
                "unexplained_share_median": self.unexplained_median, "unexplained_share_p90": self.unexplained_p90,
                "unseen_share_median": self.unseen_median, "unseen_share_p90": self.unseen_p90,
                "limits": {"unexplained_share_median": MAX_UNEXPLAINED, "unseen_share_median": MAX_UNSEEN,
                           "registered_share": MIN_REGISTERED}}


def model_check(frames: int, registered: int, unexplained, unseen, gate_m) -> ModelCheck:
    """Summarize per-frame residual shares (lists over the checked frames) into a :class:`ModelCheck`.

    Parameters
    ----------
    frames : int
        Observation frames with returns to register.
    registered : int
        Frames the model registered.
    unexplained, unseen : sequence of float
        Per checked frame, :func:`unexplained_share` and :func:`unseen_share` (0-1).
    gate_m : float
        The gate they were taken with (m).

    Returns
    -------
    ModelCheck
    """
    unexplained, unseen = np.asarray(unexplained, float), np.asarray(unseen, float)
    stat = (lambda a, q: float(np.percentile(a, q)) if len(a) else float("nan"))
    return ModelCheck(frames, registered, len(unexplained), stat(unexplained, 50), stat(unseen, 50),
                      stat(unexplained, 90), stat(unseen, 90), float(gate_m))
