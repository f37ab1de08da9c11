"""Ctrl-C and SIGTERM: the run stops where it is, and every ``finally`` cleans up.

The handlers remember the signal as well as raising: a solver that catches the exception in its
own callback (IPOPT through casadi reports it as a user stop and returns) would otherwise let the
run go on. ``check()`` after such a call raises it again. Where Python itself ignores the
exception (a weakref callback or ``__del__`` that it interrupted), the signal is sent again.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import signal
import sys
import threading

_received: int | None = None
# A signal whose exception Python ignores (raised inside a weakref callback or a __del__, such as
# the import system's module-lock callbacks) is sent again this much later, where it can stop the run.
REDELIVERY_DELAY = 0.05


class Terminated(BaseException):
    """SIGTERM, raised like KeyboardInterrupt so that cleanup runs as for Ctrl-C."""


def _raise(signum: int):
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated()


# Inside our unraisable hook a signal is only noted (``_held``), not raised: raised there, Python
# would print "Exception ignored in sys.unraisablehook" and its traceback; the hook sends it again.
_in_hook = False
_held = False


# Inside ``held()`` a signal is only noted, and raised when the block ends.
_holding = False
# What was put in place whole while a signal waited (``wrote``): the run's one line says so.
_written: list = []


def _handler(signum, frame):
    global _received, _held
    _received = signum
    if _in_hook:
        _held = True
        return
    if _holding:
        return
    _raise(signum)


def wrote(path) -> None:
    """Note that ``path`` was put in place whole in a ``held`` block while a signal waited."""
    if _received is not None:
        _written.append(str(path))


def written() -> list:
    """The outputs put in place whole while the signal that stops the run waited."""
    return list(_written)


@contextlib.contextmanager
def held():
    """A step that must not be cut in half once begun (moving a run's outputs into place and
    removing the previous run's, or removing a scratch folder): a signal received in the block
    is raised when it ends."""
    global _holding
    before = _holding
    _holding = True
    try:
        yield
    finally:
        _holding = before
    if not before:
        check()


def received() -> int | None:
    """The signal received since ``install``, if any."""
    return _received


def check() -> None:
    """Raise the signal received during a call that swallowed it."""
    if _received is not None:
        _raise(_received)


def leave_now(code: int, exit_functions: bool = True) -> None:
    """End the process with ``code`` at once, its files written and closed: after the exit
    functions (atexit: a coverage tool's), unless ``exit_functions`` is False, and the standard
    streams flushed, but without the interpreter's clean-up (with casadi, the CAD kernel and
    matplotlib loaded, unloading them takes 0.2-0.5 s)."""
    if exit_functions:
        atexit._run_exitfuncs()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


def reinstall() -> None:
    """Put Python's SIGINT and SIGTERM handlers back at the C level where a library replaced them
    without Python knowing: gmsh's initialisation sets SIGTERM to its default action, so that a
    SIGTERM would end the process at once and leave its scratch files. Only in the main thread; a
    handler that Python did not install is left alone."""
    if threading.current_thread() is not threading.main_thread():
        return
    for s in (signal.SIGINT, signal.SIGTERM):
        handler = signal.getsignal(s)
        if handler is not None:
            signal.signal(s, handler)


def install():
    """Handle SIGINT and SIGTERM; returns a function that puts the previous handlers back.
    Outside the main thread nothing is installed."""
    global _received
    _received = None
    _written.clear()
    try:
        previous = {s: signal.signal(s, _handler) for s in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        return lambda: None
    hook = sys.unraisablehook

    def unraisable(args):
        global _in_hook, _held
        _in_hook, _held = True, False
        try:
            ours = isinstance(args.exc_value, (KeyboardInterrupt, Terminated)) and _received is not None
            if not ours:  # not printed when ours: Python would say "Exception ignored in ..." and go on
                hook(args)
            if ours or _held:
                threading.Timer(REDELIVERY_DELAY, os.kill, (os.getpid(), _received)).start()
        finally:
            _in_hook = False

    sys.unraisablehook = unraisable

    def restore():
        global _received
        for s, h in previous.items():
            signal.signal(s, h)
        sys.unraisablehook = hook
        _received = None   # the signal belonged to the run that handled it; later library calls go on
    return restore
