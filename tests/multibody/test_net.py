"""Net building blocks against closed forms."""
import math

import numpy as np
import pytest

from multibody.net import (add_bending_forces, add_thread_forces, add_thread_forces_runs, bowl_net_positions,
                          flat_square_net, square_grid_threads, sum_reassociated, thread_node_mass, thread_runs,
                          thread_tension_strain)


def test_node_mass_of_the_reference_net():
    # paper Sec. 3.1 net: 2380 threads of 0.8824 m, 2 mm Kevlar (1440 kg/m^3) over 1225 nodes
    expected = 2 * 35 * 34 * (30 / 34) * np.pi * 1e-6 * 1440 / 35**2
    assert thread_node_mass(30.0, 35, 0.002, 1440.0) == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(0.00776, rel=1e-3)
    assert len(square_grid_threads(35)) == 2380


def test_thread_is_tension_only_kelvin_voigt():
    x = np.array([[0.0, 0.0, 0.0], [1.1, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    args = (np.array([[0, 1]]), np.array([1.0]), np.array([1000.0]), np.array([2.0]))
    f = np.zeros((2, 3))
    elastic, power = add_thread_forces(x, v, *args, f)
    # T = k (l - l0) + c l' = 1000 * 0.1 + 2 * 0.5 = 101 N pulling the nodes together
    assert f[0, 0] == pytest.approx(101.0) and f[1, 0] == pytest.approx(-101.0)
    assert elastic == pytest.approx(0.5 * 1000 * 0.01) and power == pytest.approx(2 * 0.25)
    f[:] = 0.0
    add_thread_forces(np.array([[0.0, 0, 0], [0.9, 0, 0]]), v, *args, f)
    assert np.all(f == 0.0), "a slack thread pushes nothing"


def test_bending_forces_are_the_energy_gradient_and_free_of_net_force_and_moment():
    rng = np.random.default_rng(7)
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [2.0, -0.2, 0.3]]) + 0.01 * rng.standard_normal((3, 3))
    triples, kb = np.array([[0, 1, 2]]), np.array([0.5])
    f = np.zeros((3, 3))
    energy = add_bending_forces(x, triples, kb, f)
    e1 = (x[1] - x[0]) / np.linalg.norm(x[1] - x[0])
    e2 = (x[2] - x[1]) / np.linalg.norm(x[2] - x[1])
    assert energy == pytest.approx(0.5 * (1 - e1 @ e2))
    h = 1e-7
    for node in range(3):
        for axis in range(3):
            xp, xm = x.copy(), x.copy()
            xp[node, axis] += h
            xm[node, axis] -= h
            grad = (add_bending_forces(xp, triples, kb, np.zeros((3, 3)))
                    - add_bending_forces(xm, triples, kb, np.zeros((3, 3)))) / (2 * h)
            # central difference error ~ h^2 * third derivative: 1e-6 relative is ample
            assert f[node, axis] == pytest.approx(-grad, rel=1e-5, abs=1e-8)
    assert np.abs(f.sum(axis=0)).max() < 1e-12
    assert np.abs(np.cross(x, f).sum(axis=0)).max() < 1e-12


def test_exported_thread_tensions_are_the_kernel_forces():
    """The vectorised tension of the exports gives, summed at the nodes, exactly the force
    the simulation kernel applies (same tension-only Kelvin-Voigt law, paper eq. 1)."""
    rng = np.random.default_rng(3)
    threads = square_grid_threads(5)
    n = 25
    grid = np.stack(np.meshgrid(np.arange(5.0), np.arange(5.0)), -1).reshape(-1, 2)
    x = np.c_[grid, np.zeros(n)] + rng.normal(0, 0.08, (n, 3))   # some threads slack, some taut
    v = rng.normal(0, 2.0, (n, 3))
    rest = np.full(len(threads), 1.0)
    k, c = np.full(len(threads), 6.2e4), np.full(len(threads), 1.58)
    kernel_force = np.zeros((n, 3))
    add_thread_forces(x, v, threads, rest, k, c, kernel_force)
    tension, strain = thread_tension_strain(x, v, threads, rest, k, c)
    d = x[threads[:, 1]] - x[threads[:, 0]]
    unit = d / np.linalg.norm(d, axis=1, keepdims=True)
    force = np.zeros((n, 3))
    np.add.at(force, threads[:, 0], tension[:, None] * unit)
    np.add.at(force, threads[:, 1], -tension[:, None] * unit)
    assert np.allclose(force, kernel_force, rtol=1e-12, atol=1e-9)
    assert np.allclose(strain, np.linalg.norm(d, axis=1) - 1.0, rtol=0, atol=1e-15)  # rest length 1 m
    assert (tension[strain <= 0] == 0).all() and (tension > 0).any() and (strain < 0).any()
    # snapshots stack: (frames, nodes, 3) in, (frames, threads) out
    tension2, _ = thread_tension_strain(np.stack([x, x]), np.stack([v, v]), threads, rest, k, c)
    assert np.array_equal(tension2[1], tension)


def test_thread_runs_give_the_sequential_loop_to_the_bit():
    """The vectorized run-by-run thread pass equals add_thread_forces exactly in the forces (same law, same order
    of each node's sum), and in the elastic energy and damping power to round-off (their totals are partial
    sums, multibody.net.sum_reassociated: within 1e-14 of themselves, a few ulp of the total over some 200
    positive terms), on a crumpled 9 x 9 net with bullets (about half of the threads slack) and on a shuffled
    thread list (runs of one thread)."""
    rng = np.random.default_rng(11)
    net = flat_square_net([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 8.0, 9, 0.01, 0.01, 6.2e4, 1.58, 1.8, 0.01, 1.0)
    n = net.n_nodes
    x = net.positions + rng.normal(0, 0.05, (n, 3))
    v = rng.normal(0, 2.0, (n, 3))
    for order in (np.arange(len(net.threads)), rng.permutation(len(net.threads))):
        threads = net.threads[order]
        rest, k, c = net.rest_lengths[order], net.stiffness[order], net.damping[order]
        expected = np.zeros((n, 3))
        elastic, power = add_thread_forces(x, v, threads, rest, k, c, expected)
        runs = thread_runs(threads, rest, k, c)
        force = np.zeros((3, n))
        got = add_thread_forces_runs(np.ascontiguousarray(x.T), np.ascontiguousarray(v.T), runs, force,
                                     np.zeros((5, len(runs.rest_lengths))))
        assert np.array_equal(force.T, expected)
        assert got == pytest.approx((elastic, power), rel=1e-14, abs=0.0)
        assert 0 < elastic and 0 < power
    # the grid's threads are two runs (padded) plus the four tethers
    assert len(thread_runs(net.threads, net.rest_lengths, net.stiffness, net.damping).runs) == 6


def test_bowl_net_trails_its_centre_by_the_sag_without_stretching_a_thread():
    """bowl_net_positions (launch.sag): the grid centre trails the corners by exactly the sag along the launch
    direction (its paraboloid: -sag at rho = 0, 0 at the corners), no thread starts longer than its rest length
    (a bowl without tension; the mesh is drawn in just enough, so the tautest thread is exactly at rest), the
    in-plane layout keeps its centre and symmetry, sag 0 returns the flat net, and a bowl deeper than the net
    allows is refused."""
    direction = np.array([0.0, 1.0, 0.0])
    net = flat_square_net([0.3, -1.5, 0.2], direction, 8.0, 9, 0.01, 0.01, 6.2e4, 1.58, 1.8, 0.01, 1.0)
    assert np.allclose(bowl_net_positions(net, direction, 0.0), net.positions, rtol=0.0, atol=1e-12)
    for sag in (0.1, 1.0, 2.5):
        x = bowl_net_positions(net, direction, sag)
        corners, centre = [0, 8, 72, 80], 40
        assert np.allclose(x[corners, 1], net.positions[corners, 1], atol=1e-12)
        assert abs((x[centre, 1] - x[corners, 1].mean()) + sag) < 1e-12
        assert np.allclose(x[centre, [0, 2]], net.positions[centre, [0, 2]], atol=1e-12)
        ratio = np.linalg.norm(x[net.threads[:, 0]] - x[net.threads[:, 1]], axis=1) / net.rest_lengths
        assert ratio.max() == pytest.approx(1.0, abs=1e-12)
    # mouth < 1: every thread slack when the bowl alone would not need it
    x = bowl_net_positions(net, direction, 0.1, mouth=0.8)
    assert (np.linalg.norm(x[net.threads[:, 0]] - x[net.threads[:, 1]], axis=1) / net.rest_lengths).max() < 0.81
    with pytest.raises(ValueError, match="too deep"):
        bowl_net_positions(net, direction, 4.0)   # the 1 m bullet tethers need 0.385 sag < 1 m along the launch


def test_sum_reassociated_is_the_exact_sum_to_round_off():
    """multibody.net.sum_reassociated (the thread energies' totals, partial sums in the compiler's order)
    against math.fsum, the correctly rounded sum: within 1e-14 of it for 2451 positive terms spread over
    six decades (a sequential sum's bound is m eps ~ 5e-13; partial sums do better), exact for a short
    list and zero for an empty one."""
    rng = np.random.default_rng(3)
    values = 10.0 ** rng.uniform(-3, 3, 2451)
    assert sum_reassociated(values) == pytest.approx(math.fsum(values), rel=1e-14, abs=0.0)
    assert sum_reassociated(np.array([0.5, 0.25, 2.0])) == 2.75
    assert sum_reassociated(np.zeros(0)) == 0.0
