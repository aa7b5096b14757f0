"""multibody.solver_output: the solver's routine notices go to the log only, anything else also to stderr."""
import os
import sys

from multibody.jit_cache import compiled_on_disk
from multibody.solver_output import solver_chatter_captured, solver_log

ROUTINE = ("WARNING: VelocityVerlet: still under development\n"
           "WARNING: ExplicitSolver detected large amount (137523) of memory allocations, which seem to occur in "
           "every time step; this may be due to user functions; solver may be slow\n")


def test_routine_notices_stay_in_the_log_others_reach_stderr(tmp_path, capfd):
    log = tmp_path / "solver.log"
    with solver_log(log):
        with solver_chatter_captured():
            os.write(1, ROUTINE.encode())                 # the C++ core writes to file descriptor 1
            print("ERROR: a real problem")                # pybind's print goes through sys.stdout
        with solver_chatter_captured():                   # a second solve appends
            os.write(1, b"WARNING: VelocityVerlet: still under development\n")
    out, err = capfd.readouterr()
    assert out == ""                                      # standard output stays the tool's own
    assert err.strip() == "ERROR: a real problem"
    text = log.read_text()
    assert ROUTINE in text and "ERROR: a real problem" in text
    assert text.count("still under development") == 2


def test_without_a_log_the_output_goes_to_stderr(capfd):
    with solver_chatter_captured():
        os.write(1, b"WARNING: VelocityVerlet: still under development\n")
    out, err = capfd.readouterr()
    assert out == "" and "still under development" in err


def test_compiled_on_disk_tells_a_cold_cache_from_a_warm_one(tmp_path, monkeypatch):
    (tmp_path / "tiny_kernel.py").write_text(
        "from numba import njit\n\n@njit(cache=True)\ndef twice(x):\n    return 2.0 * x\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import tiny_kernel

    try:
        assert not compiled_on_disk(tiny_kernel.twice)    # nothing compiled yet
        assert tiny_kernel.twice(1.5) == 3.0
        assert compiled_on_disk(tiny_kernel.twice)        # in __pycache__ now, for this source and CPU
        source = tmp_path / "tiny_kernel.py"
        source.write_text(source.read_text() + "\n# changed\n")
        sys.modules.pop("tiny_kernel")
        import tiny_kernel as changed                     # a new process would import the new source

        assert not compiled_on_disk(changed.twice)        # its stamp differs: numba would recompile
    finally:
        sys.modules.pop("tiny_kernel", None)
    assert not compiled_on_disk(lambda x: x)              # not a numba function
