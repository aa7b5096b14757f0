"""The seed paper's sequential method as two models built from one impact case
(``simulation.coupling = "sequential"``; Cuadrat-Grzybowski & Gill 2024, Sec. 2.1).

1. :func:`wall_inputs`: the net against the target held fixed ("the space debris object behaves as
   a rigid wall"): every debris body weighs :data:`WALL_MASS_FACTOR` times its mass and inertia, so
   the net's contacts cannot move it (20 m/s of a 10 kg net moves an 8 t target by ~1e-8 m/s), while
   its shapes, joints and the contact law stay those of the case.
2. :func:`driven_inputs`: the free multibody debris without the net, driven by the contact force
   (LVLH) and moment (body frame) histories recorded on each body in step 1
   (:mod:`multibody.recorded_loads`); hinge loads, stresses and the verdict come from this run.

The coupled model (the default) needs neither: the net and the debris move together.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from multibody.assembly import ImpactAssembly
from multibody.net import single_node_net
from multibody.recorded_loads import RecordedBodyLoads
from riskassess.models.impact import ModelInputs

#: Mass and inertia factor that makes the debris a wall for the net (step 1).
WALL_MASS_FACTOR = 1e6


def wall_inputs(inputs: ModelInputs) -> ModelInputs:
    """Step 1: the case's model with every debris body :data:`WALL_MASS_FACTOR` times heavier.

    Parameters
    ----------
    inputs : ModelInputs
        The case's coupled model (:func:`riskassess.models.impact.model_inputs`).

    Returns
    -------
    ModelInputs
        A copy with debris masses (kg) and inertias (kg m^2) scaled; the chaser is unchanged.
    """
    assembly = inputs.assembly
    heavy = [dataclasses.replace(b, mass=b.mass * WALL_MASS_FACTOR, inertia_body=b.inertia_body * WALL_MASS_FACTOR)
             if k in assembly.debris_indices else b for k, b in enumerate(assembly.bodies)]
    return ModelInputs(dataclasses.replace(assembly, bodies=heavy), inputs.rest_attitudes, inputs.rest_coms)


def recorded_loads(series: dict, reference_energy: float) -> RecordedBodyLoads:
    """The contact loads step 1 recorded on each body (interval means; the t = 0 sample has none).

    Parameters
    ----------
    series : dict
        Step 1's recorded series: ``time`` (k,) s, ``contact_force_lvlh`` (k, nb, 3) N in LVLH,
        ``contact_moment_body`` (k, nb, 3) N m in each body frame.
    reference_energy : float
        Energy the driven run's energy balance is judged against (J): step 1's reference, the
        net's launch energy.

    Returns
    -------
    multibody.recorded_loads.RecordedBodyLoads
        The loads from the second sample on ((k - 1,) times).
    """
    return RecordedBodyLoads(time=np.asarray(series["time"][1:], float),
                             force_lvlh=np.asarray(series["contact_force_lvlh"][1:], float),
                             moment_body=np.asarray(series["contact_moment_body"][1:], float),
                             reference_energy=reference_energy)


def driven_inputs(inputs: ModelInputs, loads: RecordedBodyLoads) -> ModelInputs:
    """Step 2: the case's debris, free, without the net (one node at rest at the LVLH origin,
    the chaser, where it has no contact and no orbital force), driven by ``loads``.

    Parameters
    ----------
    inputs : ModelInputs
        The case's coupled model; it must have no chaser.
    loads : multibody.recorded_loads.RecordedBodyLoads
        Step 1's contact loads on each body (force N, LVLH; moment N m, body frame).

    Returns
    -------
    ModelInputs

    Raises
    ------
    ValueError
        For a case with a ``[chaser]``.
    """
    assembly: ImpactAssembly = inputs.assembly
    if assembly.chaser is not None or assembly.mount is not None:
        raise ValueError("simulation.coupling = 'sequential' takes no [chaser]: the paper's method has the net "
                         "launched free")
    placeholder = single_node_net(np.zeros(3), float(assembly.net.masses.min()), float(assembly.net.radii.min()))
    driven = dataclasses.replace(assembly, net=placeholder, net_velocity=np.zeros((1, 3)), body_loads=loads)
    return ModelInputs(driven, inputs.rest_attitudes, inputs.rest_coms)


def applied_contact_series(series: dict, loads: RecordedBodyLoads) -> dict:
    """Step 2's series with the contact loads it was driven by, in both frames, in place of the
    (absent) net contact: what the verdict's evidence check and the products read.

    Parameters
    ----------
    series : dict
        Step 2's recorded series (``time`` (k,) s, ``body_to_lvlh`` (k, nb, 3, 3), contact arrays
        (k, nb, 3)).
    loads : multibody.recorded_loads.RecordedBodyLoads
        The loads step 2 was driven by.

    Returns
    -------
    dict
        A copy of ``series`` with ``contact_force_lvlh`` / ``contact_force_body`` (N) and
        ``contact_moment_body`` / ``contact_moment_lvlh`` (N m) replaced, (k, nb, 3) each; zero at t = 0.
    """
    out = dict(series)
    k = len(series["time"])
    force_lvlh = np.zeros_like(series["contact_force_lvlh"])
    moment_body = np.zeros_like(series["contact_moment_body"])
    n = min(k - 1, len(loads.time))
    force_lvlh[1:n + 1] = loads.force_lvlh[:n]
    moment_body[1:n + 1] = loads.moment_body[:n]
    body_to_lvlh = series["body_to_lvlh"]
    out["contact_force_lvlh"] = force_lvlh
    out["contact_moment_body"] = moment_body
    out["contact_force_body"] = np.einsum("kbji,kbj->kbi", body_to_lvlh, force_lvlh)
    out["contact_moment_lvlh"] = np.einsum("kbij,kbj->kbi", body_to_lvlh, moment_body)
    return out
