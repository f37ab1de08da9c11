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


def ops_for(value) -> Ops:
    """The operations for ``value``: casadi's for a casadi expression, numpy's otherwise."""
    return casadi_ops() if type(value).__module__.startswith("casadi") else NUMERIC
