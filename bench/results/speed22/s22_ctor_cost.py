"""CPU time (s) of Recorder(...) (its RecorderModel structref built) the first and second time in a fresh process,
the capture case's model (sample 0's draws)."""
import sys, time, tomllib
from pathlib import Path
sys.path.insert(0, "/work/wt-speed22/bench")
from bench_safe_velocity_history import sample_overrides
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs
from riskassess.sweep.spec import case_with
from multibody.impact import ImpactSimulation
from multibody.recorder import Recorder
case_path = "/tmp/speed22/envisat_small_segments_modes_high_capture.toml"
store = Path("/work/wt-speed22/bench/results/array_modes/lead_safe_velocity_high_1p0_135s_s45_store")
ov = sample_overrides(store, 0) | {"structures.release": "never", "simulation.end_time": 1.0}
case = validate_case(case_with(tomllib.loads(Path(case_path).read_text()), ov), case_path)
inputs = model_inputs(case, Path(case_path).parent)
sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
for k in range(2):
    t0 = time.process_time()
    Recorder(sim.assembly, sim.system, health=sim.health)
    print(f"Recorder(...) #{k + 1}: {time.process_time() - t0:.3f} s CPU")
