"""The objectives, the feasibility tolerance and the ranking of designs (docs/model.md §5)."""

from __future__ import annotations

from designer.model.ops import NUMERIC, Ops

OBJECTIVES = ("error", "deflection", "mass")
# What ranks designs tied on the objective first (then mass, then deflection).
SECONDARY = {"error": "deflection", "deflection": "mass", "mass": "deflection"}
# Objectives within this fraction of each other tie; ties rank by deflection, then mass.
TIE_TOLERANCE = 1e-3
# A limit's normalised value (value/limit - 1) up to this counts as met.
FEASIBILITY_TOLERANCE = 1e-9


def error_terms(a, targets):
    """``(sigma_F/F_min ÷ force target, sigma_x ÷ position target)``: each 1 on target."""
    return a.force_error / targets.force_error, a.position_error / targets.position_error


def error_ratio(a, targets, ops: Ops = NUMERIC):
    """``e = max(force error / target, position error / target)``; ``e <= 1`` meets the targets."""
    return ops.fmax(*error_terms(a, targets))


def objective(a, spec, ops: Ops = NUMERIC):
    """The objective ``spec.objective`` names, SI (numbers, arrays or casadi)."""
    if spec.objective == "deflection":
        return a.deflection
    if spec.objective == "mass":
        return a.mass
    return error_ratio(a, spec.targets, ops)


def secondary(a, spec):
    """The quantity ``SECONDARY`` names for ``spec.objective``, SI."""
    return getattr(a, SECONDARY[spec.objective])


def ties(objective_value: float, lead: float) -> bool:
    """Whether ``objective_value`` lies within the tie band of the best objective ``lead``."""
    return objective_value - lead <= TIE_TOLERANCE * abs(lead)


def tie_key(ev) -> tuple:
    """Inside a tie band: lower deflection, then lower mass."""
    return float(ev.analysis.deflection), float(ev.analysis.mass)


def ranks_before(a, b) -> bool:
    """Lower objective first; within the tie band, lower deflection, then lower mass."""
    fa, fb = a.objective, b.objective
    if abs(fa - fb) > TIE_TOLERANCE * min(abs(fa), abs(fb)):
        return fa < fb
    return tie_key(a) < tie_key(b)


def rank(evaluations: list) -> list:
    """Order feasible evaluations: repeatedly take the best objective, then among those within
    the tie band of it the lowest deflection, then the lowest mass. Deterministic; ties are
    anchored on the best objective, never chained."""
    rest = sorted(evaluations, key=lambda ev: ev.objective)
    out = []
    while rest:
        lead = rest[0].objective
        pick = min((ev for ev in rest if ties(ev.objective, lead)), key=lambda ev: (*tie_key(ev), ev.objective))
        out.append(pick)
        rest.remove(pick)
    return out
