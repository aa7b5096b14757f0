"""Start a full-net tow from the end state of an impact run (``[full_net] start = "run"``,
``from_run = "runs/x"``): the capture simulated by the impact stage (``riskassess run``), the tow
continuing from its last net snapshot (docs/towing.md, "Tow from an impact run").

**What is read** from the run folder: ``manifest.json`` (status ``complete``, an impact run),
``case.json`` (the validated impact case: orbit, net, target), ``net.npz`` (the last snapshot's node
positions and velocities, LVLH, and the net's arrays: threads, natural lengths, stiffnesses, damping,
masses, radii) and ``timeseries.npz`` (the debris body's CoM, velocity, attitude and angular velocity at
that snapshot's time). The net of the tow is the run's net (its arrays) with the towing case's closing
loop appended (open at the flat net's lacing distances, reeled in from ``full_net.closing_time``).

**Checks** (each a :class:`riskassess.cases.impact.CaseError` naming the case file, the key and the
run's file): the folder exists and its manifest says complete; the impact case has no simulated chaser
(the chaser is the LVLH origin); its orbit altitude is the towing chaser's within 1 km; its net has
``full_net.nodes_per_side`` nodes a side, ``full_net.side_length`` within 1 mm, the towing net's
threads, and ``net_mass`` within 1 %; its target is one rigid body (no joints) of ``debris.nominal_mass``
and ``debris.principal_inertia`` within 0.1 %, shaped as one cylinder of ``debris.diameter`` and
``debris.length`` (1 mm) along the body z axis, centred where :func:`debris_geometry` puts it (1 mm); the
snapshot's time is before ``full_net.closing_time`` and a time-series sample exists at it.

**Contact surface.** The impact model's cylinder is a faceted mesh (32 facets: their middles lie
r (1 - cos(pi/32)) = 9.4 mm inside the round cylinder of the towing model), so nodes resting on it are
inside the towing model's analytic cylinder; left there, the Hertz contact (1.6e8 N/m^1.5) would push a
9.5 g node out with ~100 kN and blow the net off the stage. Moving those nodes out along the surface normal
(:func:`lift_onto_cylinder`) is not enough by itself: it lengthens the threads round the surface (by up to
lift / radius, 0.5 %: 300 N in a Kevlar thread) and put 12.5 J of elastic energy into a net that held 1e-4 J
(cases/zenit2_capture.toml at 12 s), which threw the net off the stage within 10 s of towing. The nodes are
therefore draped onto the round cylinder (:func:`drape_on_cylinder`): lifted, then every thread the lift
lengthened is brought back to its length in the run, the nodes sliding along the surface (up to 15 mm there;
the net's CoM moves by 2 mm; velocities kept); ``RunStart.lift`` is the largest move (m).

**Closing loop.** The impact model has none, so its lacing points end up wherever the capture left them,
up to a few per cent farther apart than the flat net's straight lacing distances (1.7 % in
cases/zenit2_capture.toml at 12 s); a loop appended at those open lengths would start stretched and jerk the
0.15 kg corner masses with ~1 kN (it threw the net off the stage). Each closing thread's open natural length
is therefore the larger of the flat distance and the distance at the start (:func:`slack_closing_loop`): the
loop starts slack or just taut and is reeled in to ``closed_fraction`` of the flat lengths as usual.

**Frames.** The impact run is in the chaser-centred LVLH frame (x radial, y along-track, z orbit
normal), which rotates at the mean motion n of its circular orbit about z; the tow is in the
Earth-centred inertial frame. The LVLH origin is put at the towing case's chaser (Table 2) and its axes
are those of that chaser's orbit (:func:`multibody.orbit.lvlh_to_eci`, R: LVLH -> ECI):

    x_ECI = r_C + R x_LVLH,  v_ECI = v_C + R (v_LVLH + omega_LVLH x x_LVLH),  omega_LVLH = [0, 0, n],
    debris_to_ECI = R debris_to_LVLH,  omega_body(inertial) = omega_body(relative to LVLH) + debris_to_LVLH^T omega_LVLH.

The chaser keeps its Table 2 state (attitude, rates) at the tow's start: the Table 2 state is re-timed
from the impact's t = 0 to the snapshot time, a shift of the orbit phase, which two-body gravity does
not see. The tow's clock is the impact's (net ejection at t = 0): closing at ``full_net.closing_time``,
thrust from ``thrust.t_on``.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from multibody.net import NetTopology
from multibody.net_towing_kernel import cylinder_distance
from multibody.net_wrap import TowingNet, towing_net
from multibody.orbit import R_EARTH, lvlh_to_eci, mean_motion
from riskassess.cases.impact import CaseError
from riskassess.cases.towing import TowingCase
from riskassess.models.towing_fullnet import debris_geometry

#: Tolerances of the checks (module doc): orbit altitude (m), lengths (m), net mass (-), debris mass and inertia (-).
ALTITUDE_TOLERANCE, LENGTH_TOLERANCE, NET_MASS_TOLERANCE, DEBRIS_TOLERANCE = 1e3, 1e-3, 0.01, 1e-3


@dataclass
class RunStart:
    """The end state of an impact run in the towing frame (module doc).

    Attributes
    ----------
    folder : Path                     The impact run folder.
    time : float                      Snapshot time = the tow's start (s, impact clock).
    net : TowingNet                   The run's net with the closing loop (open).
    node_positions, node_velocities : (n, 3) float   (m, m/s; inertial).
    debris_position, debris_velocity : (3,) float   Debris CoM (m, m/s; inertial).
    debris_to_inertial : (3, 3) float
    debris_omega_body : (3,) float    Inertial angular velocity, debris body frame (rad/s).
    lift : float                      Largest move of a node onto the analytic cylinder (m; module doc).
    """

    folder: Path
    time: float
    net: TowingNet
    node_positions: np.ndarray
    node_velocities: np.ndarray
    debris_position: np.ndarray
    debris_velocity: np.ndarray
    debris_to_inertial: np.ndarray
    debris_omega_body: np.ndarray
    lift: float = 0.0


def run_folder(case: TowingCase, case_path) -> Path:
    """The impact run folder ``full_net.from_run`` names: absolute, or relative to the case file's folder.

    Parameters
    ----------
    case : TowingCase
        A towing case with ``full_net.start = "run"``.
    case_path : str or Path
        The towing case file.

    Returns
    -------
    Path
    """
    name = Path(case.full_net.from_run)
    return name if name.is_absolute() else Path(case_path).parent / name


def _refuse(case_path, message: str):
    raise CaseError(f"{case_path}: full_net.from_run: {message}")


def _read_run(case_path, folder: Path):
    """manifest (checked), impact case dict, net.npz and timeseries.npz of ``folder``."""
    if not folder.is_dir():
        _refuse(case_path, f"'{folder}' is not a folder (paths are relative to the case file)")
    try:
        manifest = json.loads((folder / "manifest.json").read_text())
    except (OSError, ValueError) as exc:
        _refuse(case_path, f"'{folder}' has no readable manifest.json ({exc}); it must be an impact run folder")
    if manifest.get("stage", "impact") != "impact":
        _refuse(case_path, f"'{folder}' holds a '{manifest.get('stage')}' output; a tow starts from an impact run")
    if manifest.get("status") != "complete":
        _refuse(case_path, f"'{folder}': its manifest says status '{manifest.get('status')}'; only a 'complete' "
                           "impact run can start a tow")
    try:
        impact = json.loads((folder / "case.json").read_text())
        net, series = dict(np.load(folder / "net.npz")), dict(np.load(folder / "timeseries.npz"))
    except (OSError, ValueError) as exc:
        _refuse(case_path, f"'{folder}': case.json, net.npz or timeseries.npz cannot be read ({exc})")
    return impact, net, series


def _check_case(case_path, case: TowingCase, impact: dict) -> float:
    """The impact case against the towing case (module doc); returns the impact orbit's mean motion (rad/s)."""
    if impact.get("chaser") is not None:
        _refuse(case_path, "the impact run simulates a chaser; only runs whose chaser is the LVLH origin are supported")
    orbit = impact["orbit"]
    altitude = np.linalg.norm(case.chaser.position_inertial) - R_EARTH
    if orbit["kind"] != "circular" or abs(orbit["altitude"] - altitude) > ALTITUDE_TOLERANCE:
        _refuse(case_path, f"the impact run's orbit ({orbit}) is not the towing chaser's circular orbit at "
                           f"{altitude:.1f} m altitude (within {ALTITUDE_TOLERANCE:g} m)")
    fn, net = case.full_net, impact["net"]
    if net["nodes_per_side"] != fn.nodes_per_side or abs(net["side_length"] - fn.side_length) > LENGTH_TOLERANCE:
        _refuse(case_path, f"the impact run's net is {net['nodes_per_side']} nodes a side, {net['side_length']} m; "
                           f"full_net has {fn.nodes_per_side} nodes a side, {fn.side_length} m")
    target = impact["target"]
    if len(target["bodies"]) != 1 or target["joints"]:
        _refuse(case_path, "the impact run's target must be one rigid body without joints (the towed debris); it has "
                           f"{len(target['bodies'])} bodies and {len(target['joints'])} joints")
    body, de = target["bodies"][0], case.debris
    inertia = np.asarray(body["inertia"] if body["inertia"] is not None else np.zeros((3, 3)), float)
    if (abs(body["mass"] - de.nominal_mass) > DEBRIS_TOLERANCE * de.nominal_mass
            or not np.allclose(inertia, np.diag(de.principal_inertia), rtol=0, atol=DEBRIS_TOLERANCE * max(de.principal_inertia))):
        _refuse(case_path, f"the impact target's mass {body['mass']} kg and inertia {inertia.tolist()} kg m^2 are not "
                           f"debris.nominal_mass {de.nominal_mass} kg and debris.principal_inertia {de.principal_inertia} "
                           f"(within {DEBRIS_TOLERANCE:g})")
    shapes = body["shapes"]
    geometry = debris_geometry(case)
    com = np.asarray(body["center_of_mass"] if body["center_of_mass"] is not None else shapes[0]["center"], float)
    ok = len(shapes) == 1 and shapes[0]["kind"] == "cylinder"
    if ok:
        shape = shapes[0]
        axis = np.asarray(shape["axis"], float) / np.linalg.norm(shape["axis"])
        ok = (abs(shape["radius"] - geometry[0]) <= LENGTH_TOLERANCE and abs(shape["length"] - 2 * geometry[1]) <= LENGTH_TOLERANCE
              and abs(abs(axis[2]) - 1.0) < 1e-9
              and np.linalg.norm(np.asarray(shape["center"]) - com - [0.0, 0.0, geometry[2]]) <= LENGTH_TOLERANCE)
    if not ok:
        _refuse(case_path, f"the impact target must be one cylinder of radius {geometry[0]} m and length "
                           f"{2 * geometry[1]} m along the body z axis, centred at z = {geometry[2]:.4f} m from the "
                           f"CoM (debris.diameter, debris.length, sub-tether attachments; within {LENGTH_TOLERANCE:g} m); "
                           f"it has {shapes}")
    return mean_motion(orbit["altitude"])


def run_net(case_path, case: TowingCase, net: dict) -> TowingNet:
    """The run's net (its arrays) with the towing case's closing loop appended (module doc).

    Parameters
    ----------
    case_path : str or Path
        The towing case file (named in errors).
    case : TowingCase
        The towing case (closing loop, net mass).
    net : dict
        The run's ``net.npz``.

    Returns
    -------
    multibody.net_wrap.TowingNet
        Closing loop at its open natural lengths (the flat net's lacing distances).
    """
    fn = case.full_net
    flat = towing_net(fn.side_length, fn.nodes_per_side, case.net_mass, fn.corner_mass, fn.node_radius,
                      fn.corner_radius, fn.thread_axial_rigidity, fn.thread_damping, fn.closing_axial_rigidity,
                      fn.closed_fraction, np.zeros(3), np.array([0.0, 0.0, 1.0]))
    top, k = flat.topology, len(flat.closing_rest_open)
    threads = np.asarray(net["threads"], np.int64)
    if (len(net["masses"]) != len(top.masses) or threads.shape != top.threads[:-k].shape
            or np.any(threads != top.threads[:-k])):
        _refuse(case_path, f"the impact run's net ({len(net['masses'])} nodes, {len(threads)} threads) is not the "
                           f"towing net ({len(top.masses)} nodes, {len(top.threads) - k} threads)")
    mass = float(np.sum(net["masses"]))
    if abs(mass - case.net_mass) > NET_MASS_TOLERANCE * case.net_mass:
        _refuse(case_path, f"the impact run's net weighs {mass:.4f} kg; net_mass is {case.net_mass} kg "
                           f"(within {NET_MASS_TOLERANCE:.0%}: m_P = s4 net_mass)")
    topology = NetTopology(
        positions=top.positions, masses=np.asarray(net["masses"], float), radii=np.asarray(net["radii"], float),
        threads=top.threads, rest_lengths=np.r_[net["rest_lengths"], top.rest_lengths[-k:]],
        stiffness=np.r_[net["stiffness"], top.stiffness[-k:]], damping=np.r_[net["damping"], top.damping[-k:]],
        bending_triples=top.bending_triples, bending_stiffness=np.zeros(len(top.bending_triples)),
        nodes_per_side=fn.nodes_per_side, n_bullets=4)
    return TowingNet(topology, flat.central, flat.closing_rest_open, flat.closing_rest_closed,
                     flat.closing_axial_rigidity)


def lvlh_frame(case: TowingCase):
    """The impact run's LVLH frame in the towing frame (module doc): origin (m) and velocity (m/s) of the
    towing chaser, rotation LVLH -> ECI.

    Parameters
    ----------
    case : TowingCase
        The towing case (chaser Table 2 state, inertial).

    Returns
    -------
    origin, velocity : (3,) float
        (m, m/s; inertial).
    lvlh_to_inertial : (3, 3) float
    """
    r_c, v_c = np.asarray(case.chaser.position_inertial, float), np.asarray(case.chaser.velocity_inertial, float)
    return r_c, v_c, lvlh_to_eci(r_c, v_c)


def lvlh_to_towing(case: TowingCase, n: float, positions_lvlh, velocities_lvlh):
    """Positions and velocities from the impact run's rotating LVLH frame to the towing frame (module doc).

    Parameters
    ----------
    case : TowingCase
        The towing case (its chaser is the LVLH origin).
    n : float
        Rate of the LVLH frame about its z axis (rad/s).
    positions_lvlh, velocities_lvlh : (..., 3) float
        (m, m/s) relative to the LVLH origin, velocities relative to the rotating frame.

    Returns
    -------
    positions, velocities : (..., 3) float
        (m, m/s; Earth-centred inertial).
    """
    r_c, v_c, rot = lvlh_frame(case)
    x = np.asarray(positions_lvlh, float)
    v = np.asarray(velocities_lvlh, float) + np.cross([0.0, 0.0, n], x)
    return r_c + x @ rot.T, v_c + v @ rot.T


def lift_onto_cylinder(nodes_body, radii, geometry):
    """Nodes moved out along the cylinder's normal where they are closer to its surface than their contact
    radius (module doc, "Contact surface").

    Parameters
    ----------
    nodes_body : (n, 3) float
        Node positions relative to the debris CoM, debris body frame (m).
    radii : (n,) float
        Contact radii (m).
    geometry : (3,) float
        Cylinder radius, half length, axial centre z_body (m) (:func:`debris_geometry`).

    Returns
    -------
    lifted : (n, 3) float
        (m, debris body frame).
    lift : float
        Largest move (m).
    """
    lifted = np.array(nodes_body, float)
    lift = 0.0
    for i, (x, r) in enumerate(zip(lifted, radii)):
        d, nx, ny, nz = cylinder_distance(x[0], x[1], x[2], geometry)
        if d < r:
            lifted[i] += (r - d) * np.array([nx, ny, nz])
            lift = max(lift, r - d)
    return lifted, float(lift)


def drape_on_cylinder(nodes_body, masses, radii, threads, targets, geometry, tolerance=1e-6, max_sweeps=20000):
    """Nodes lifted onto the analytic cylinder (:func:`lift_onto_cylinder`) with no thread longer than its
    target (module doc, "Contact surface"): a lift along the normal lengthens every thread whose ends are
    lifted unequally or that runs round the surface (by up to lift / radius of its length), so each sweep
    shortens every thread above its target to it, moving its two ends towards each other in inverse
    proportion to their masses (a node's corrections averaged over its threads), and lifts the nodes again;
    the nodes slide along the surface until both hold.

    Parameters
    ----------
    nodes_body : (n, 3) float
        Node positions relative to the debris CoM, debris body frame (m).
    masses, radii : (n,) float
        Node masses (kg) and contact radii (m).
    threads : (k, 2) int
        Node pairs.
    targets : (k,) float
        Largest length of each thread (m): its length before the lift or its natural length, the larger.
    geometry : (3,) float
        Cylinder radius, half length, axial centre z_body (m) (:func:`debris_geometry`).
    tolerance : float
        Largest thread excess over its target left (m).
    max_sweeps : int
        Most sweeps; ``RuntimeError`` if the excess is still above ``tolerance`` then.

    Returns
    -------
    draped : (n, 3) float
        (m, debris body frame).
    lift : float
        Largest move of a node (m).
    excess : float
        Largest thread excess over its target left (m).
    """
    start = np.array(nodes_body, float)
    x, _ = lift_onto_cylinder(start, radii, geometry)
    i, j = np.asarray(threads).T
    inverse = 1.0 / np.asarray(masses, float)
    share_i = (inverse[i] / (inverse[i] + inverse[j]))[:, None]
    for _ in range(max_sweeps):
        d = x[j] - x[i]
        length = np.linalg.norm(d, axis=1)
        excess = length - targets
        if excess.max() <= tolerance:
            break
        pull = np.where(excess > 0, excess / length, 0.0)[:, None] * d
        move, count = np.zeros_like(x), np.zeros(len(x))
        np.add.at(move, i, share_i * pull)
        np.add.at(move, j, -(1.0 - share_i) * pull)
        np.add.at(count, i, excess > 0)
        np.add.at(count, j, excess > 0)
        x += move / np.maximum(count, 1.0)[:, None]
        x, _ = lift_onto_cylinder(x, radii, geometry)
    else:
        raise RuntimeError(f"the net could not be draped on the round cylinder: a thread is still {excess.max():.3g} m "
                           f"longer than before the lift after {max_sweeps} sweeps")
    return x, float(np.linalg.norm(x - start, axis=1).max()), float(max(excess.max(), 0.0))


def slack_closing_loop(net: TowingNet, nodes) -> None:
    """Open natural lengths of the closing loop: the larger of the flat net's straight lacing distances and
    the distances at ``nodes`` (module doc, "Closing loop"); stiffness EA/l0 with them. In place.

    Parameters
    ----------
    net : multibody.net_wrap.TowingNet
        The net (its closing threads are the topology's last ones).
    nodes : (n, 3) float
        Node positions at the start (m, any frame).
    """
    top = net.topology
    k = len(net.closing_rest_open)
    pairs = top.threads[-k:]
    reach = np.linalg.norm(nodes[pairs[:, 1]] - nodes[pairs[:, 0]], axis=1)
    net.closing_rest_open[:] = np.maximum(net.closing_rest_open, reach)
    top.rest_lengths[-k:] = net.closing_rest_open
    top.stiffness[-k:] = net.closing_stiffness(net.closing_rest_open)


def impact_run_start(case: TowingCase, case_path, snapshot: int = -1) -> RunStart:
    """Read and check the impact run of ``full_net.from_run`` and express its end state (or another net
    snapshot) in the towing frame (module doc).

    Parameters
    ----------
    case : TowingCase
        A towing case with ``full_net.start = "run"``.
    case_path : str or Path
        The towing case file (the folder is relative to it; named in errors).
    snapshot : int
        Index of the net snapshot (default the last: the run's end state).

    Returns
    -------
    RunStart
    """
    folder = run_folder(case, case_path)
    impact, net, series = _read_run(case_path, folder)
    n = _check_case(case_path, case, impact)
    towing = run_net(case_path, case, net)
    t = float(net["time"][snapshot])
    if t >= case.full_net.closing_time:
        _refuse(case_path, f"the impact run's net snapshot is at {t:g} s, not before full_net.closing_time "
                           f"({case.full_net.closing_time:g} s): the closing would start inside the run")
    k = int(np.argmin(np.abs(series["time"] - t)))
    if abs(series["time"][k] - t) > 1e-6:
        _refuse(case_path, f"'{folder}': timeseries.npz has no sample at the last net snapshot ({t:g} s)")
    nodes, velocities = lvlh_to_towing(case, n, net["positions_lvlh"][snapshot],
                                       np.asarray(net["velocities_lvlh"][snapshot], float))
    com, com_v = lvlh_to_towing(case, n, series["body_com_lvlh"][k, 0], series["body_velocity_lvlh"][k, 0])
    to_lvlh = np.asarray(series["body_to_lvlh"][k, 0], float)
    rot = lvlh_frame(case)[2]
    omega = np.asarray(series["body_omega_body"][k, 0], float) + to_lvlh.T @ np.array([0.0, 0.0, n])
    debris_to_inertial = rot @ to_lvlh
    top, k = towing.topology, len(towing.closing_rest_open)
    body = (nodes - com) @ debris_to_inertial
    threads = top.threads[:-k]                    # the run's own threads (the loop is set slack below)
    targets = np.maximum(np.linalg.norm(body[threads[:, 1]] - body[threads[:, 0]], axis=1), top.rest_lengths[:-k])
    draped, lift, _ = drape_on_cylinder(body, top.masses, top.radii, threads, targets, debris_geometry(case))
    nodes = com + draped @ debris_to_inertial.T
    slack_closing_loop(towing, nodes)
    return RunStart(folder, t, towing, nodes, velocities, com, com_v, debris_to_inertial, omega, lift)

