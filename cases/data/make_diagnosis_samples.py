"""Write the sample measured data of the diagnosis cases (run from the repository root):

    python cases/data/make_diagnosis_samples.py

* ``cases/data/tumbling_rigid_nutation.csv``: cases/diagnose_tumbling_rigid.toml with an internal
  nutation damper (``internal_energy_dissipation``: J_d = 12 kg m^2, T_d = 40 s);
* ``cases/data/hinged_appendage_friction.csv``: cases/diagnose_hinged_appendage.toml with hinge
  Coulomb friction (``hinge_coulomb_friction``: 1.2 N m);
* ``cases/data/towing_viscoelastic.csv``: cases/diagnose_towing.toml with a viscoelastic main tether
  (``tether_viscoelasticity``: k_m = 6000 N/m, tau_m = 30 s), from the towing model in Exudyn
  (riskassess.diagnosis.towing_exudyn, 4 ms steps);

each 300 s at 10 Hz from the Exudyn model (riskassess.diagnosis.exudyn_model), with white Gaussian noise at the
levels of ``riskassess.diagnosis.synthetic.NOISE`` (seed 2024 in turn for the first two, 2025 for the towing
sample, so that ``python cases/data/make_diagnosis_samples.py towing_viscoelastic.csv`` remakes it
alone). Try them with
``riskassess diagnose cases/diagnose_tumbling_rigid.toml --measured cases/data/tumbling_rigid_nutation.csv``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from riskassess.products.measured import write_measured
from riskassess.diagnosis.synthetic import noisy, sample_times, simulate_effect
from riskassess.cases.diagnosis import load_diagnosis_case

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = (("diagnose_tumbling_rigid.toml", "tumbling_rigid_nutation.csv", "internal_energy_dissipation",
            {"damper_inertia": 12.0, "time_constant": 40.0}),
           ("diagnose_hinged_appendage.toml", "hinged_appendage_friction.csv", "hinge_coulomb_friction",
            {"friction_torque": 1.2}),
           ("diagnose_towing.toml", "towing_viscoelastic.csv", "tether_viscoelasticity",
            {"maxwell_stiffness": 6000.0, "relaxation_time": 30.0}))


#: Samples with their own noise stream (the others share seed 2024, in the order above).
OWN_SEED = {"towing_viscoelastic.csv": np.random.default_rng(2025)}


def main(only=None) -> None:
    """Write every sample, or those whose file name is in ``only``.

    Parameters
    ----------
    only : sequence of str or None
        CSV file names of :data:`SAMPLES` to remake (e.g. ``["towing_viscoelastic.csv"]``); all when
        empty or None. Each file holds 300 s at 10 Hz (time in s, channels in SI) under ``cases/data``.
    """
    rng = np.random.default_rng(2024)
    times = sample_times(300.0, 10.0)
    for case_name, data_name, effect, values in SAMPLES:
        if only and data_name not in only:
            continue
        case = load_diagnosis_case(ROOT / "cases" / case_name)
        data, _ = noisy(simulate_effect(case, times, effect, values), OWN_SEED.get(data_name, rng))
        write_measured(ROOT / "cases" / "data" / data_name, times, data)
        print(f"cases/data/{data_name}: {case_name} + {effect} {values}")


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
