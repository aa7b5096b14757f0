"""tests/multibody/test_closing.py's scene with its loop damped (5 N s/m), at three steps: the balance's largest error
over the winch's work, on the code first on PYTHONPATH (main's or loop23's; the scene is loop23's test file's).

    cd /tmp && PYTHONPATH=TREE python3 scene_cmp.py LABEL
"""
import importlib.util
import sys

import numpy as np

spec = importlib.util.spec_from_file_location("scene", "/work/wt-loop23/tests/multibody/test_closing.py")
scene = importlib.util.module_from_spec(spec)
spec.loader.exec_module(scene)
for step in (1e-4, 5e-5, 2.5e-5):
    _, recorder = scene._run(scene._reeled_net_assembly(step, loop_damping=5.0))
    s = recorder.series
    work = -s["energy_winch_work"][-1]
    error = np.abs(s["energy_total"] - s["energy_total"][0]).max()
    print(sys.argv[1], 5.0, step, f"work {work:.3f} diss {s['energy_dissipated_threads'][-1]:.3f} err/work {error / work:.3e}")
