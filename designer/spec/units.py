"""Units at the edges: parse ``"50 N"``, ``"1500 ue"``, ``"0.5 in"`` into SI floats with pint.

Bare numbers are taken as SI. Every parse names the spec key in its error, with the value
and the kind of unit allowed.
"""

from __future__ import annotations

import functools
import math
import re

from designer.errors import SpecError

# The dimension each kind of quantity must have, and the SI unit it is returned in.
KINDS = {
    "force": ("[force]", "N", "a force such as '20 N' or '2 lbf'"),
    "length": ("[length]", "m", "a length such as '120 mm' or '0.5 in'"),
    "voltage": ("[electric_potential]", "V", "a voltage such as '5 V' or '1.3 mV'"),
    "strain": ("", "", "a strain such as '1500 ue' or 0.0015"),
    "frequency": ("1/[time]", "Hz", "a frequency such as '100 Hz'"),
    "ratio": ("", "", "a plain number or a percentage such as '1 %'"),
    "resistance": ("[resistance]", "ohm", "a resistance such as '120 ohm'"),
    "pressure": ("[pressure]", "Pa", "a stress such as '276 MPa' or '68.9 GPa'"),
    "density": ("[mass] / [length] ** 3", "kg/m^3", "a density such as '2700 kg/m^3'"),
    "mass": ("[mass]", "kg", "a mass such as '500 g'"),
}

_SUBSTITUTIONS = (
    (re.compile(r"(?<![A-Za-z])(µε|με|ue|uε)(?![A-Za-z])"), "microstrain"),
    (re.compile(r"%"), " percent"),
    (re.compile(r"Ω"), "ohm"),
)


@functools.lru_cache(maxsize=1)
def registry():
    """The one pint registry, built on first use (pint is slow to start)."""
    import pint

    ureg = pint.UnitRegistry()
    ureg.define("microstrain = 1e-6")
    return ureg


def parse(value, kind: str, key: str) -> float:
    """Return ``value`` in SI as a finite float, or raise SpecError naming ``key``."""
    dimension, si_unit, example = KINDS[kind]
    if isinstance(value, bool) or value is None:
        raise SpecError(f"{key}: {value!r} is not a value; expected {example}")
    if isinstance(value, (int, float)):
        number = float(value)
    elif isinstance(value, str):
        number = _parse_text(value, dimension, si_unit, example, key)
    else:
        raise SpecError(f"{key}: {value!r} is not a value; expected {example}")
    if not math.isfinite(number):
        raise SpecError(f"{key}: {value!r} is not a finite number; expected {example}")
    return number


def _parse_text(text: str, dimension: str, si_unit: str, example: str, key: str) -> float:
    import pint

    cleaned = text.strip()
    for pattern, replacement in _SUBSTITUTIONS:
        cleaned = pattern.sub(replacement, cleaned)
    ureg = registry()
    try:
        quantity = ureg.Quantity(cleaned)
    except Exception as exc:  # pint raises several types for unreadable text
        raise SpecError(f"{key}: {text!r} cannot be read as a quantity; expected {example}") from exc
    if not isinstance(quantity, ureg.Quantity) or str(quantity.units) == "dimensionless":
        return float(getattr(quantity, "magnitude", quantity))  # a bare number: SI
    try:
        if dimension:
            return float(quantity.to(si_unit).magnitude)
        return float(quantity.to("dimensionless").magnitude)
    except pint.DimensionalityError as exc:
        raise SpecError(f"{key}: {text!r} has the wrong units; expected {example}") from exc


def parse_positive(value, kind: str, key: str, allow_zero: bool = False) -> float:
    number = parse(value, kind, key)
    if number < 0 or (number == 0 and not allow_zero):
        what = "zero or positive" if allow_zero else "positive"
        raise SpecError(f"{key}: {value!r} must be {what}")
    return number


def parse_range(value, kind: str, key: str) -> tuple[float, float]:
    """A ``[low, high]`` pair of positive values with ``low < high``."""
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise SpecError(f"{key}: {value!r} must be a pair [low, high]")
    low = parse_positive(value[0], kind, f"{key}[0]")
    high = parse_positive(value[1], kind, f"{key}[1]")
    if not low < high:
        raise SpecError(f"{key}: {value!r} is reversed or empty; the first value must be below the second")
    return low, high


def mm(metres: float) -> float:
    return metres * 1e3
