"""Secondary debris, simulated: a failed weak location releases its joint during the run.

:class:`ReleaseMonitor` is called by the recorder at every output sample with the joint
loads just recorded. When a weak location's demand reaches its decisive allowable (after
the skipped initial transient), the joint's connector is switched off in the Exudyn system
(``activeConnector = False``) and the simulation continues: the released piece (the child
body and everything still attached to it) flies on under the net's contact and the orbit.

:func:`released_pieces` reports each piece after the run: bodies, mass, size (oriented
bounding box of its shapes), release time, and at the end of the run its position,
velocity and spin relative to the chaser (the LVLH origin), and whether it is still held
inside the net (its centre of mass inside the convex hull of the net nodes).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from multibody.assembly import subtree_bodies
from structures.weak_location import WeakLocation, exceeds_now, online_modal_loads


@dataclass
class ReleaseEvent:
    location: str
    joint: int
    time: float          # s
    criterion: str
    demand: float        # SI unit of the criterion
    stored_energy: float # J, penalty-joint elastic energy let go at release


class ReleaseMonitor:
    """Releases joints whose weak location fails; see the module docstring."""

    def __init__(self, locations: list[WeakLocation], system, skip_until=0.0, policy="low", interval_s=None):
        self.locations = locations
        self.system = system
        self.skip_until = skip_until
        self.policy = policy
        self.events: list[ReleaseEvent] = []
        if interval_s is None and any(loc.structural_modes_hz for loc in locations):
            raise ValueError("a location read through structural modes needs the output interval (interval_s)")
        # a location read through its structure's modes is released on the modal loads, filtered as
        # the samples arrive (the filter is causal: the same loads the verdict judges afterwards)
        self._modal = {loc.name: online_modal_loads(loc, interval_s) for loc in locations}

    def released_joints(self) -> set:
        return {e.joint for e in self.events}

    def check(self, t, force_joint, moment_joint, joint_energies):
        """One output sample: (nj, 3) joint loads (joint frame) and (nj,) joint elastic energies (J).

        Releases (:meth:`release`) every location not yet released whose demand reaches its decisive
        allowable; does nothing before ``skip_until``.

        Parameters
        ----------
        t : float
            Simulation time of the sample (s).
        force_joint : (nj, 3) float
            Reaction force of each joint, the load the parent exerts on the child (N), joint frame
            (h1, h2, h3).
        moment_joint : (nj, 3) float
            Reaction moment of each joint at the joint point (N m), joint frame.
        joint_energies : (nj,) float
            Elastic energy stored in each penalty joint at the sample (J).
        """
        modal = {}      # every sample feeds the modal filters, also those before skip_until
        for loc in self.locations:
            if self._modal[loc.name] is not None:
                modal[loc.name] = self._modal[loc.name].update(np.stack([force_joint[loc.joint], moment_joint[loc.joint]]))
        if t < self.skip_until:
            return
        released = self.released_joints()
        for loc in self.locations:
            if loc.joint in released:
                continue
            if loc.name in modal:
                hit = exceeds_now(loc, modal[loc.name][:, 0], modal[loc.name][:, 1], self.policy)
            else:
                hit = exceeds_now(loc, force_joint[loc.joint], moment_joint[loc.joint], self.policy)
            if hit is not None:
                self.release(loc, t, *hit, stored_energy=float(joint_energies[loc.joint]))
                released.add(loc.joint)

    def release(self, location: WeakLocation, t, criterion, demand, stored_energy=0.0):
        """Switch the joint of ``location`` off in the Exudyn system and record the event.

        Parameters
        ----------
        location : WeakLocation
            The failed location; its joint's connector is deactivated.
        t : float
            Release time (s).
        criterion : str
            Name of the criterion that failed (``"normal_stress"``, ``"shear_stress"``, ``"moment"``,
            ``"force"``).
        demand : float
            Demand at release, in the criterion's SI unit (Pa, N m or N).
        stored_energy : float
            Elastic energy of the penalty joint let go at release (J).
        """
        mbs = self.system.mbs
        mbs.SetObjectParameter(self.system.joint_objects[location.joint], "activeConnector", False)
        self.events.append(ReleaseEvent(location.name, location.joint, float(t), criterion, demand, stored_energy))


def piece_size(bodies, members, attitudes, coms) -> list[float]:
    """Oriented bounding-box extents (m) of the piece's shapes, sorted large to small.

    Parameters
    ----------
    bodies : list of RigidBodySpec
        All bodies of the assembly (their ``meshes_body``: contact shapes, body frame, origin at
        the CoM, m).
    members : list of int
        Indices of the bodies in the piece.
    attitudes : list of (3, 3) float
        Rotation body -> LVLH of every body (indexed like ``bodies``).
    coms : list of (3,) float
        CoM position of every body, LVLH (m).

    Returns
    -------
    list of 3 float
        Box extents (m), largest first.
    """
    meshes = []
    for k in members:
        for mesh in bodies[k].meshes_body:
            m = mesh.copy()
            transform = np.eye(4)
            transform[:3, :3] = attitudes[k]
            transform[:3, 3] = coms[k]
            meshes.append(m.apply_transform(transform))
    merged = trimesh.util.concatenate(meshes)
    return sorted(np.asarray(merged.bounding_box_oriented.primitive.extents, float).tolist(), reverse=True)


def inside_net(point_lvlh, net_positions_lvlh) -> bool:
    """True if the point lies inside the convex hull of the net nodes (the net wraps it).

    Parameters
    ----------
    point_lvlh : (3,) float
        Point to test, LVLH (m).
    net_positions_lvlh : (n, 3) float
        Net node positions, LVLH (m).

    Returns
    -------
    bool
        False also for a flat or degenerate node cloud (nothing is enclosed).
    """
    try:
        hull = trimesh.convex.convex_hull(np.asarray(net_positions_lvlh, float))
    except Exception:  # flat or degenerate node cloud: nothing is enclosed
        return False
    return bool(hull.contains(np.atleast_2d(point_lvlh))[0])


def released_pieces(events: list[ReleaseEvent], assembly, series, net_positions_final) -> list[dict]:
    """Report per release event (see module doc); states are the last recorded sample.

    Parameters
    ----------
    events : list of ReleaseEvent
        The releases of the run (:attr:`ReleaseMonitor.events`).
    assembly : multibody.assembly.ImpactAssembly
        The simulated assembly (bodies, joints; initial poses give the piece's shape).
    series : dict
        Recorded series (:mod:`multibody.recorder`): ``body_com_lvlh`` (k, nb, 3) m,
        ``body_velocity_lvlh`` (k, nb, 3) m/s, ``body_omega_body`` (k, nb, 3) rad/s body frame,
        ``body_to_lvlh`` (k, nb, 3, 3).
    net_positions_final : (n, 3) float
        Net node positions at the end of the run, LVLH (m).

    Returns
    -------
    list of dict
        One JSON-ready dict per event, in release order: location, joint, release time (s),
        criterion and demand, bodies, mass (kg), size (m), and at the end of the run the piece's
        CoM position (m) and velocity (m/s) relative to the chaser, LVLH, spin (rad/s, LVLH),
        and whether it is inside the net.
    """
    bodies, joints = assembly.bodies, assembly.joints
    masses = np.array([b.mass for b in bodies])
    attitudes0 = [b.body_to_lvlh for b in bodies]
    coms0 = [b.com_lvlh for b in bodies]
    com_end = series["body_com_lvlh"][-1]
    vel_end = series["body_velocity_lvlh"][-1]
    omega_end = series["body_omega_body"][-1]
    rot_end = series["body_to_lvlh"][-1]
    out, before = [], set()
    for e in sorted(events, key=lambda e: e.time):
        # the child and everything still attached below it (earlier releases cut their joints)
        members = subtree_bodies(joints, joints[e.joint].child, before)
        before.add(e.joint)
        m = masses[members]
        com = m @ com_end[members] / m.sum()
        vel = m @ vel_end[members] / m.sum()
        root = members[0]
        spin_lvlh = rot_end[root] @ omega_end[root]
        out.append({
            "location": e.location, "joint": joints[e.joint].name, "release_time_s": e.time,
            "criterion": e.criterion, "demand_at_release": e.demand,
            "bodies": [bodies[k].name for k in members], "mass_kg": float(m.sum()),
            "size_m": piece_size(bodies, members, attitudes0, coms0),
            "position_relative_to_chaser_lvlh_m": com.tolist(),
            "velocity_relative_to_chaser_lvlh_m_s": vel.tolist(),
            "spin_lvlh_rad_s": spin_lvlh.tolist(), "spin_rate_rad_s": float(np.linalg.norm(spin_lvlh)),
            "inside_net_at_end": inside_net(com, net_positions_final),
        })
    return out
