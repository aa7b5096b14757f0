"""One node striking a fixed plane against the Hertz / Hunt-Crossley analytic solution.

References: Hertz impact of a sphere on a half-space, F = k d^1.5 (Johnson, Contact Mechanics,
1985, Sec. 11.4): max penetration d_m = (5 m v^2 / (4 k))^(2/5), duration
T = 2 (d_m / v) int_0^1 (1 - u^(5/2))^(-1/2) du = (2/2.5) B(0.4, 0.5) d_m / v.
Hunt-Crossley F = k d^n (1 + lam d'), lam = 1.5 alpha: the phase-plane relation
m u du/dd = -k d^n (1 + lam u) integrates in closed form (Marhefka & Orin 1999):
u/lam - ln(1 + lam u)/lam^2 = u0/lam - ln(1 + lam u0)/lam^2 - (k/m) d^(n+1)/(n+1).
"""
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import beta

from multibody.impact import ImpactSimulation
from tests.conftest import KEVLAR_NODE_MASS as M
from tests.conftest import PAPER_CONTACT_STIFFNESS as K


def _contact_force_history(assembly):
    rec = ImpactSimulation(assembly).run()
    force = np.linalg.norm(rec.series["contact_force_lvlh"][:, 0], axis=1)
    return rec, force


def _hertz_peak_and_duration(v):
    d_max = (5 * M * v**2 / (4 * K)) ** 0.4
    return K * d_max**1.5, 2.0 / 2.5 * beta(0.4, 0.5) * d_max / v


def _hunt_crossley_phase(v, alpha):
    """u(d) on approach (+) and rebound (-) branches from the closed-form phase plane."""
    lam = 1.5 * alpha
    g = lambda u: u / lam - np.log1p(lam * u) / lam**2  # noqa: E731
    c0 = g(v)
    d_max = ((c0 - g(0.0)) * 2.5 * M / K) ** 0.4
    rhs = lambda d: c0 - K / M * d**2.5 / 2.5  # noqa: E731
    u_in = lambda d: brentq(lambda u: g(u) - rhs(d), 0.0, v) if d < d_max else 0.0  # noqa: E731
    u_lo = -1.0 / lam + 1e-15
    u_out = lambda d: brentq(lambda u: g(u) - rhs(d), u_lo, 0.0) if d < d_max else 0.0  # noqa: E731
    return lam, d_max, u_in, u_out


def _hunt_crossley_reference(v, alpha):
    lam, d_max, u_in, u_out = _hunt_crossley_phase(v, alpha)
    ds = np.linspace(0.0, d_max, 4001)[1:-1]
    force = lambda d, u: K * d**1.5 * (1 + lam * u)  # noqa: E731
    peak = max(max(force(d, u_in(d)) for d in ds), max(force(d, u_out(d)) for d in ds))
    # Duration: time = int dd / |u| on both branches (integrable 1/sqrt singularity at d_max).
    t_in = quad(lambda d: 1.0 / u_in(d), 0.0, d_max, limit=200)[0]
    t_out = quad(lambda d: -1.0 / u_out(d), 0.0, d_max, limit=200)[0]
    rebound = -u_out(0.0)
    return peak, t_in + t_out, rebound


@pytest.mark.parametrize("speed", [2.0, 20.0])
def test_elastic_hertz_peak_force_and_duration(node_strikes_plane, speed):
    step = 2e-7 if speed > 10 else 1e-6
    end = 4e-4 if speed > 10 else 1.2e-3
    rec, force = _contact_force_history(node_strikes_plane(speed, alpha=0.0, step=step, contact_substep=1.0,
                                                           end_time=end))
    peak, duration = _hertz_peak_and_duration(speed)
    # 2 %: the tolerance; discretisation error at >200 steps per contact is ~0.1 %.
    assert force.max() == pytest.approx(peak, rel=0.02)
    assert (force > 0).sum() * step == pytest.approx(duration, rel=0.02)


def test_hunt_crossley_peak_force_duration_and_rebound(node_strikes_plane):
    speed, alpha = 20.0, 0.05  # paper Table 2 damping constant at the paper's impact speed
    step = 2e-7
    rec, force = _contact_force_history(node_strikes_plane(speed, alpha=alpha, step=step, contact_substep=1.0))
    peak, duration, rebound = _hunt_crossley_reference(speed, alpha)
    assert force.max() == pytest.approx(peak, rel=0.02)
    assert (force > 0).sum() * step == pytest.approx(duration, rel=0.02)
    assert -rec.net["velocities_lvlh"][-1, 0, 1] == pytest.approx(rebound, rel=0.005)


@pytest.mark.parametrize("step", [5e-5, 1e-4, 2e-4])
def test_sub_cycled_contact_keeps_the_rebound_at_large_steps(node_strikes_plane, step):
    """With a step longer than the whole contact, the sub-cycled impulse still gives the
    analytic rebound (restitution) velocity; plain force evaluation would eject the node at
    several times its impact speed (63 m/s at 5e-5 s, bench/step_convergence.py)."""
    speed, alpha = 20.0, 0.05
    rec, _ = _contact_force_history(node_strikes_plane(speed, alpha=alpha, step=step, contact_substep=2e-6,
                                                       end_time=10 * step))
    _, _, rebound = _hunt_crossley_reference(speed, alpha)
    # 0.5 %: the 2 us sub-step resolves the ~150 us contact with ~75 sub-steps.
    assert -rec.net["velocities_lvlh"][-1, 0, 1] == pytest.approx(rebound, rel=0.005)


@pytest.mark.parametrize("gap", [1e-9, 1.2e-5])
@pytest.mark.parametrize("push", [0.0, 1e-9, -1e-9, 1e-3, -1e-3])
def test_sub_cycle_rebound_from_a_gap_under_a_constant_push(push, gap):
    """A node one sub-step's travel short of the surface, closing at 20 m/s, under a small
    constant non-contact force along the normal (a nearly slack thread): the closed-form
    free-flight part of the sub-cycle must hand over to contact at the right sub-step.
    Expected: the analytic Hunt-Crossley rebound speed, corrected by the push's impulse over
    the step (its effect is exact, it acts in closed form); 0.5 % as in the test above. A
    tiny push once made the touching time a 0/0 and skipped the whole contact."""
    from multibody.contact import contact_over_step

    speed, alpha, step, n_sub = 20.0, 0.05, 4e-4, 200  # 2 us sub-steps; the ~150 us contact ends within the step
    normal = np.array([[0.0, 0.0, 1.0]])           # from the body to the node
    # gap (m): touches within the first sub-step (1.2e-5 m is 0.3 of a sub-step's travel)
    force = np.array([0.0, 0.0, -push])             # pushes the node towards the body
    impulses = np.zeros((1, 3))
    _, _, _, _, _, end_z, _ = contact_over_step(
        np.array([-gap]), np.array([[0.0, 0.0, -speed]]), normal, force, M, np.array([1e12]), step, n_sub,
        K, 1.5, 1.5 * alpha * K, 0.0, 0.0, 0.1, impulses, np.zeros(1), np.zeros((1, 3)), np.zeros((1, 3)))
    _, _, rebound = _hunt_crossley_reference(speed, alpha)
    # end_z is the velocity change by contact alone: rebound + speed (the push acts separately).
    assert end_z - speed == pytest.approx(rebound, rel=0.005)
