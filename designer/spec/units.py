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
    "voltage_drift": ("[electric_potential] / [temperature]", "V/K", "a drift such as '6 nV/K'"),
    "drift": ("1 / [temperature]", "1/K", "a drift such as '5 ppm/K'"),
    "temperature": ("[temperature]", "K", "a temperature such as '23 °C' or '296 K'"),
    "time": ("[time]", "s", "a time such as '30 min'"),
}

# A quantity is a number and, after it, a unit made of unit names with optional small integer
# powers, joined by spaces, '*', '/' or '·'. Anything else (a second number, a bare unit, an
# arithmetic expression such as '10**10**10 N') is refused before pint sees it: pint would
# multiply '3 N 4' into 12 N, read 'N' as 1 N and evaluate powers without bound.
_NUMBER = re.compile(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d{1,3})?)\s*(.*?)\s*$")
_UNIT_NAME = r"(?:°|[^\W\d])+(?:\s*(?:\^|\*\*)\s*-?\d)?"
_UNIT = re.compile(rf"{_UNIT_NAME}(?:\s*[*/·]\s*{_UNIT_NAME}|\s+{_UNIT_NAME})*")
MAX_TEXT = 100   # characters of a quantity's text

# The magnitudes fpdesign handles, per kind (SI): a nonzero value outside [smallest, largest]
# is refused, naming the range, rather than carried into the solvers (1e300 N overflows the
# optimiser's scaling, a position of 1e6 km stalls the elastica).
RANGES = {
    "force": (1e-9, 1e6), "length": (1e-9, 100.0), "voltage": (1e-15, 1e3), "strain": (1e-12, 1.0),
    "frequency": (1e-6, 1e9), "ratio": (1e-12, 1e10), "resistance": (1e-3, 1e9), "pressure": (1.0, 1e13),
    "density": (1e-3, 1e6), "mass": (1e-12, 1e5), "voltage_drift": (1e-15, 1.0), "drift": (1e-12, 1.0),
    "temperature": (1.0, 2000.0), "time": (1e-3, 1e9),
}

# pint's base units of no dimension that are not plain numbers
_COUNTED = {"radian": "an angle", "steradian": "a solid angle", "count": "a count"}

_SUBSTITUTIONS = (
    (re.compile(r"(?<![A-Za-z])(µε|με|ue|uε)(?![A-Za-z])"), "microstrain"),
    (re.compile(r"%"), " percent"),
    (re.compile(r"Ω"), "ohm"),
)


@functools.lru_cache(maxsize=1)
def registry():
    """The one pint registry, built on first use. Reading pint's definitions takes 0.12 s; pint
    keeps them parsed in the user's cache folder (``cache_folder=":auto:"``: 0.02 s from the
    second run on). A cache that cannot be written or read (a read-only home, a file half
    written by another run) falls back to reading the definitions."""
    import pint

    try:
        ureg = pint.UnitRegistry(cache_folder=":auto:")
    except Exception:  # noqa: BLE001 - any trouble with the cache: without it
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
    smallest, largest = RANGES[kind]
    if number != 0 and not smallest <= abs(number) <= largest:
        unit = f" {si_unit}" if si_unit else ""
        raise SpecError(f"{key}: {value!r} is outside what fpdesign handles; its size must lie between "
                        f"{smallest:g}{unit} and {largest:g}{unit}")
    return number


def _parse_text(text: str, dimension: str, si_unit: str, example: str, key: str) -> float:
    import pint

    shown = text if len(text) <= MAX_TEXT else text[:MAX_TEXT] + "..."
    match = _NUMBER.fullmatch(text) if len(text) <= MAX_TEXT else None
    unit = match.group(2) if match else ""
    if unit == "%":
        unit = "percent"
    if match is None or (unit and not (_UNIT.fullmatch(unit) or unit == "percent")):
        raise SpecError(f"{key}: {shown!r} cannot be read as a quantity (a number, then one unit); expected {example}")
    number = float(match.group(1))
    if not unit:
        return number  # a bare number: SI
    for pattern, replacement in _SUBSTITUTIONS:
        unit = pattern.sub(replacement, unit)
    ureg = registry()
    try:
        quantity = ureg.Quantity(number, unit.strip())
    except Exception as exc:  # pint raises several types for unreadable text
        raise SpecError(f"{key}: {shown!r} cannot be read as a quantity; expected {example}") from exc
    logarithmic = [str(name) for name in quantity._units if ureg._units[name].is_logarithmic]
    if logarithmic:
        # pint takes dB as a power ratio: '40 dB' of voltage gain would be 10 000, not 100
        raise SpecError(f"{key}: {text!r} has a logarithmic unit ({logarithmic[0]}), which fpdesign does not "
                        f"convert (a voltage's and a power's dB differ); give the ratio as a number, expected {example}")
    if str(quantity.units) == "dimensionless" and not dimension:
        return float(quantity.magnitude)
    base = dict(quantity.to_base_units().unit_items())
    counted = [what for name, what in _COUNTED.items() if name in base]
    if counted:
        # pint takes an angle or a count for a plain number: '2 rad' would be a gain of 2,
        # '60 rpm' a frequency of 2 pi Hz, '100 rad/s' one of 100 Hz
        raise SpecError(f"{key}: {text!r} has the wrong units: it holds {' and '.join(counted)}, which fpdesign "
                        f"does not convert; expected {example}")
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
