"""The ``fpdesign`` command line: a thin layer that parses, calls the library, writes files.

Each command group lives in ``designer.cli.<group>`` and offers ``register(subparsers)``;
the heavy libraries (casadi, cadquery, matplotlib, gmsh) are imported only inside the
commands that use them, so that every command starts fast.
"""

from __future__ import annotations

import argparse
import importlib
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
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse exits 2 on bad usage, 0 on --help
        return int(exc.code or 0)
    try:
        return int(args.func(args) or 0)
    except FpdError as exc:
        print(f"fpdesign: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("fpdesign: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
