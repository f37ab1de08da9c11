"""Ctrl-C and SIGTERM: the run stops where it is, and every ``finally`` cleans up.

The handlers remember the signal as well as raising: a solver that catches the exception in its
own callback (IPOPT through casadi reports it as a user stop and returns) would otherwise let the
run go on. ``check()`` after such a call raises it again.
"""

from __future__ import annotations

import signal

_received: int | None = None


class Terminated(BaseException):
    """SIGTERM, raised like KeyboardInterrupt so that cleanup runs as for Ctrl-C."""


def _raise(signum: int):
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated()


def _handler(signum, frame):
    global _received
    _received = signum
    _raise(signum)


def received() -> int | None:
    """The signal received since ``install``, if any."""
    return _received


def check() -> None:
    """Raise the signal received during a call that swallowed it."""
    if _received is not None:
        _raise(_received)


def install():
    """Handle SIGINT and SIGTERM; returns a function that puts the previous handlers back.
    Outside the main thread nothing is installed."""
    global _received
    _received = None
    try:
        previous = {s: signal.signal(s, _handler) for s in (signal.SIGINT, signal.SIGTERM)}
    except ValueError:  # not the main thread
        return lambda: None

    def restore():
        global _received
        for s, h in previous.items():
            signal.signal(s, h)
        _received = None   # the signal belonged to the run that handled it; later library calls go on
    return restore
