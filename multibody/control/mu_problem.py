"""The net-approach optimal-control problem and its collocation solution, the data shared by the
transcription and solver (:mod:`multibody.control.mu_approach`) and the mesh and open-loop check
(:mod:`multibody.control.mu_mesh`)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class ApproachProblem:
    """One optimal-control problem of the net approach (SI units, world frame).

    Attributes
    ----------
    model : RigidRodMUs or IndependentMUs   The dynamics (:mod:`multibody.control.mu_dynamics`).
    initial_state : (n_states,) float   Initial state in ``model.state_names`` order.
    objective : {"min_fuel", "min_time", "combined"}
    debris_center : (2,) float          Debris centre (m), world frame.
    keep_out_radius : float             r_o (m), eqs. 5-6.
    thrust_bounds : (2,) float          Thrust magnitude bounds per MU (N), eq. 7.
    intervals : int                     Collocation intervals N.
    mesh : tuple or None                Interval widths in normalized time (N,), summing to 1; None: N
                                        equal intervals. Set by the mesh refinement of
                                        :func:`~multibody.control.mu_approach.solve`.
    mesh_tolerance : float              Largest local error of an interval (-,
                                        :func:`~multibody.control.mu_mesh.local_errors`)
                                        left unrefined.
    mesh_rounds : int                   Most refinement solves after the first.
    final_time : float or None          Fixed t_f (s) (min_fuel); None: free in ``final_time_bounds``.
    final_time_bounds : (2,) float      (s).
    final_time_guess : float            (s).
    time_weight : float                 w1 of the combined cost (1/s), eq. 18.
    impulse_weight : float              w2 of the combined cost (1/(N s)), eq. 18.
    width_bounds : (2,) float or None   Mouth width bounds (m), eq. 15 (independent units).
    position_bounds : (2,) float or None  Box on every MU coordinate (m).
    min_unit_mass : float or None       Lower bound of each MU mass (kg), eq. 16.
    final_at_rest : bool                Zero velocities at t_f.
    control_smoothing : float           Weight of the tie-breaking penalty on control jumps between
                                        consecutive points (-), see
                                        :meth:`~multibody.control.mu_approach._Transcription.smoothing`.
    keep_out_margin : float             Keep-out radius added at the collocation points (m), so that the
                                        continuous path keeps r_o between them too.
    """

    model: object
    initial_state: np.ndarray
    objective: str
    debris_center: np.ndarray
    keep_out_radius: float
    thrust_bounds: tuple
    intervals: int = 50
    final_time: float | None = None
    final_time_bounds: tuple = (0.1, 20.0)
    final_time_guess: float = 7.0
    time_weight: float = 1.0
    impulse_weight: float = 1.0
    width_bounds: tuple | None = None
    position_bounds: tuple | None = None
    min_unit_mass: float | None = None
    final_at_rest: bool = False
    keep_out_margin: float = 0.02
    control_smoothing: float = 1e-4
    mesh: tuple | None = None
    mesh_tolerance: float = 1e-4
    mesh_rounds: int = 3


@dataclass
class ApproachSolution:
    """Collocation solution: nodes ``t`` (N+1,) (s), ``states`` (n_states, N+1), ``controls``
    (6, N+1) (:data:`~multibody.control.mu_dynamics.CONTROLS`) and the midpoint values ``mid_states``
    (n_states, N), ``mid_controls`` (6, N)."""

    problem: ApproachProblem
    status: str
    success: bool
    iterations: int
    solve_s: float
    final_time: float
    objective_value: float
    impulse_Ns: float
    t: np.ndarray
    states: np.ndarray
    controls: np.ndarray
    mid_states: np.ndarray
    mid_controls: np.ndarray
    extras: dict = field(default_factory=dict)

    @property
    def fuel_kg(self) -> float:
        """Fuel used by both MUs (kg): :math:`k \\int (T_1 + T_2)\\,dt` (eq. 11 integrated)."""
        return self.problem.model.fuel_rate * self.impulse_Ns
