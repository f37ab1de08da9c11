"""Checks of a spec's mappings and keys, shared by the readers of its parts."""

from __future__ import annotations

from designer.errors import SpecError, brief, describe_allowed
from designer.model.sections import LEAST_CUT


def mapping(raw, key: str, allowed) -> dict:
    """``raw`` as a mapping of the ``allowed`` keys (None: empty); SpecError names the first unknown key."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise SpecError(f"{key}: {brief(raw)} must be a mapping with keys {describe_allowed(allowed)}")
    unknown = [k for k in raw if k not in allowed]
    if unknown:
        raise SpecError(f"{key}.{unknown[0]}: unknown key; allowed keys are {describe_allowed(allowed)}")
    return raw


def required(raw: dict, key: str, parent: str):
    """``raw[key]``; SpecError ``parent.key: missing`` when it is absent or null."""
    if key not in raw or raw[key] is None:
        raise SpecError(f"{parent}.{key}: missing; it is required" if parent else f"{key}: missing; it is required")
    return raw[key]


def boolean(value, key: str) -> bool:
    """``value`` if it is true or false; SpecError naming ``key`` otherwise."""
    if not isinstance(value, bool):
        raise SpecError(f"{key}: {value!r} must be true or false")
    return value


LONGEST_NAME = 100   # characters: a name fits a report's table and a plot's legend


def plain_name(value, key: str, error: type = SpecError) -> str:
    """``value`` as a name that reports, plots and the drawing show as it is: text on one line,
    without control characters or '$' (which the plots would read as mathematics), at most
    LONGEST_NAME characters; ``error`` naming ``key`` otherwise."""
    if (not isinstance(value, str) or not value.strip() or len(value) > LONGEST_NAME or "$" in value
            or not value.isprintable()):
        raise error(f"{key}: {value!r} must be a name: text on one line of at most {LONGEST_NAME} characters, "
                    "without control characters or '$'")
    return value


def machinable(value: float, key: str, shown: str, error: type = SpecError) -> float:
    """``value`` (m) when a part can be cut to it: at least LEAST_CUT, the 0.01 mm grid its sizes
    are given on; ``error`` naming ``key`` and the value as written (``shown``) otherwise."""
    if value < LEAST_CUT * (1 - 1e-9):
        raise error(f"{key}: {shown} is finer than the {LEAST_CUT * 1e3:g} mm grid a part is machined to; must be "
                    f"at least {LEAST_CUT * 1e3:g} mm")
    return value
