import sys, numpy as np
sys.path.insert(0, sys.argv[1])
from tests.multibody.test_closing import _run
import tests.multibody.test_closing as tc
import inspect
# the worktree's scene builder with loop damping, imported from the worktree's test file path
spec = __import__("importlib.util").util.spec_from_file_location("sc", "/work/wt-loop23/tests/multibody/test_closing.py")
sc = __import__("importlib.util").util.module_from_spec(spec); spec.loader.exec_module(sc)
for c in (5.0,):
  for step in (1e-4, 5e-5, 2.5e-5):
    sim, rec = _run(sc._reeled_net_assembly(step, loop_damping=c))
    s=rec.series; w=-s["energy_winch_work"][-1]
    err=np.abs(s["energy_total"]-s["energy_total"][0]).max()
    print(sys.argv[1], c, step, "work %.3f diss %.3f err/work %.3e" % (w, s["energy_dissipated_threads"][-1], err/w))
