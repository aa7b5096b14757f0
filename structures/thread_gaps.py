"""What the threads that passed through a part could have added to a weak location's demand.

The net's contact acts on its nodes only, so a thread whose nodes lie on either side of a thin part
passes through it without a force (:mod:`multibody.thread_crossing`). A location judged "holds" on
such a run holds only if it would also hold with the load those threads would have put on the part.
This module bounds that load at each net snapshot (twice each passing thread's tension, at its
crossing point, on every body carried by the location's joint) and the demand it could add, so the
verdict can keep "holds" only where the margin absorbs the bound.

The added demand is bounded with the location's demands per unit load: a stress at a cut is the
largest over the section of a norm of a linear function of the six internal loads, so it is
sublinear, and a load of magnitude F along an unknown direction adds at most F times the sum of the
demands of unit loads along the three joint axes.
"""
from __future__ import annotations

import numpy as np

from multibody.assembly import subtree_bodies
from multibody.thread_crossing import PassThroughSnapshot, missed_load_bounds
from structures.indeterminacy import Indeterminacy
from structures.weak_location import WeakLocation, demands, joint_loads, judged_demands


def demand_per_unit_load(location: WeakLocation) -> dict[str, tuple[float, float]]:
    """Per criterion, the demand of a unit force and of a unit moment of unknown direction at the joint:
    the sum of the demands of unit loads along the three joint axes (module docstring).

    Parameters
    ----------
    location : WeakLocation
        The location.

    Returns
    -------
    dict of str to (float, float)
        Criterion -> (demand per N of force, demand per N m of moment), in the criterion's unit.
    """
    unit, zero = np.eye(3), np.zeros((3, 3))
    per_force, per_moment = demands(location, unit, zero), demands(location, zero, unit)
    return {name: (float(per_force[name].sum()), float(per_moment[name].sum())) for name in location.criteria()}


def joint_point_lvlh(assembly, joint: int, com_lvlh, body_to_lvlh):
    """The joint point at one sample, carried by the joint's child body, LVLH (m).

    Parameters
    ----------
    assembly : multibody.assembly.ImpactAssembly
        The joint's initial point and the child's initial pose.
    joint : int
        The joint's index.
    com_lvlh : (nb, 3) float
        Body CoMs at the sample, LVLH (m).
    body_to_lvlh : (nb, 3, 3) float
        Body attitudes at the sample.

    Returns
    -------
    (3,) float
    """
    spec = assembly.joints[joint]
    child = assembly.bodies[spec.child]
    point_child_body = child.body_to_lvlh.T @ (np.asarray(spec.point_lvlh) - child.com_lvlh)
    return com_lvlh[spec.child] + body_to_lvlh[spec.child] @ point_child_body


def pass_through_check(location: WeakLocation, result: dict, history: list[PassThroughSnapshot], assembly,
                       series: dict, skip_until: float) -> dict | None:
    """Could the load of the threads that passed through the bodies a location carries have taken it past
    its allowable? None when no loaded thread passed through them in the judged window.

    Parameters
    ----------
    location : WeakLocation
        The location.
    result : dict
        Its verdict (:func:`structures.weak_location.assess`): the criteria's decisive allowables.
    history : list of PassThroughSnapshot
        :func:`multibody.thread_crossing.pass_through_history` of the run.
    assembly : multibody.assembly.ImpactAssembly
        The joints and bodies.
    series : dict
        Recorded series: ``time``, ``body_com_lvlh``, ``body_to_lvlh``, ``joint_force_joint``, ``joint_moment_joint``.
    skip_until : float
        Start of the judged window (s).

    Returns
    -------
    dict or None
        ``bodies`` (names), ``snapshots`` (how many), ``first_s``, ``last_s``, ``most_threads``, ``force_bound_N``,
        ``moment_bound_Nm`` (largest over the snapshots, about the joint point), ``could_exceed`` (criterion names
        whose demand plus its bound reaches the decisive allowable at some snapshot) and ``worst_ratio`` (largest
        (demand + bound) / allowable).
    """
    carried = set(subtree_bodies(assembly.joints, assembly.joints[location.joint].child))
    time = np.asarray(series["time"], float)
    demand = judged_demands(location, time, *joint_loads(location, series))
    per_unit = demand_per_unit_load(location)
    rows = []
    for snap in history:
        hit = [b for b in snap.by_body if b in carried]
        if snap.time < skip_until or not hit:
            continue
        k = int(np.argmin(np.abs(time - snap.time)))
        point = joint_point_lvlh(assembly, location.joint, series["body_com_lvlh"][k], series["body_to_lvlh"][k])
        bounds = [missed_load_bounds(snap.by_body[b], snap.tension, point) for b in hit]
        force, moment = (float(sum(v)) for v in zip(*bounds))
        if force > 0.0:
            rows.append((snap.time, k, hit, sum(snap.by_body[b].threads.size for b in hit), force, moment))
    if not rows:
        return None
    could_exceed, worst = set(), 0.0
    for _, k, _, _, force, moment in rows:
        for name, (per_force, per_moment) in per_unit.items():
            allowable = result["criteria"][name]["decisive_allowable"]
            ratio = (demand[name][k] + per_force * force + per_moment * moment) / allowable
            worst = max(worst, ratio)
            if ratio >= 1.0:
                could_exceed.add(name)
    return {"bodies": sorted({assembly.bodies[b].name for row in rows for b in row[2]}), "snapshots": len(rows),
            "first_s": rows[0][0], "last_s": rows[-1][0], "most_threads": max(r[3] for r in rows),
            "force_bound_N": max(r[4] for r in rows), "moment_bound_Nm": max(r[5] for r in rows),
            "could_exceed": sorted(could_exceed), "worst_ratio": float(worst)}


def pass_through_reason(check: dict) -> Indeterminacy:
    """Why a location that held is indeterminate because of threads passing through what it carries
    (rule ``thread_pass_through``).

    Parameters
    ----------
    check : dict
        The location's :func:`pass_through_check` (bodies, snapshots, times, bounds, criteria it could exceed).

    Returns
    -------
    structures.indeterminacy.Indeterminacy
    """
    return Indeterminacy("thread_pass_through", (
            f"net threads passed through {', '.join(check['bodies'])} (node-only contact; up to "
            f"{check['most_threads']} threads at once, {check['snapshots']} snapshots from {check['first_s']:.2f} to "
            f"{check['last_s']:.2f} s): the load they would have put on it, at most {check['force_bound_N']:.3g} N and "
            f"{check['moment_bound_Nm']:.3g} N m about the joint, could take {', '.join(check['could_exceed'])} "
            f"past the allowable ({check['worst_ratio']:.2f} of it)"))
