"""The error budget (docs/model.md §13): every contribution to the force and position errors as a
standard uncertainty (JCGM 100, the GUM), combined by root sum of squares.

Each contribution is an error ``δV_i`` of the bridge outputs, propagated through the
least-squares estimator (``estimator``) to the force and the position. Three shapes occur:

- *per bridge, independent*: each output has its own error of standard uncertainty ``u``
  (noise; the calibration fit; each bridge's own zero drift; the front-end's gain drift);
- *common offset*: every output moves by the same ``δ``. With equal ``k_i`` it cancels in the
  force and moves the position by ``δ/(k·F)``;
- *common span*: every output scales by the same ``1 + s``. The force scales with it and the
  position does not move.

A systematic term bounded by its worst case ``a`` over the temperature range counts as a
rectangular distribution, ``u = a/sqrt(3)``; random terms are 1σ. Everything is written with
plain arithmetic and ``Ops`` so that it serves both the evaluator and the optimiser's graph.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from designer.model.estimator import normal_matrix_inverse
from designer.model.ops import NUMERIC, Ops

SQRT3 = 3 ** 0.5
RANDOM, SYSTEMATIC = "random", "systematic"


@dataclass(frozen=True)
class Contribution:
    """One term of the budget at one load, as variances (``u²``) so that a term that is zero
    keeps the optimiser's derivatives finite: ``force_var`` of ``u(F)/F``, ``position_var`` of
    ``u(x)`` in m²."""

    name: str
    kind: str          # RANDOM | SYSTEMATIC
    force_var: Any
    position_var: Any

    @property
    def force(self) -> float:
        """``u(F)/F`` (numbers only)."""
        return float(self.force_var) ** 0.5

    @property
    def position(self) -> float:
        """``u(x)``, m (numbers only)."""
        return float(self.position_var) ** 0.5


@dataclass(frozen=True)
class BudgetInputs:
    """What the budget needs beyond the beam model, in SI; every drift is its worst case over the
    operating temperatures, ``ΔT = max|T − T_cal|``.

    ``sigma_v``: the noise per channel at the output, V. ``calibration_leverage(F, x)``: the
    calibration fit's variance at a load as a multiple of ``sigma_v²`` (``calibration_leverage``).
    ``zero_common``, ``zero_each``: the worst output offset change common to all bridges and each
    bridge's own, V at the output. ``span``: ``|α_G − α_E|·ΔT``. ``gain_each``: the front-end's
    gain drift ``γ·ΔT`` per channel. ``creep``: the output's creep over the hold, as a fraction.
    ``weights``: the calibration weights' maximum permissible error, as a fraction. ``placement``:
    the worst error in placing the calibration load, m. ``quarter``: bridges with one active
    gauge (their output is not linear in the strain: ``V ∝ ε/(1 + G ε/2)``). ``gauge_factor``."""

    sigma_v: Any
    calibration_leverage: Any
    zero_common: Any
    zero_each: Any
    span: Any
    gain_each: Any
    creep: Any
    weights: Any
    placement: Any
    quarter: bool
    gauge_factor: float


def _gradients(k, d, force, position):
    """``∂F/∂V_i`` and ``∂x/∂V_i`` of the least-squares estimate at ``(force, position)``."""
    m11, m12, m22 = normal_matrix_inverse(k, d)
    g_force = [ki * (m12 - m22 * di) for ki, di in zip(k, d)]
    g_moment = [ki * (m11 - m12 * di) for ki, di in zip(k, d)]
    g_position = [(gm - position * gf) / force for gm, gf in zip(g_moment, g_force)]
    return g_force, g_position


def _independent(gradients, u_each):
    """The variance of a sum of per-bridge errors of standard uncertainty ``u_each`` (one value,
    or one per bridge)."""
    u_each = u_each if isinstance(u_each, (list, tuple)) else [u_each] * len(gradients)
    return sum((g * u) * (g * u) for g, u in zip(gradients, u_each))


def _signed(gradients, errors):
    """The change of an estimate when the outputs move by ``errors`` (one per bridge)."""
    return sum(g * e for g, e in zip(gradients, errors))


def contributions(k, d, force, position, strains, inputs: BudgetInputs) -> list[Contribution]:
    """Every contribution at the load ``force`` at ``position`` (bridges' sensitivities ``k``,
    stations ``d``, gauge strains ``strains`` at that load)."""
    g_f, g_x = _gradients(k, d, force, position)
    outputs = [ki * force * (position - di) for ki, di in zip(k, d)]

    def independent(name, kind, u_each):
        return Contribution(name, kind, _independent(g_f, u_each) / (force * force), _independent(g_x, u_each))

    def signed(name, errors, scale=1 / SQRT3):
        df, dx = _signed(g_f, errors) * scale / force, _signed(g_x, errors) * scale
        return Contribution(name, SYSTEMATIC, df * df, dx * dx)

    def span(name, a):
        return Contribution(name, SYSTEMATIC, a * a / 3, 0.0 * a)

    zero = 0.0 * force
    out = [
        independent("noise", RANDOM, inputs.sigma_v),
        independent("calibration fit", RANDOM, inputs.sigma_v * inputs.calibration_leverage(force, position) ** 0.5),
        signed("zero drift, common", [inputs.zero_common] * len(k)),
        independent("zero drift, between bridges", SYSTEMATIC, inputs.zero_each / SQRT3),
        span("span drift", inputs.span),
        independent("front-end gain drift", SYSTEMATIC, [v * inputs.gain_each / SQRT3 for v in outputs]),
        span("creep", inputs.creep),
    ]
    if inputs.quarter:
        # V = V_lin / (1 + G ε/2) ~ V_lin (1 - G ε/2): a bias that differs between the stations
        out.append(signed("bridge non-linearity", [-v * inputs.gauge_factor * e / 2 for v, e in zip(outputs, strains)]))
    out += [span("calibration weights", inputs.weights),
            Contribution("calibration load placement", SYSTEMATIC, zero, zero + inputs.placement ** 2 / 3)]
    return out


def combined(terms: list[Contribution], ops: Ops = NUMERIC):
    """``(u_c(F)/F, u_c(x))``: the root sum of squares of every term."""
    return ops.sqrt(sum(t.force_var for t in terms)), ops.sqrt(sum(t.position_var for t in terms))
