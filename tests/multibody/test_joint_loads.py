"""The recorder's joint loads, computed in its compiled sample (multibody.recorder_kernel.connector_load_into), against
Exudyn's own connector outputs (``GetObjectOutput`` of ``ForceLocal`` and ``TorqueLocal``, which the recorder called
eight times a sample before: 7.7 us of every step of the reference case, measured in the run).

Case: ``cases/envisat_small.toml`` to 0.12 s: the net has struck the ASAR and the array, every joint carries load and
the array hinge has turned. The expected values are Exudyn's, read at the recorded end state; the loads are the
parent's on the child, i.e. Exudyn's outputs with the sign reversed. Tolerances: the penalty forces are
stiffness (up to 1e9 N/m) times a joint gap of a few nanometres, the difference of two positions some 40 m from the
origin, so both computations carry the round-off of those positions times the stiffness: eps x 40 m x 1e9 N/m = 9e-6
N (measured on the reference case: 1e-6-1e-5 N); the test allows 100 times that. Moments: 1e-7 of the largest
(measured 1e-11-1e-8; their rotations are not differences of large numbers).
"""
from pathlib import Path

import exudyn as exu
import numpy as np
import pytest

from multibody.impact import ImpactSimulation
from riskassess.cases.impact import load_case
from riskassess.models.impact import model_inputs

CASES = Path(__file__).resolve().parents[2] / "cases"


@pytest.fixture(scope="module")
def small_run():
    case = load_case(CASES / "envisat_small.toml")
    case = case.model_copy(update={"simulation": case.simulation.model_copy(update={"end_time": 0.12})})
    inputs = model_inputs(case, CASES)
    simulation = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    return simulation, simulation.run()


def test_joint_loads_are_exudyns_connector_outputs(small_run):
    simulation, recorder = small_run
    mbs, joints = simulation.system.mbs, simulation.system.joint_objects
    assert recorder.series["time"][-1] == pytest.approx(0.12)
    force = np.array([mbs.GetObjectOutput(j, exu.OutputVariableType.ForceLocal) for j in joints])
    moment = np.array([mbs.GetObjectOutput(j, exu.OutputVariableType.TorqueLocal) for j in joints])
    recorded_force, recorded_moment = recorder.series["joint_force_joint"][-1], recorder.series["joint_moment_joint"][-1]
    assert np.abs(moment).max() > 1.0 and np.abs(force).max() > 1.0   # loaded joints (N m, N)
    distance = np.abs(recorder.series["body_com_lvlh"][-1]).max()
    stiffness = max(np.abs(np.diag(mbs.GetObjectParameter(j, "stiffness"))).max() for j in joints)
    np.testing.assert_allclose(recorded_force, -force, rtol=0, atol=100 * np.finfo(float).eps * distance * stiffness)
    np.testing.assert_allclose(recorded_moment, -moment, rtol=0, atol=1e-7 * np.abs(moment).max())


def test_a_released_joint_reads_zero(small_run):
    """A joint switched off by the release monitor records no load (as before: Exudyn's connector keeps computing its
    spring from the separating bodies, which the recorder must not report)."""
    _, recorder = small_run
    active, kept = recorder._joint_active_float, recorder._joint_active_float.copy()
    try:
        active[0] = 0.0
        recorder.sample(0.12)
        assert np.all(recorder._body_out.joint_force[0] == 0.0) and np.all(recorder._body_out.joint_moment[0] == 0.0)
        assert np.abs(recorder._body_out.joint_moment[1:]).max() > 0.0
    finally:
        active[:] = kept
