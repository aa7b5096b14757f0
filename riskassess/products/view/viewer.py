"""``viewer.html``: an interactive 3-D viewer of a run in one offline file.

The page (``templates/viewer.html``) holds the scene as JSON and a small hand-written canvas
script: scrub time, play, rotate (drag), zoom (wheel), jump to the instants of the report,
toggle the net, the bodies and the contact forces. No library, no WebGL (a 2-D canvas draws in
every browser, also without a GPU), nothing loaded from the network.

Size: positions are rounded to 0.1 mm and tensions and forces to 4 significant digits; at most
``max_frames`` snapshots are kept (evenly spread, first and last included).
"""
from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from riskassess.products.view.scene import Scene, decimation

TEMPLATE = Path(__file__).parent / "templates" / "viewer.html"
#: Default cap on the viewer's snapshots: 150 keeps the reference run's viewer at a few MB.
VIEWER_MAX_FRAMES = 150


def _round(values, digits: int = 4):
    return np.round(np.asarray(values, float), digits).tolist()


def _significant(values, digits: int = 4):
    values = np.asarray(values, float)
    return [float(f"{v:.{digits}g}") for v in values.ravel()]


def scene_data(scene: Scene, max_frames: int = VIEWER_MAX_FRAMES) -> dict:
    """The JSON the viewer draws: per kept snapshot the net, tensions, body poses and contact forces.

    Parameters
    ----------
    scene : Scene
        The run's scene.
    max_frames : int
        Most snapshots to keep, >= 2.

    Returns
    -------
    dict
        JSON-ready: ``time`` (s), ``net`` node positions (m, LVLH, flattened), ``tension`` (N),
        ``poses`` per body (body_to_lvlh row-major then CoM, m, LVLH), ``body_force`` and
        ``node_force`` (N, LVLH), ``bodies`` (vertices in the body frame, m), ``bounds`` (m, LVLH),
        ``instants``.
    """
    frames = decimation(scene.n_frames, max_frames)
    low, high = scene.bounds()
    poses, body_force, node_force = [], [], []
    for f in frames:
        poses.append([_round(np.r_[rot.ravel(), com], 6)
                      for rot, com in (scene.body_pose(f, k) for k in range(len(scene.meshes)))])
        body_force.append([_significant(F) for F in scene.body_contact_force(f)])
        if scene.node_contact_force is None:
            node_force.append([])
        else:
            F = np.asarray(scene.node_contact_force[f], float)
            node_force.append([[int(i), *_significant(F[i])] for i in np.flatnonzero(np.abs(F).sum(axis=1) > 0)])
    forces = np.array([F for per in body_force for F in per] or [[0.0, 0.0, 0.0]])
    kept = {int(f): n for n, f in enumerate(frames)}
    instants = [{"label": i.label, "time": i.time, "frame": kept.get(i.frame, int(np.abs(frames - i.frame).argmin()))}
                for i in scene.instants()]
    return {
        "time": _round(scene.time[frames], 6), "n_nodes": int(scene.positions.shape[1]),
        "n_bullets": scene.n_bullets, "threads": scene.threads.ravel().tolist(),
        "net": [_round(scene.positions[f].ravel()) for f in frames],
        "tension": [_significant(scene.tension[f]) for f in frames],
        "tension_max": scene.tension_scale(), "force_max": float(np.linalg.norm(forces, axis=1).max()),
        "bodies": [{"name": name, "vertices": _round(v.ravel()), "faces": np.asarray(faces).ravel().tolist(),
                    "released_at": None if np.isinf(r) else float(r)}
                   for name, (v, faces), r in zip(scene.body_names, scene.meshes, scene.released_from)],
        "poses": poses, "body_force": body_force, "node_force": node_force,
        "bounds": [low.tolist(), high.tolist()], "instants": instants,
        "start_frame": next((i["frame"] for i in instants if i["label"] == "peak contact load"), 0),
    }


def _script_json(data: dict) -> str:
    """JSON safe inside a <script> element: no '<', '>' or '&' can close it or start markup."""
    text = json.dumps(data, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def viewer_html(scene: Scene, title: str, max_frames: int = VIEWER_MAX_FRAMES) -> str:
    """The viewer page of ``scene``; ``title`` is user text (escaped).

    Parameters
    ----------
    scene : Scene
        The run's scene.
    title : str
        Page title (user text, escaped).
    max_frames : int
        Most snapshots to keep, >= 2.

    Returns
    -------
    str
        The whole HTML page.
    """
    data = scene_data(scene, max_frames)
    # JSON has no infinity: a body never released is null, which the script compares as "never"
    for body in data["bodies"]:
        if body["released_at"] is None:
            body["released_at"] = 1e300
    return TEMPLATE.read_text().replace("__TITLE__", html.escape(title)).replace("__DATA__", _script_json(data))
