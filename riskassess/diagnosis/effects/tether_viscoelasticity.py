"""``tether_viscoelasticity``: the main tether relaxes: a standard linear solid instead of a Kelvin-Voigt tether.

The nominal main tether is a tension-only Kelvin-Voigt element, T = max(0, k e + c e') while
stretched (Boonrath, Singh & Botta 2024 eq. 5). A viscoelastic tether (polymer braid) adds a
Maxwell branch in parallel, a spring k_m in series with a dashpot k_m tau_m (the standard linear
solid, e.g. Lakes, *Viscoelastic Materials*, 2009, Sec. 2.6), whose tension T_m (N) is a state:

.. math::
    T = \\max(0,\\ k\\,e + c\\,\\dot e + T_m)\\ (e > -T_m/k),\\qquad
    \\dot T_m = k_m\\,\\frac{d\\max(e, 0)}{dt} - \\frac{T_m}{\\tau_m},\\quad T_m \\ge 0

with e = l - l0 the elongation (m). Fast loading (t << tau_m) sees the stiffness k + k_m, slow
loading k; at tau_m -> 0 the branch is a dashpot k_m tau_m. The branch is a strand: it cannot push
(T_m >= 0) and it is loaded only while the tether is stretched.

Implementation: over one step h the exact solution for a constant elongation rate is affine in the
step's end elongation, T_m(t + h) = T_m(t) exp(-h/tau_m) + b (e(t + h) - e(t)) with
b = k_m tau_m (1 - exp(-h/tau_m)) / h, so the branch *is* a spring b with a preload over the step:
the law hands the towing kernel the main tether's stiffness k + b and a rest length shortened by
the preload / (k + b) for that step. The tether, the branch included, is then part of the
connection point's implicit step (an explicit branch force, tried first, made the results depend on
the step by a factor 2 at 4 ms: P hangs on stiff, heavily damped tethers). The tension the kernel
reports is T, the ``tether_tension`` channel. (With an MRAC thrust law the controller's elongation
would include the preload's shift; the sample case uses the ramp.) Parameters: k_m and tau_m.
Towing scenario only. Its own states, two slots of the towing model: T_m (``MAXWELL``, N, zero at
t = 0) and the elongation it was last advanced at (``ELONGATION``, m; NaN at t = 0: not yet seen).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.plants.towing_dynamics import TOWING_LAW_SIGNATURE, W_TETHER, last_diagnostics
from multibody.towing_kernel import K_MT, L_MT, MT_ELONGATION

#: The effect's own states (towing model): Maxwell-branch tension T_m (N), and the main tether's
#: elongation when the branch was last advanced (m).
MAXWELL, ELONGATION, STATES = 0, 1, 2


@njit(cache=True)
def step_gain(relaxation_time, h):
    """b / k_m: the branch's stiffness over a step of ``h`` (s) per unit k_m (-); 1 for h << tau_m.

    Parameters
    ----------
    relaxation_time : float
        tau_m (s), > 0.
    h : float
        Step (s).

    Returns
    -------
    gain : float
        (1 - exp(-h/tau_m)) / (h/tau_m) (-).
    """
    ratio = h / relaxation_time
    return (1.0 - math.exp(-ratio)) / ratio if ratio > 1e-8 else 1.0 - 0.5 * ratio


@njit(cache=True)
def branch_after(maxwell_tension, elongation_before, elongation_after, maxwell_stiffness, relaxation_time, h):
    """T_m (N) after a step of ``h`` (s) in which the elongation went from ``elongation_before`` to
    ``elongation_after`` (m) at a constant rate (the exact solution), loaded over the stretched part
    only and kept >= 0.

    Parameters
    ----------
    maxwell_tension : float
        T_m at the step's start (N).
    elongation_before, elongation_after : float
        Main-tether elongation e = l - l0 at the step's start and end (m).
    maxwell_stiffness : float
        k_m (N/m).
    relaxation_time : float
        tau_m (s).
    h : float
        Step (s).

    Returns
    -------
    maxwell_tension : float
        T_m at the step's end (N), >= 0.
    """
    decay = math.exp(-h / relaxation_time)
    change = max(elongation_after, 0.0) - max(elongation_before, 0.0)
    return max(0.0, maxwell_tension * decay + maxwell_stiffness * step_gain(relaxation_time, h) * change)


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """``p`` = [k_m, tau_m, k (N/m), l0 (m) of the case's main tether]. Sets the kernel's main-tether
    stiffness and rest length for the coming step (no load).

    Parameters
    ----------
    t : float
        Time (s), the towing case's clock.
    q, v : (15,) float
        Evaluation state, kernel layout (:mod:`multibody.towing_kernel`): P, chaser and debris
        displacements from their reference positions (m, ECI; P's are stale, see
        :func:`~riskassess.diagnosis.plants.towing_dynamics.point_position`) and rotation vectors body -> ECI
        (rad); velocities (m/s, ECI) and angular velocities (rad/s, body frames).
    p : (4,) float
        [k_m (N/m), tau_m (s), the case's main-tether stiffness k (N/m) and rest length l0 (m)].
    work : (w,) float
        Packed towing model (:func:`multibody.towing.packed`).
    xe : (2,) float
        The effect's own states, ``MAXWELL`` (N) and ``ELONGATION`` (m), advanced in place.
    h : float
        Step (s) over which ``xe`` is advanced; 0: do not advance.
    load : (15,) float
        Generalized forces, kernel layout, added to in place: none (the branch acts through the main
        tether's stiffness and rest length in ``work``).
    """
    if h <= 0.0:
        return
    k_m, tau, k, rest = p[0], p[1], p[2], p[3]
    # the last evaluation's elongation, against the tether's true rest length
    e = last_diagnostics(work)[MT_ELONGATION] + work[W_TETHER + L_MT] - rest
    if not math.isnan(xe[ELONGATION]):
        xe[MAXWELL] = branch_after(xe[MAXWELL], xe[ELONGATION], e, k_m, tau, h)
    xe[ELONGATION] = e
    b = k_m * step_gain(tau, h)
    preload = xe[MAXWELL] * math.exp(-h / tau) - b * max(e, 0.0)
    work[W_TETHER + K_MT] = k + b
    work[W_TETHER + L_MT] = rest - preload / (k + b)


class TetherViscoelasticity(Effect):
    id = "tether_viscoelasticity"
    towing_extra_states = STATES
    title = "viscoelastic main tether (standard linear solid: a relaxing Maxwell branch)"
    scenarios = ("towing",)
    channels = ("tether_tension", "rel_x", "rel_y", "rel_z", "omega_x", "omega_y", "omega_z", "q_w")
    towing_law = staticmethod(towing_law)

    def initial_towing_states(self, model):
        """No Maxwell tension at t = 0; the elongation not yet seen (NaN: the first step only records it).

        Parameters
        ----------
        model : TowingModel
            The built towing model (not read).

        Returns
        -------
        xe0 : (2,) float
            [T_m (N), e (m)] = [0, NaN].
        """
        return np.array([0.0, np.nan])

    def towing_law_parameters(self, plant, values):
        """[k_m, tau_m] followed by the case's main-tether stiffness and rest length.

        Parameters
        ----------
        plant : TowingPlant
            The towing plant (its case's main tether).
        values : (m,) float
            [k_m (N/m), tau_m (s)].

        Returns
        -------
        p : (4,) float
            [k_m (N/m), tau_m (s), k (N/m), l0 (m)].
        """
        tether = plant.case.main_tether
        return np.r_[np.asarray(values, float), tether.stiffness, tether.natural_length]

    def parameter_specs(self, case, channels=None):
        # (outside towing the effect is not applicable; 1 kN/m only sizes the listed parameters)
        """k_m (N/m) and tau_m (s), both fitted on a log scale.

        Parameters
        ----------
        case : DiagnosisCase
            Validated diagnosis case; the towing case's main-tether stiffness (N/m) sizes k_m.
        channels : sequence of str, optional
            Measured channel names (not used).
        """
        k = case.towing_case.main_tether.stiffness if case.kind == "towing" else 1000.0
        # typical: a branch as stiff as the tether relaxing over tens of seconds (creep of a polymer braid);
        # weaker or faster branches hide in the damped tether (c = 300 N s/m in the Zenit-2 case)
        # both on a log scale: a ramp that loads the tether slowly against tau_m sees mostly the product
        # k_m tau_m (the viscous limit), a straight valley in (ln k_m, ln tau_m) that Gauss-Newton steps
        # follow; on a linear scale it is a hyperbola, and the fit stopped 30 % off along it (docs).
        # (k_m >= 1e-4 k: a log scale needs a positive bound; the nominal model is the k_m -> 0 limit)
        return [Parameter("maxwell_stiffness", "N/m", "stiffness of the relaxing branch k_m", k, 1e-4 * k, 30.0 * k,
                          log=True),
                Parameter("relaxation_time", "s", "relaxation time of the branch tau_m", 20.0, 0.05, 1000.0, log=True)]

    def starts(self, specs):
        """A grid over both parameters' decades (k_m: k / 3 .. 3 k; tau_m: 3 .. 300 s): a towing candidate's
        fit starts from the best of them on the training span (one run each, riskassess.diagnosis.fit), as the
        fit from one start stopped in another basin (k_m 8384 N/m and tau_m 151 s, chi^2 1060 above
        the truth's, for a 12000 N/m, 80 s tether; docs/diagnosis.md).

        Parameters
        ----------
        specs : list of Parameter
            [maxwell_stiffness, relaxation_time].

        Returns
        -------
        starts : list of (m,) float
            Nine [k_m (N/m), tau_m (s)].
        """
        return [np.array([k_m, tau]) for k_m in specs[0].typical * np.array([1 / 3, 1.0, 3.0])
                for tau in (3.0, 30.0, 300.0)]


EFFECT = TetherViscoelasticity()
