"""Running an output job in a child process beside the main one (the machine's other core).

The CAD model (the CAD kernel alone takes seconds to load) is built in a child while the main
process computes the trade-off fronts and draws the plots. The child is started with ``spawn``:
a fresh interpreter, so that nothing of the parent's solver state or threads is forked into it.
It may be started before its job is known, importing the job's modules (``modules``) while the
parent searches, and given the job later (``submit``). An error in the child is raised again in
the parent by ``result``; ``stop`` ends the child when the parent stops first (an error, Ctrl-C,
SIGTERM).
"""

from __future__ import annotations

import importlib
import multiprocessing
import signal

from designer import interrupt


def _run(connection, target, args):
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # the parent decides; it stops the child itself
    try:
        connection.send((True, target(*args)))
    except BaseException as exc:  # noqa: BLE001 - every failure goes back to the parent
        try:
            connection.send((False, exc))
        except Exception:  # an exception that cannot be pickled: its text
            connection.send((False, RuntimeError(f"{type(exc).__name__}: {exc}")))
    finally:
        connection.close()


def _serve(jobs, connection, modules):
    """Import ``modules``, then run the job the parent sends (none: it stopped first)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        for name in modules:
            importlib.import_module(name)
    except Exception:  # noqa: BLE001 - the job's own import says what is wrong, in the parent
        pass
    try:
        target, args = jobs.recv()
    except EOFError:
        connection.close()
        return
    _run(connection, target, args)
    # the answer is sent and every file the job wrote is closed: end at once, without the
    # interpreter's clean-up (about half a second with the CAD kernel, which the parent would wait for)
    interrupt.leave_now(0)


class Background:
    """``target(*args)`` in a child process; ``target`` must be importable by name. Without a
    target the child imports ``modules`` at once and waits for ``submit``."""

    def __init__(self, target=None, *args, modules=()):
        context = multiprocessing.get_context("spawn")
        self._parent, child = context.Pipe(duplex=False)
        waiting, self._jobs = context.Pipe(duplex=False)
        self._process = context.Process(target=_serve, args=(waiting, child, tuple(modules)), daemon=True)
        self._process.start()
        child.close()
        waiting.close()
        if target is not None:
            self.submit(target, *args)

    def submit(self, target, *args) -> "Background":
        """Give the child its job, ``target(*args)`` (once)."""
        self._jobs.send((target, args))
        self._jobs.close()
        return self

    def result(self):
        """The child's return value, or its exception raised here."""
        try:
            ok, value = self._parent.recv()
        except EOFError:
            self._process.join()
            raise RuntimeError(f"the background job ended without an answer (exit code {self._process.exitcode})")
        self._process.join()
        if not ok:
            raise value
        return value

    def stop(self) -> None:
        """End the child if it still runs."""
        if self._process.is_alive():
            self._process.terminate()
            self._process.join(5)
        self._jobs.close()
        self._parent.close()
