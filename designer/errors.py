"""The package's errors. Every error a user can cause derives from ``FpdError``.

``InputError`` and its subclasses mean bad input (spec, design.json, CSV): the command
line prints the message and exits with code 2, with no traceback.
"""


class FpdError(Exception):
    """Base of every error fpdesign raises on purpose."""

    exit_code = 1


class InputError(FpdError, ValueError):
    """Bad user input: names the key (or row and column), the value and what is allowed."""

    exit_code = 2


class SpecError(InputError):
    """A spec.yaml that cannot be read or violates SPEC.md."""


class DesignFileError(InputError):
    """A design.json that is missing keys or describes an impossible beam."""


class CsvError(InputError):
    """A readings CSV that cannot be used."""


class CalibrationFileError(InputError):
    """A calibration.json that is missing keys or holds impossible values."""


class CatalogueError(InputError):
    """A catalogue file (``materials/``, such as stock.yaml) that is missing keys or holds
    impossible values: the message names the file, the entry and the key."""


class SolverError(FpdError, RuntimeError):
    """A numerical method failed in a way the caller must hear about."""


def brief(value, width: int = 80) -> str:
    """``repr`` of a value from a file, cut to ``width`` characters: a whole list or object read
    where one value was due must not fill the screen."""
    text = repr(value)
    return text if len(text) <= width else text[:width - 3] + "..."


def metres(value) -> str:
    """A length of design.json for a message: in m, as the file holds it, and in mm. Twelve
    significant digits, so that a spec's 0.6 mm (0.0006000000000000001 m once converted) reads
    0.0006 m, while any two sizes on the 0.01 mm grid still read apart."""
    v = float(value)
    return f"{v:.12g} m ({v * 1e3:.6g} mm)"


def describe_allowed(choices) -> str:
    """``"one of [a, b, c]"`` for error messages."""
    return "one of [" + ", ".join(str(c) for c in choices) + "]"


def read_text(path, error: type, where: str | None = None, encoding: str = "utf-8") -> str:
    """The text of the file ``path``; a missing or unreadable file raises ``error`` (an
    InputError) whose message starts with ``where`` (the path by default)."""
    from pathlib import Path

    where = str(path) if where is None else where
    try:
        return Path(path).read_text(encoding=encoding)
    except FileNotFoundError as exc:
        raise error(f"{where}: no such file") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{where}: cannot be read ({exc})") from exc
