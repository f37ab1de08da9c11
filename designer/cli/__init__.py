"""The ``fpdesign`` command line: a thin layer that parses, calls the library, writes files.

Each command group lives in ``designer.cli.<group>`` and offers ``register(subparsers)``;
the heavy libraries (casadi, cadquery, matplotlib, gmsh) are imported only inside the
commands that use them, so that every command starts fast.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys

from designer import __version__
from designer.errors import FpdError

_COMMAND_GROUPS = (
    "designer.cli.design",       # optimize, evaluate, simulate, materials
    "designer.cli.cad",          # export
    "designer.cli.plot",         # plot, bench
    "designer.cli.calibration",  # plan, calibrate, measure
    "designer.cli.verify",       # verify
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fpdesign",
        description="Design force-and-position cantilever sensors with strain-gauge bridges.",
    )
    parser.add_argument("--version", action="version", version=f"fpdesign {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in _COMMAND_GROUPS:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:
                continue  # a command group not built yet
            raise
        module.register(sub)
    parser.commands = sub.choices
    return parser


def parse(parser: argparse.ArgumentParser, argv: list[str] | None) -> argparse.Namespace:
    """``parser.parse_args``, but an argument no command takes is reported by that command's own
    parser, with its usage (``fpdesign calibrate: error: unrecognized arguments: x.csv``), not by the
    top level's ``fpdesign COMMAND ...``, which would not show what the command does take."""
    args, extra = parser.parse_known_args(argv)
    if extra:
        parser.commands[args.command].error(f"unrecognized arguments: {' '.join(extra)}")
    return args


def main(argv: list[str] | None = None) -> int:
    from designer import interrupt

    restore = interrupt.install()
    stdout = sys.stdout
    sys.stdout = _StandardOutput(stdout)
    try:
        try:
            args = parse(build_parser(), argv)
        except SystemExit as exc:  # argparse exits 2 on bad usage, 0 on --help
            return int(exc.code or 0)
        code = int(args.func(args) or 0)
        sys.stdout.flush()   # a closed pipe shows here, inside the handlers, not at exit
        return code
    except FpdError as exc:
        print(f"fpdesign: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except BrokenPipeError:
        return _pipe_closed()
    except SystemExit:
        # rich meets a closed pipe by pointing standard output at the null device and raising
        # SystemExit(1), which would read as "infeasible"
        if _stdout_is_null():
            return PIPE_CLOSED
        raise
    except OSError as exc:  # reading goes through errors.read_text: this is a file that cannot be written
        if interrupt.received() is not None:
            return _stopped(interrupt.received())
        where = exc.filename if exc.filename is not None else "an output"
        print(f"fpdesign: error: cannot write {where}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except Exception:
        # a C extension may turn the signal into its own error (importing the CAD kernel gives
        # ImportError "initialization failed"): the signal is the cause
        if interrupt.received() is None:
            raise
        return _stopped(interrupt.received())
    except KeyboardInterrupt:
        return _stopped(signal.SIGINT)
    except interrupt.Terminated:
        return _stopped(signal.SIGTERM)
    finally:
        sys.stdout = stdout
        restore()


class _StandardOutput:
    """``sys.stdout`` whose write errors name it: a summary redirected to a full disk reads
    "cannot write standard output: No space left on device" rather than an output of no name
    (the command's files are written by then). A closed pipe's error passes as it is."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        try:
            return self._stream.write(text)
        except OSError as exc:
            raise _named(exc)

    def flush(self):
        try:
            return self._stream.flush()
        except OSError as exc:
            raise _named(exc)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _named(exc: OSError) -> OSError:
    if exc.filename is None and not isinstance(exc, BrokenPipeError):
        exc.filename = "standard output"
    return exc


def run() -> None:
    """The ``fpdesign`` command: ``main`` with the process's exit code. A finished command leaves
    at once, after the exit functions (atexit) but without the interpreter's clean-up: its files
    are written and closed and its child process ended by then, and unloading the numerical
    libraries takes 0.2-0.3 s after an ``optimize``. Under a profiler or a tracer it leaves the
    usual way, so that they can report. A run stopped by Ctrl-C or SIGTERM, already cleaned up,
    leaves at once in any case: a solver that caught the signal too may have left it pending,
    and the clean-up would raise it again."""
    from designer import interrupt

    code = main()
    stopped = code in STOP_CODES
    if not stopped and (sys.getprofile() is not None or sys.gettrace() is not None):
        sys.exit(code)
    interrupt.leave_now(code, exit_functions=not stopped)


STOP_CODES = (128 + signal.SIGINT, 128 + signal.SIGTERM)


#: The exit code of a command whose standard output was closed before it finished printing
#: (``fpdesign optimize spec.yaml | head``): 128 + SIGPIPE, as a program stopped by the signal.
PIPE_CLOSED = 141


def _pipe_closed() -> int:
    """A reader that stopped reading (``| head``) is no error: no message, no traceback, and
    nothing more is printed (standard output goes to the null device, so that Python's own
    flush at exit does not fail again). Files are written before the summary is printed."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):   # stdout replaced by an object without a file descriptor
        pass
    return PIPE_CLOSED


def _stdout_is_null() -> bool:
    import os

    try:
        return os.path.samestat(os.fstat(sys.stdout.fileno()), os.stat(os.devnull))
    except (OSError, ValueError):
        return False


def _stopped(signum: int) -> int:
    """The one line and the exit code (128 + the signal) of a run stopped by Ctrl-C or SIGTERM."""
    from designer import interrupt

    done = interrupt.written()
    print(("fpdesign: interrupted" if signum == signal.SIGINT else "fpdesign: terminated")
          + (f" after its outputs were put in place whole ({', '.join(done)})" if done else ""), file=sys.stderr)
    return 128 + int(signum)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
