"""The node-local implicit contact step (multibody/contact_implicit.py) against its invariants.

The discrete-gradient step conserves kinetic plus Hertz energy exactly for any step (Gonzalez 1996),
books the Hunt-Crossley damping's work exactly, and settles at the static Hertz penetration under a
constant load: each is checked to round-off (1e-9 relative: the Newton tolerance is 1e-11 of the
penetration scale, and a contact takes a few hundred steps).
"""
import numpy as np
import pytest

from multibody.contact_implicit import contact_implicit_step, implicit_normal_step
from tests.conftest import KEVLAR_NODE_MASS as M
from tests.conftest import PAPER_CONTACT_STIFFNESS as K

STEP = 1e-4  # the reference case's step: the contact period at rest is 0.6 ms, about 6 steps


def _hertz_energy(d):
    return K * max(d, 0.0) ** 2.5 / 2.5


def _advance(d0, rate0, accel_n, damping, n_steps, mass=M):
    """Iterate the implicit normal step; returns penetration, rate and the booked dissipation."""
    d, rate, dissipated = d0, rate0, 0.0
    history = []
    for _ in range(n_steps):
        d1, _, extra = implicit_normal_step(d, rate, accel_n, STEP, mass, K, 1.5, damping)
        dissipated += extra * (d1 - d)
        rate = 2.0 * (d1 - d) / STEP - rate   # trapezoid: d1 = d + h (rate + rate1) / 2
        d = d1
        history.append((d, rate))
    return d, rate, dissipated, np.array(history)


@pytest.mark.parametrize("speed", [0.01, 0.1, 1.0])
def test_elastic_contact_conserves_energy_and_rebounds_at_the_impact_speed(speed):
    d, rate, _, history = _advance(0.0, speed, 0.0, 0.0, 400)
    energy = 0.5 * M * history[:, 1] ** 2 + np.array([_hertz_energy(x) for x in history[:, 0]])
    assert np.abs(energy - 0.5 * M * speed**2).max() <= 1e-9 * 0.5 * M * speed**2
    assert d < 0.0 and rate == pytest.approx(-speed, rel=1e-9)  # separated, leaving at the impact speed


def test_damping_work_is_booked_exactly():
    alpha = 0.05
    d, rate, dissipated, _ = _advance(0.0, 0.1, 0.0, 1.5 * alpha * K, 400)
    assert d < 0.0 and 0.0 < -rate < 0.1
    lost = 0.5 * M * 0.1**2 - 0.5 * M * rate**2
    assert dissipated == pytest.approx(lost, rel=1e-9)


def test_a_constant_load_settles_at_the_static_hertz_penetration():
    push = 10.0   # N towards the body: a taut thread's pull on a node resting on the surface
    d, rate, _, _ = _advance(0.0, 0.0, -push / M, 1.5 * 0.05 * K, 20000)
    assert d == pytest.approx((push / K) ** (1 / 1.5), rel=1e-6)
    assert abs(rate) < 1e-9


def test_friction_stops_the_slip_but_never_reverses_it():
    impulse = np.zeros(3)
    normal = np.array([0.0, 0.0, 1.0])
    # resting at the static penetration of a 10 N load, sliding at 1 mm/s along x
    d0 = (10.0 / K) ** (1 / 1.5)
    _, _, _, ex, _, ez, dissipated = contact_implicit_step(
        d0, np.array([1e-3, 0.0, 0.0]), normal, np.array([0.0, 0.0, -10.0]), M, 1e12, STEP, K, 1.5, 0.0,
        0.19, 0.152, 0.01, impulse)
    assert -1e-3 <= ex < 0.0                        # slowed, at most to a stop
    assert ez > 0.0 and dissipated >= 0.0


def test_friction_creep_under_a_tangential_pull_is_the_regularised_law_s():
    """A node pressed on a surface (2 N) and pulled along it (0.3 N, below mu_s N = 0.38 N) creeps
    at the slip where the Hollar law (paper eq. 7) gives mu(s) N = T: x (mu_k + 2 (mu_s - mu_k) / (1 + x^2))
    = 0.15 with x = s / V_t, s = 7.475 mm/s (solved below). Reading mu at the slip without friction
    made the implicit step creep at 5.52 mm/s (-26 %: resting contacts stuck too well)."""
    from scipy.optimize import brentq

    mus, muk, vt, press, pull = 0.19, 0.152, 0.01, 2.0, 0.3
    x = brentq(lambda x: x * (muk + 2 * (mus - muk) / (1 + x * x)) - pull / press, 1e-6, 1.0)
    d = (press / K) ** (1 / 1.5)
    v = np.zeros(3)
    external = np.array([pull, 0.0, -press])
    for _ in range(400):          # 40 ms: the creep settles within a few ms
        impulse = np.zeros(3)
        mean = contact_implicit_step(d, v, np.array([0.0, 0.0, 1.0]), external, M, 1e3, STEP, K, 1.5,
                                     1.5 * 0.05 * K, mus, muk, vt, impulse)
        d -= STEP * (v[2] + mean[2]) - 0.5 * STEP * STEP * press / M
        v = v + np.array(mean[3:6]) + external / M * STEP
    # 0.5 %: the step's trapezoid on a creep that settles; measured 0.05 % off
    assert v[0] == pytest.approx(x * vt, rel=5e-3)


@pytest.mark.parametrize("seed", [0, 1])
def test_friction_impulse_solves_its_consistency_equation_to_round_off(seed):
    """friction_impulse's j satisfies j = mu(s - j / (2 m)) N (Hollar, paper eq. 7, read at the step's
    mean slip) or stops the slip, and equals the unique root a bracketing solver finds where the
    residual is monotonic. Inputs span slips of 0.1 to 100 times the transition speed and normal
    impulses from feather touches to ones that stop the slip. Tolerance 1e-12 of the stopping
    impulse: the solver stops when its Newton step is below 1e-13 of it, Brent's method here at 1e-15."""
    from scipy.optimize import brentq

    from multibody.contact import hollar_friction_coefficient as mu
    from multibody.contact_implicit import friction_impulse

    rng = np.random.default_rng(seed)
    mus, muk, vt = 0.19, 0.152, 0.01
    for _ in range(500):
        mass = 10 ** rng.uniform(-3, 0)
        slip = vt * 10 ** rng.uniform(-1, 2)
        end = slip * rng.uniform(0.5, 1.5)
        normal = mass * slip * 10 ** rng.uniform(-2, 2) / mus
        j = friction_impulse(slip, end, normal, mass, mus, muk, vt)
        stop = mass * end
        assert 0.0 <= j <= stop
        if j == stop:
            assert stop <= mu(max(slip - 0.5 * end, 0.0), mus, muk, vt) * normal
            continue
        def residual(x):
            return x - mu(max(slip - 0.5 * x / mass, 0.0), mus, muk, vt) * normal
        assert abs(residual(j)) <= 1e-12 * stop
        grid = np.linspace(0.0, stop, 200)
        if np.all(np.diff([residual(x) for x in grid]) > 0.0):   # a single root: the same one
            assert j == pytest.approx(brentq(residual, 0.0, stop, xtol=1e-15 * stop), abs=1e-12 * stop)


@pytest.mark.parametrize("d0, d1", [(2e-6, -3e-6), (-1.4e-6, 6e-7), (2.3e-6, 2.2e-7), (2.7e-5, 2.9e-5)])
def test_normal_residual_derivative_is_the_residuals_own(d0, d1):
    """Newton's derivative of the implicit normal step is the exact derivative of its residual, so Newton
    converges quadratically (with the midpoint estimate used before it converged only linearly, by 1/10 to
    1/50 an iteration, on rebounds and closing gaps). Against central differences of the residual itself;
    the cases: a rebound leaving the surface, a gap closing into contact, a contact easing, one deepening
    (penetrations of the reference run's resting contacts, um). Tolerance 1e-6 relative: the difference
    quotient's truncation at a 1e-12 m step is about (1e-12 / 1e-6)^2 = 1e-12, its round-off about
    1e-16 x residual / 1e-12 m, well below."""
    from multibody.contact_implicit import _hertz_energy as energy
    from multibody.contact_implicit import _normal_residual

    damping, rate0, accel_n, mass = 1.5 * 0.05 * K, 0.02, -3.0, M
    p0 = max(d0, 0.0)
    args = (d0, p0, energy(p0, K, 1.5), rate0, accel_n, 1.0 / STEP, STEP, STEP / mass, K, 1.5, damping)
    residual, derivative, force, _ = _normal_residual(d1, *args)
    assert force > 0.0   # the contact acts (else the derivative is 2 / h, trivially exact)
    h = 1e-12
    numeric = (_normal_residual(d1 + h, *args)[0] - _normal_residual(d1 - h, *args)[0]) / (2.0 * h)
    assert derivative == pytest.approx(numeric, rel=1e-6)
