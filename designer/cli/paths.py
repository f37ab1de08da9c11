"""A command never writes over one of its own inputs."""

from __future__ import annotations

from pathlib import Path

from designer.errors import InputError
from designer.outputs.files import same_file


def guard_inputs(outputs: dict, inputs: dict) -> None:
    """InputError when an output file (``{flag: path}``) is one of the inputs (``{name: path}``),
    a folder, below a file, or the file of another output: checked before any work is done."""
    for flag, out in outputs.items():
        not_empty(out, flag, "a file name")
    given = [(flag, out) for flag, out in outputs.items() if out]
    for i, (flag, out) in enumerate(given):
        if Path(out).is_dir():
            raise InputError(f"{flag}: {out} is a folder; give a file name")
        folder = Path(out).parent
        while not folder.exists() and folder.parent != folder:
            folder = folder.parent
        if not folder.is_dir():
            raise InputError(f"{flag}: {out} cannot be written: {folder} is a file, not a folder")
        for name, path in inputs.items():
            if path and same_file(out, path):
                raise InputError(f"{flag}: {out} is the {name} this command reads; write to another file")
        for other, path in given[:i]:
            if same_file(out, path):
                raise InputError(f"{other} {path} and {flag} {out} name the same file; give each output its own file")


def not_empty(path, flag: str, wanted: str) -> None:
    """InputError for a path given as empty text (an unset shell variable), which would name the
    current folder."""
    if path is not None and not str(path).strip():
        raise InputError(f"{flag}: {str(path)!r} is empty; give {wanted}")


def output_folder(path, flag: str = "-o", what: str = "the outputs"):
    """``Path(path)``, checked before any work is done: InputError when it names a file."""
    not_empty(path, flag, f"a folder for {what}")
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{flag}: {folder} is a file, not a folder; give a folder for {what}")
    return folder


def whole_number(low: int, high: int):
    """An argparse type: a whole number from ``low`` to ``high``."""
    def parse(text: str) -> int:
        import argparse

        try:
            value = int(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from exc
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text!r} must be from {low} to {high}")
        return value
    return parse


#: The largest seed numpy's generators take from a command line (any 63-bit number works; the
#: bound keeps a typing slip such as 10**100 from reading as a seed).
MAX_SEED = 2**63 - 1
#: argparse type of ``--seed``: numpy refuses negative seeds
seed = whole_number(0, MAX_SEED)
