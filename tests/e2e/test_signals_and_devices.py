"""Signals and device outputs (docs/spec.md, exit codes): a stopped run exits 128 + the signal
with one line and leaves nothing behind; a device is written to, never replaced by a file."""

import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from designer.cli import main
from shared_inputs import wait_for_handlers

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("signum, code, line", [(signal.SIGTERM, 143, "fpdesign: terminated"),
                                                (signal.SIGINT, 130, "fpdesign: interrupted")])
@pytest.mark.parametrize("delay", [0.5, 3.0])
def test_a_signal_stops_optimize_and_leaves_nothing(tmp_path, signum, code, line, delay):
    # 0.5 s after the command's handlers are in place: during the imports or the search; 3 s:
    # the fronts, the plots or the CAD kernel in its child process (on this machine)
    proc = subprocess.Popen([sys.executable, "-m", "designer.cli", "optimize", str(EXAMPLES / "gripper-finger.yaml"),
                             "-o", str(tmp_path / "out")], cwd=tmp_path, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    wait_for_handlers(proc)
    time.sleep(delay)
    if proc.poll() is not None:
        pytest.skip("the run finished before the signal")
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == code, err
    lines = [x for x in err.splitlines() if "CasADi" not in x]   # IPOPT's own note of the stop
    assert lines == [line]
    assert sorted(p.name for p in tmp_path.iterdir()) == []      # no output folder, no hidden scratch


def test_a_device_is_written_not_replaced(tmp_path, capsys):
    record = tmp_path / "out" / "design.json"
    assert main(["optimize", str(EXAMPLES / "probe.yaml"), "-o", str(record.parent), "--no-cad", "--no-plots",
                 "--quiet"]) == 0
    assert main(["plan", str(record), "-o", os.devnull]) == 0
    assert stat.S_ISCHR(os.stat(os.devnull).st_mode)
    if os.path.exists("/dev/full"):
        capsys.readouterr()
        assert main(["plan", str(record), "-o", "/dev/full"]) == 2
        assert capsys.readouterr().err.strip() == "fpdesign: error: cannot write /dev/full: No space left on device"
        assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full, a device that is always full")
def test_a_full_standard_output_is_named_and_the_folder_is_whole(tmp_path):
    # the summary printed to a full disk (here /dev/full) after the files are written: exit 2 with
    # one line naming standard output, and the folder as design.json lists it
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "designer.cli", "evaluate", str(EXAMPLES / "prototype-b.yaml"),
                               "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"], cwd=tmp_path, stdout=full,
                              stderr=subprocess.PIPE, text=True, timeout=300)
    assert proc.returncode == 2
    assert proc.stderr.strip() == "fpdesign: error: cannot write standard output: No space left on device"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["design.json", "report.md"]


def test_an_output_below_a_file_is_bad_input(tmp_path, capsys):
    (tmp_path / "afile").write_text("x")
    assert main(["optimize", str(EXAMPLES / "probe.yaml"), "-o", str(tmp_path / "afile" / "out"), "--no-cad",
                 "--no-plots", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == f"fpdesign: error: cannot write {tmp_path / 'afile'}: it is a file, not a folder"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


def test_a_reused_output_folder_holds_one_runs_outputs(tmp_path):
    out = tmp_path / "out"
    assert main(["optimize", str(EXAMPLES / "probe.yaml"), "-o", str(out), "--no-cad", "--quiet"]) == 0
    plots = [p for p in out.iterdir() if p.suffix in (".png", ".svg")]
    assert plots
    (out / "my-notes.txt").write_text("kept")
    assert main(["optimize", str(EXAMPLES / "probe.yaml"), "-o", str(out), "--no-cad", "--no-plots", "--quiet"]) == 0
    # the previous run's plots are gone; the user's own file stays
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "my-notes.txt", "report.md"]


@pytest.mark.slow
@pytest.mark.parametrize("delay", [0.5, 2.0, 3.0])
def test_a_signal_stops_verify_and_leaves_no_scratch(tmp_path, delay):
    # 0.5 s: building the CAD solid in its child process; 2 s and 3 s: meshing or solving, after
    # gmsh's start (this machine; the whole coarse check of this design takes about 5 s)
    record = tmp_path / "in" / "design.json"
    assert main(["optimize", str(EXAMPLES / "probe.yaml"), "-o", str(record.parent), "--no-cad", "--no-plots",
                 "--quiet"]) == 0
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "TMPDIR": str(scratch)}
    proc = subprocess.Popen([sys.executable, "-m", "designer.cli", "verify", str(record), "-o", str(tmp_path / "v"),
                             "--mesh", "coarse"], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, env=env)
    wait_for_handlers(proc)
    time.sleep(delay)
    if proc.poll() is not None:
        pytest.skip("the check finished before the signal")
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert [x for x in err.splitlines() if "CasADi" not in x] == ["fpdesign: terminated"]
    assert not (tmp_path / "v").exists()
    assert list(scratch.iterdir()) == []      # no fpdesign-verify-* folder left


@pytest.mark.parametrize("again", [False, True])
def test_a_signal_raised_where_python_ignores_exceptions_is_delivered_again(capsys, monkeypatch, again):
    """SIGTERM arriving inside a weakref callback (the import system's module locks have them):
    Python ignores the exception raised there and would print "Exception ignored in"; the run
    must still stop, with nothing printed. ``again``: a second signal (Ctrl-C pressed twice)
    arrives while the hook that sends the first one again is starting its timer; raised there,
    Python would print "Exception ignored in sys.unraisablehook" and a traceback."""
    import gc
    import threading
    import weakref

    from designer import interrupt

    class Timer(threading.Timer):
        def start(self):
            os.kill(os.getpid(), signal.SIGTERM)   # the second signal, inside the hook
            time.sleep(0.01)
            super().start()

    if again:
        monkeypatch.setattr(interrupt.threading, "Timer", Timer)

    class Thing:
        pass

    restore = interrupt.install()
    try:
        thing = Thing()
        ref = weakref.ref(thing, lambda _: os.kill(os.getpid(), signal.SIGTERM) or time.sleep(0.01))
        with pytest.raises(interrupt.Terminated):
            del thing
            gc.collect()
            assert ref() is None
            time.sleep(2.0)  # the signal delivered again stops this
    finally:
        restore()
    assert "Exception ignored" not in capsys.readouterr().err


def _children(pid: int) -> list[int]:
    """The live (not zombie) processes whose parent is ``pid`` (Linux /proc)."""
    out = []
    for stat_file in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat_file.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            out.append(int(stat_file.parent.name))
    return out


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc")
def test_the_cad_process_ends_when_a_killed_optimize_leaves_it_waiting(tmp_path):
    # optimize's CAD process draws the design's plots, then waits for the trade-off fronts the
    # other process hands over. SIGKILL gives that process no chance to stop it: the CAD process
    # must notice its parent is gone and end, not wait for ever. The fronts are made slow here
    # so that it is waiting (its four plots claimed) when the parent is killed.
    code = ("import time; import designer.result.pipeline as p; "
            "p.tradeoff_fronts = lambda *a, **k: time.sleep(120); "
            "from designer.cli import main; "
            f"main(['optimize', {str(EXAMPLES / 'gripper-finger.yaml')!r}, '-o', {str(tmp_path / 'out')!r}, '--quiet'])")
    proc = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        start = time.monotonic()
        while time.monotonic() - start < 120:
            claims = [p for c in tmp_path.glob(".out.*/.claims") for p in c.iterdir()]
            if len(claims) >= 4:
                break
            time.sleep(0.1)
        else:
            pytest.fail("the CAD process did not draw the design's plots")
        children = _children(proc.pid)
        assert children
        proc.kill()
        proc.wait()
        start = time.monotonic()
        while time.monotonic() - start < 10 and any(_alive(c) for c in children):
            time.sleep(0.1)
        assert not any(_alive(c) for c in children)
    finally:
        proc.kill()


def test_the_command_leaves_once_it_is_done_without_the_interpreter_s_shutdown(tmp_path):
    # a thread asleep for 20 s, which the interpreter's shutdown would wait for (as unloading
    # casadi, matplotlib and the rest takes 0.2-0.3 s after an optimize), is not waited for; the
    # exit functions (a profiler's, a coverage tool's) run, the output is flushed, the code kept
    mark = tmp_path / "ran"
    code = ("import atexit, pathlib, sys, threading, time; "
            "threading.Thread(target=time.sleep, args=(20.0,)).start(); "
            f"atexit.register(pathlib.Path({str(mark)!r}).touch); "
            "sys.argv = ['fpdesign', '--version']; from designer.cli import run; run()")
    started = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert time.perf_counter() - started < 10.0
    assert done.returncode == 0 and done.stdout.startswith("fpdesign ") and mark.exists()
    bad = subprocess.run([sys.executable, "-c", code.replace("'--version'", "'optimize', 'no-such.yaml'")],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "no-such.yaml" in bad.stderr


def test_under_a_profiler_the_command_leaves_the_usual_way_so_that_it_reports():
    done = subprocess.run([sys.executable, "-m", "cProfile", "-m", "designer.cli", "--version"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.startswith("fpdesign ") and "function calls" in done.stdout


@pytest.mark.parametrize("reinstall", [False, True])
def test_gmsh_s_start_drops_the_sigterm_handler_and_reinstall_puts_it_back(reinstall):
    # gmsh.initialize sets SIGTERM to its default action at the C level (Python still reports its
    # own handler): a SIGTERM then ends the process at once, without cleaning up (-15). The mesher
    # puts the handlers back after it (``interrupt.reinstall``); the signal then stops the run.
    code = ("import os, signal, sys, time, gmsh\n"
            "from designer import interrupt\n"
            "interrupt.install()\n"
            "gmsh.initialize(interruptible=False)\n"
            f"if {reinstall}: interrupt.reinstall()\n"
            "try:\n"
            "    os.kill(os.getpid(), signal.SIGTERM)\n"
            "    time.sleep(5)\n"
            "except interrupt.Terminated:\n"
            "    sys.exit(3)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == (3 if reinstall else -signal.SIGTERM), done.stderr
