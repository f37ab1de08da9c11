"""The math backend that lets one set of model expressions serve numbers and casadi graphs.

Every model function takes its math through an ``Ops``: ``NUMERIC`` (numpy) for checking and
reporting a design, ``casadi_ops()`` for the optimiser's symbolic graph (docs/model.md §0).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np


@dataclass(frozen=True)
class Ops:
    sqrt: Callable
    sin: Callable
    cos: Callable
    acos: Callable
    fmax: Callable
    fmin: Callable
    exp: Callable = np.exp
    fabs: Callable = np.abs
    log: Callable = np.log


NUMERIC = Ops(np.sqrt, np.sin, np.cos, np.arccos, np.fmax, np.fmin, np.exp, np.abs, np.log)


def casadi_ops() -> Ops:
    import casadi

    return Ops(casadi.sqrt, casadi.sin, casadi.cos, casadi.acos, casadi.fmax, casadi.fmin, casadi.exp, casadi.fabs,
               casadi.log)


def ops_for(*values) -> Ops:
    """The operations for ``values``: casadi's where any of them is a casadi expression (numpy's
    functions on casadi values are deprecated by casadi), numpy's otherwise."""
    return casadi_ops() if any(type(v).__module__.startswith("casadi") for v in values) else NUMERIC


# Two peaks within this share of the first of each other have their maximum rounded off
# (``rounded_max``): IPOPT stalls at the kink of a plain max(). Beyond it the maximum is exact, so
# that a design one peak governs by more is judged, and searched, as with the plain maximum.
PEAK_SMOOTHING = 0.002


def rounded_max(a, b, width, ops: Ops = NUMERIC):
    """``max(a, b)`` rounded off within ``w`` = ``width`` of each other:
    ``max(a, b) + max(w - |a - b|, 0)^2 / (4 w)`` is ``(a + b)/2 + (w^2 + (a - b)^2)/(4 w)`` there
    (smooth, never below the maximum, at most ``w / 4`` above it) and the maximum itself beyond,
    where its value and derivatives are exactly those of the larger."""
    return ops.fmax(a, b) + ops.fmax(width - ops.fabs(a - b), 0.0) ** 2 / (4 * width)


# The least area (m^2) under a square root of a length squared, (1 nm)^2: sqrt's derivative at 0 is
# infinite, and where a max() clips the area to 0 its derivative there is 0 x infinity, no number
# (IPOPT's Invalid_Number_Detected), at a tiny round bar whose wire channel is wider than it, or a
# flat cut to no depth at a tolerance corner. A nanometre changes no length the model reports.
LEAST_AREA = 1e-18


def clipped_root(area, ops: Ops = NUMERIC):
    """``sqrt(max(area, 0))`` (m), with its derivative a number everywhere: the area is clipped at
    ``LEAST_AREA`` rather than 0."""
    return ops.sqrt(ops.fmax(area, LEAST_AREA))
