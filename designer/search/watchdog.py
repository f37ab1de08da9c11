"""A run in a forked child that is killed when it overstays.

nlopt's methods loop inside C where no Python callback runs: COBYLA's linear programs can go on
for good whatever its evaluation and time budgets (nlopt issues #118 and #370), and there
neither a budget nor Ctrl-C can end the run in its own process. In a child, the parent keeps
control: it waits at most its deadline, Ctrl-C and SIGTERM reach it while it waits, and it kills
the child in every case it does not answer.
"""

from __future__ import annotations

import os
import pickle
import select
import signal
import sys
import time
from typing import Callable, TypeVar

T = TypeVar("T")

PR_SET_PDEATHSIG = 1   # Linux prctl: a signal the child gets when its parent dies
# Children that answered and are leaving: reaped at the next run, not waited for (their exit,
# unmapping the parent's copied address space, takes a few milliseconds).
_leaving: list[int] = []


class Lost(Exception):
    """The child gave no answer: it overstayed its deadline (and was killed) or died."""


def can_watch() -> bool:
    """Whether runs can be watched here: fork and poll are POSIX only."""
    return hasattr(os, "fork") and hasattr(select, "poll")


def run_watched(run: Callable[[], T], seconds: float) -> T:
    """``run()`` in a forked child and its result (picklable), or what it raised raised again
    here; ``Lost`` when the child has not answered within ``seconds`` (it is then killed) or died
    first. The child ignores Ctrl-C: the parent's handler raises, and the child is killed."""
    _reap_leaving()
    parent = os.getpid()
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: answer through the pipe, then leave without the parent's clean-up
        try:
            os.close(read)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            _die_with_parent(parent)
            try:
                answer = (True, run())
            except Exception as exc:  # noqa: BLE001 -- given to the parent to raise
                answer = (False, exc)
            try:
                data = pickle.dumps(answer)
            except Exception as exc:  # noqa: BLE001 -- an answer that cannot be pickled, said so
                data = pickle.dumps((False, RuntimeError(f"the run's answer could not be passed on: {exc}")))
            with os.fdopen(write, "wb") as pipe:
                pipe.write(data)
        finally:
            os._exit(0)
    os.close(write)
    data = None
    try:
        data = _read_until(read, seconds)
    finally:
        os.close(read)
        if data:  # it answered and closed the pipe: it is leaving
            _leaving.append(pid)
        else:
            _end(pid)
    if data is None:
        raise Lost(f"no answer within {seconds:g} s; stopped")
    if not data:
        raise Lost("the run ended without an answer")
    ok, value = pickle.loads(data)
    if not ok:
        raise value
    return value


def _read_until(fd: int, seconds: float) -> bytes | None:
    """Everything written to ``fd`` until it is closed, or None at the deadline."""
    deadline = time.monotonic() + seconds
    chunks = []
    poller = select.poll()   # not select.select: it fails on descriptors past 1024
    poller.register(fd, select.POLLIN)
    while True:
        left = deadline - time.monotonic()
        if left <= 0 or not poller.poll(left * 1000):
            return None
        chunk = os.read(fd, 65536)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def _reap_leaving() -> None:
    for pid in list(_leaving):
        try:
            done, _ = os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            done = pid
        if done:
            _leaving.remove(pid)


def _end(pid: int) -> None:
    """Kill the child if it still runs, and reap it."""
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if done == 0:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    except ChildProcessError:
        pass


def _die_with_parent(parent: int) -> None:
    """On Linux, the child is killed when its parent dies, so that a parent killed outright (no
    ``finally`` runs) leaves no run behind; a parent already gone ends the child here."""
    if sys.platform == "linux":
        try:
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:
        os._exit(0)
