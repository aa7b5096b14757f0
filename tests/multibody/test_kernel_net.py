"""The net integrated by the compiled kernel (multibody.kernel_net) against the reference path in which
Exudyn integrates every net node: same case, same forces, same Verlet step, so the same run.

Case: ``cases/envisat_small.toml`` (15 x 15 net onto the Envisat mock-up, orbit on), first 0.3 s: the
ASAR impact, the first bullet strikes and the solar-array swing, with several hundred node contacts
sub-cycled. Both paths evaluate the same kernel at the same states; they differ in who takes the net's
Verlet update (f / m here, a sparse LU solve on the diagonal mass in Exudyn) and in the order of the
floating-point operations, i.e. by round-off (1e-16 relative), which the node impacts amplify (an
arrival a few ulp earlier moves an impulse between two 1 ms output samples). Measured differences
after 0.3 s, relative to each series' largest magnitude: body velocities 3.5e-6, angular velocities 3.1e-5,
joint moments 2.2e-5 and forces 3.6e-5, 1 ms contact forces 6e-6, energy total 1.3e-8, linear momentum
1.4e-15; net positions 1.0e-6 m, velocities 3.2e-5. The tolerances below are 25-75 times these; an error in
the integration itself (a force applied half a step late, the velocity at the wrong instant) changes
these figures at first order in the step, by 1e-2 or more.
"""
import dataclasses
from pathlib import Path

import numpy as np
import pytest
from numba.core.runtime import _nrt_python, rtsys

from multibody.impact import ImpactSimulation
from multibody.kernel import N_CONTACTS
from multibody.kernel_net import kernel_net_step
from riskassess.models.impact import model_inputs
from riskassess.cases.impact import load_case

CASES = Path(__file__).resolve().parents[2] / "cases"

#: series -> allowed difference relative to the series' largest magnitude (see the module doc)
TOLERANCES = {
    "body_velocity_lvlh": 1e-4,
    "body_omega_body": 1e-3,
    "joint_moment_joint": 1e-3,
    "joint_force_joint": 1e-3,
    "contact_force_lvlh": 1e-3,
    "energy_total": 1e-6,
    "momentum_linear_lvlh": 1e-12,
}


@pytest.fixture(scope="module")
def both_paths():
    case = load_case(CASES / "envisat_small.toml")
    runs = {}
    for path in ("exudyn", "kernel"):
        inputs = model_inputs(case, CASES)
        assembly = inputs.assembly
        assembly.solver = dataclasses.replace(assembly.solver, end_time=0.3, net_integration=path)
        simulation = ImpactSimulation(assembly, inputs.rest_attitudes, inputs.rest_coms)
        runs[path] = (simulation, simulation.run())
    return runs


def test_the_kernel_path_holds_the_net_and_exudyn_does_not(both_paths):
    reference, fast = both_paths["exudyn"][0], both_paths["kernel"][0]
    n = reference.assembly.net.n_nodes
    assert reference.system.kernel_net is None and reference.system.net_node is not None
    assert fast.system.kernel_net is not None and fast.system.net_node is None
    assert fast.system.mbs.systemData.ODE2Size() == reference.system.mbs.systemData.ODE2Size() - 3 * n


@pytest.mark.parametrize("key", sorted(TOLERANCES))
def test_both_paths_give_the_same_run(both_paths, key):
    reference, fast = both_paths["exudyn"][1].series, both_paths["kernel"][1].series
    np.testing.assert_array_equal(reference["time"], fast["time"])
    scale = np.abs(reference[key]).max()
    assert np.abs(fast[key] - reference[key]).max() <= TOLERANCES[key] * scale


def test_both_paths_record_the_same_net(both_paths):
    reference, fast = both_paths["exudyn"][1].net, both_paths["kernel"][1].net
    np.testing.assert_array_equal(reference["time"], fast["time"])
    # positions within 25 um over a 30 m net that moved 6 m (round-off amplified as above)
    assert np.abs(fast["positions_lvlh"] - reference["positions_lvlh"]).max() < 2.5e-5
    assert np.abs(fast["velocities_lvlh"] - reference["velocities_lvlh"]).max() < 1e-3 * np.abs(
        reference["velocities_lvlh"]).max()


def test_the_finite_state_check_sees_the_kernels_net(both_paths):
    """Exudyn no longer holds the net on the kernel path: a NaN in the kernel's node velocities must
    still fail the health check (multibody.health, the recorder's check at every sample and 1 ms)."""
    from multibody.health import HealthWatch

    system = both_paths["kernel"][0].system
    watch = HealthWatch(cause="test")
    assert watch.state(0.3, *system.state_arrays())
    saved = system.kernel_net.qt[7]
    system.kernel_net.qt[7] = np.nan
    try:
        assert not watch.state(0.3, *system.state_arrays())
        assert "not finite" in str(watch.failure)
    finally:
        system.kernel_net.qt[7] = saved


def test_a_sample_stores_nothing_from_a_lost_net_state(both_paths):
    """The recorder's compiled sample (multibody.recorder_kernel.sample_row) tests the kernel's net state as it
    sums it: a NaN there fails the health check, with the entry named by the full check, and no row is stored;
    the same sample with the state restored stores one."""
    from multibody.health import HealthWatch

    simulation, recorder = both_paths["kernel"]
    node_velocities, kept_watch, rows = simulation.system.kernel_net.qt, recorder.health, recorder._n_rows
    saved = node_velocities[7]
    recorder.health = watch = HealthWatch(cause="test")
    node_velocities[7] = np.nan
    try:
        recorder.sample(0.3)
        assert not watch.ok and "state is not finite" in str(watch.failure) and recorder._n_rows == rows
        node_velocities[7] = saved
        recorder.health = HealthWatch(cause="test")
        recorder.sample(0.3)
        assert recorder.health.ok and recorder._n_rows == rows + 1
    finally:
        node_velocities[7] = saved
        recorder.health, recorder._n_rows = kept_watch, rows


def test_kernel_steps_keep_numbas_reference_counts_balanced():
    """The step's kernels that skip numba's reference counting (multibody.jit_cache.NO_REFCOUNTS: the force pass,
    the contact pass, the threads, the box flags, the bodies' states) must neither keep an array alive nor let one
    be freed that the structref still holds: over 200 more steps of a short kernel-path run (envisat_small, 0.3 s,
    then the bodies frozen, so the net keeps striking them and the contact pass and its sub-cycle run), numba's
    runtime frees exactly as many blocks as it allocates (the sub-cycle's work arrays: none kept, and none of the
    structref's arrays freed, which would count a free without an allocation), and the state stays finite. A count
    taken without being released (a leak of a count, not of memory) is not seen by this test."""
    case = load_case(CASES / "envisat_small.toml")
    inputs = model_inputs(case, CASES)
    inputs.assembly.solver = dataclasses.replace(inputs.assembly.solver, end_time=0.3, net_integration="kernel")
    simulation = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    simulation.run()
    kernel_net = simulation.system.kernel_net
    data = simulation.system.mbs.systemData
    q, qt, qtt = (kernel_net._bodies(np.array(v)) for v in (data.GetODE2Coordinates(), data.GetODE2Coordinates_t(),
                                                             data.GetODE2Coordinates_tt()))
    q_next, force = np.zeros_like(q), np.zeros_like(q)
    kernel_net_step(kernel_net.model, q, qt, qtt, 0.3, q_next, force)   # compiled before the count
    counting = _nrt_python.memsys_stats_enabled()
    _nrt_python.memsys_enable_stats()
    try:
        before = rtsys.get_allocation_stats()
        for k in range(200):
            kernel_net_step(kernel_net.model, q, qt, qtt, 0.3 + 1e-4 * k, q_next, force)
        after = rtsys.get_allocation_stats()
    finally:
        if not counting:
            _nrt_python.memsys_disable_stats()
    assert after.alloc - before.alloc == after.free - before.free
    assert after.mi_alloc - before.mi_alloc == after.mi_free - before.mi_free
    assert np.isfinite(kernel_net.q).all() and np.isfinite(force).all()
    assert kernel_net.kernel.buffers.scalars[N_CONTACTS] > 0   # the contact pass had work
