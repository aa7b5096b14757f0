"""Momentum and energy of a free impact (no orbit): net + tumbling box, one coupled system."""
import numpy as np

from multibody.impact import ImpactSimulation




def _run(assembly):
    return ImpactSimulation(assembly).run()


def test_linear_and_angular_momentum_conserved(small_net_on_box):
    rec = _run(small_net_on_box())
    s = rec.series
    assert s["contact_force_lvlh"][:, 0, 1].max() > 100.0, "the net must actually hit the box"
    p, h = s["momentum_linear_lvlh"], s["momentum_angular_lvlh"]
    # Scales: initial linear momentum, and sum |r||m v| + |J w| for the angular momentum
    # (the total is near zero by symmetry, so it cannot be its own scale).
    net = rec.assembly.net
    x0, v0 = rec.net["positions_lvlh"][0], rec.net["velocities_lvlh"][0]
    box = rec.assembly.bodies[0]
    h_scale = np.sum(np.linalg.norm(x0, axis=1) * net.masses * np.linalg.norm(v0, axis=1)) + np.linalg.norm(
        box.inertia_body @ box.omega_body)
    # 1e-6 relative (the figure): contact and its reaction are one action-reaction pair
    # on one line of action, so only round-off and the rigid-body rotation update remain.
    assert np.linalg.norm(p - p[0], axis=1).max() / np.linalg.norm(p[0]) < 1e-6
    assert np.linalg.norm(h - h[0], axis=1).max() / h_scale < 1e-6


def test_energy_bookkeeping_closes(small_net_on_box):
    """Kinetic + thread elastic + contact elastic + dissipated (threads, contact, friction) = initial energy."""
    rec = _run(small_net_on_box(step=2e-5, end_time=0.4))
    s = rec.series
    e0 = s["energy_total"][0]
    dissipated = s["energy_dissipated_threads"][-1] + s["energy_dissipated_contact"][-1]
    assert dissipated > 0.05 * e0, "the check is only meaningful when much energy is dissipated"
    # 1 % (the figure) of the initial energy, at every output sample.
    assert np.abs(s["energy_total"] - e0).max() / e0 < 0.01
