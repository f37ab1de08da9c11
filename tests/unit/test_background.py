"""The output job's child process (designer.outputs.background): started with its job, or
started first to import the job's modules while the parent works and given the job later."""

import math
import operator

import pytest

from designer.outputs.background import Background


def test_a_job_runs_in_the_child_and_its_value_comes_back():
    assert Background(math.hypot, 3.0, 4.0).result() == 5.0


def test_a_prepared_child_imports_first_and_runs_the_job_it_is_given():
    child = Background(modules=("json", "no_such_module_anywhere"))   # a failed import is the job's to say
    assert child.submit(operator.add, 2, 3).result() == 5


def test_an_error_in_the_job_is_raised_in_the_parent():
    with pytest.raises(ValueError, match="math domain error"):
        Background(math.sqrt, -1.0).result()


def test_a_prepared_child_without_a_job_is_stopped():
    child = Background(modules=("json",))
    child.stop()
    assert not child._process.is_alive()


def test_the_answer_does_not_wait_for_the_child_interpreter_s_shutdown():
    # the job leaves a thread asleep for 20 s, which the interpreter's shutdown would wait for (as
    # unloading the CAD kernel and matplotlib takes about half a second): the parent has its
    # answer and the child is gone long before
    import time

    started = time.perf_counter()
    child = Background(exec, "import threading, time; threading.Thread(target=time.sleep, args=(20.0,)).start()", {})
    assert child.result() is None
    assert time.perf_counter() - started < 10.0
    assert not child._process.is_alive()


def test_the_child_runs_its_exit_functions():
    # what a coverage tool or a profiler registers with atexit still runs: here it writes a file
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        mark = Path(tmp) / "ran"
        code = f"import atexit, pathlib; atexit.register(pathlib.Path({str(mark)!r}).touch)"
        Background(exec, code, {}).result()
        assert mark.exists()
