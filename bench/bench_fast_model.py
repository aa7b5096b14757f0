"""CPU time of the models integrated by the shared RK4 (multibody/maths/rk4.py): the diagnosis' fast model
(riskassess.diagnosis.plants.dynamics.integrate; a 300 s prediction at 10 Hz of the sample tumbling and
hinged cases, nominal and with the nutation damper at its typical parameters) and perception's
torque-free propagation (30 s, 0.01 s steps).

    python bench/bench_fast_model.py [--repeats 40]

Prints the minimum CPU time (time.process_time) over the repeats and a checksum of the states (equal
checksums: the same numbers). The first call, which may compile, is not timed.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from perception.euler_poinsot import propagate_torque_free  # noqa: E402
from riskassess.diagnosis.plants import dynamics  # noqa: E402
from riskassess.diagnosis.cases import load_diagnosis_case  # noqa: E402
from riskassess.diagnosis.effects import CATALOG  # noqa: E402
from riskassess.diagnosis.effects.base import own_states  # noqa: E402
from riskassess.diagnosis.model import max_step  # noqa: E402
from riskassess.diagnosis.plants.plant import Plant  # noqa: E402


def fast_model_loads() -> dict:
    """Arguments of ``dynamics.integrate`` per load: (law, p, env, x0, times, max_step)."""
    times = np.arange(0.0, 300.0 + 1e-9, 0.1)
    damper = CATALOG["internal_energy_dissipation"]
    loads = {}
    for scenario in ("tumbling_rigid", "hinged_appendage"):
        case = load_diagnosis_case(ROOT / "cases" / f"diagnose_{scenario}.toml")
        plant = Plant.from_case(case)
        loads[f"{scenario} nominal"] = (dynamics.no_load, np.zeros(1), dynamics.environment(plant),
                                        dynamics.initial_state(plant), times, max_step(plant))
        values = np.array([p.typical for p in damper.parameter_specs(case)])
        damped = damper.modify_plant(plant, values)
        loads[f"{scenario} damper"] = (
            damper.law, np.ascontiguousarray(damper.law_parameters(damped, values), float),
            dynamics.environment(damped), dynamics.initial_state(damped, own_states(damper, damped)), times,
            max_step(damped, damper.parameter_free_stiffness_rate(damped)))
    return loads


def cpu_minimum(function, args, repeats: int) -> float:
    """Least CPU time (s) of ``function(*args)`` over ``repeats`` calls, after one untimed call."""
    function(*args)
    best = np.inf
    for _ in range(repeats):
        start = time.process_time()
        function(*args)
        best = min(best, time.process_time() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=40)
    repeats = parser.parse_args().repeats
    for name, args in fast_model_loads().items():
        seconds = cpu_minimum(dynamics.integrate, args, repeats)
        print(f"{name:28s} {seconds * 1e3:7.2f} ms CPU; checksum {dynamics.integrate(*args).sum():.17g}")
    q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
    args = (q0, np.array([0.05, -0.2, 0.12]), np.array([0.4, 0.8, 1.0]), np.linspace(0.0, 30.0, 301), 0.01)
    seconds = cpu_minimum(propagate_torque_free, args, repeats)
    print(f"{'perception torque-free 30 s':28s} {seconds * 1e3:7.2f} ms CPU; checksum "
          f"{sum(part.sum() for part in propagate_torque_free(*args)):.17g}")


if __name__ == "__main__":
    main()
