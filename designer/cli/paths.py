"""A command never writes over one of its own inputs."""

from __future__ import annotations

import os
from pathlib import Path

from designer.errors import InputError


def _same(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    pa, pb = Path(a), Path(b)
    try:
        if pa.exists() and pb.exists():
            return os.path.samefile(pa, pb)
    except OSError:
        return False
    return pa.resolve() == pb.resolve()


def guard_inputs(outputs: dict, inputs: dict) -> None:
    """InputError when an output (``{flag: path}``) is one of the inputs (``{name: path}``)."""
    for flag, out in outputs.items():
        if not out:
            continue
        for name, path in inputs.items():
            if path and _same(out, path):
                raise InputError(f"{flag}: {out} is the {name} this command reads; write to another file")
