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

from designer.model.electronics import volts_per_strain
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

    ``sigma_v``: the noise per channel at the output, V. ``calibration``: the calibration fit
    (``CalibrationFit``).
    ``zero_common``, ``zero_each``: the worst output offset change common to all bridges and each
    bridge's own, V at the output. ``span``: ``|α_G − α_E|·ΔT``. ``gain_each``: the front-end's
    gain drift ``γ·ΔT`` per channel. ``creep``: the output's creep over the hold, as a fraction.
    ``weights``: the calibration weights' maximum permissible error, as a fraction. ``placement``:
    the worst error in placing the calibration load, m. ``quarter``: bridges with one active
    gauge (their output is not linear in the strain: ``V ∝ ε/(1 + G ε/2)``). ``gauge_factor``."""

    sigma_v: Any
    calibration: Any          # CalibrationFit
    zero_common: Any
    zero_each: Any
    span: Any
    gain_each: Any
    creep: Any
    weights: Any
    placement: Any
    quarter: bool
    gauge_factor: float
    rigidity: Any = None      # EI of the beam as its free-end deflection gives it, N m^2 (None: no large-deflection term)


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
        independent("calibration fit", RANDOM, inputs.sigma_v * inputs.calibration.leverage(force, position) ** 0.5),
        signed("zero drift, common", [inputs.zero_common] * len(k)),
        independent("zero drift, between bridges", SYSTEMATIC, inputs.zero_each / SQRT3),
        span("span drift", inputs.span),
        independent("front-end gain drift", SYSTEMATIC, [v * inputs.gain_each / SQRT3 for v in outputs]),
        span("creep", inputs.creep),
    ]
    if inputs.quarter:
        # V = V_lin / (1 + G ε/2) ~ V_lin (1 - G ε/2): a bias that differs between the stations
        out.append(signed("bridge non-linearity", [-v * inputs.gauge_factor * e / 2 for v, e in zip(outputs, strains)]))
    if inputs.rigidity is not None:
        out.append(signed("large deflection", _arm_shortening(k, d, force, position, inputs)))
    out += [span("calibration weights", inputs.weights),
            Contribution("calibration load placement", SYSTEMATIC, zero, zero + inputs.placement ** 2 / 3)]
    return out


def shortening(force, position, s, rigidity):
    """How far a point at arc length ``s <= position`` moves towards the clamp as the beam bends
    under ``force`` at ``position``, to first order: ``∫0^s θ²/2`` with the beam-theory slope
    ``θ = F (x s − s²/2) / EI``, i.e. ``F² (x² s³/3 − x s⁴/4 + s⁵/20) / (2 EI²)``; at the load
    ``F² x⁵ / (15 EI²) = 0.6 w²/x``."""
    return force * force * (position * position * s ** 3 / 3 - position * s ** 4 / 4 + s ** 5 / 20) / \
        (2 * rigidity * rigidity)


def _arm_shortening(k, d, force, position, inputs: BudgetInputs):
    """The outputs' error from the lever arm's shortening, left after the calibration fit: a bridge
    at ``d`` reads ``k F (x − d − (u(x) − u(d)))`` (the elastica's moment ``F (X_F − X(d))``), which
    the fit ``V = a F x + b F + c`` over the calibration loads absorbs in part; the rest at the load."""
    ei = inputs.rigidity
    fit = inputs.calibration

    def bias(ki, di, f, x):
        return -ki * f * (shortening(f, x, x, ei) - shortening(f, x, di, ei))

    weights = fit.weights(force, position)
    out = []
    for ki, di in zip(k, d):
        at_calibration = [bias(ki, di, f, x) for f, x in zip(fit.forces, fit.positions)]
        out.append(bias(ki, di, force, position) - sum(w * b for w, b in zip(weights, at_calibration)))
    return out


def combined(terms: list[Contribution], ops: Ops = NUMERIC):
    """``(u_c(F)/F, u_c(x))``: the root sum of squares of every term."""
    return ops.sqrt(sum(t.force_var for t in terms)), ops.sqrt(sum(t.position_var for t in terms))


@dataclass(frozen=True)
class CalibrationFit:
    """The 9-point scheme ``plan`` proposes (forces and positions at the ends and the middle of
    the region, each load hung once), each bridge fitted to ``V = a·F·x + b·F + c`` by least
    squares (docs/model.md §10)."""

    forces: tuple
    positions: tuple
    inverse: Any          # (XᵀX)⁻¹ of the rows (F x, F, 1)

    @classmethod
    def over(cls, force_range, position_range) -> "CalibrationFit":
        import numpy as np

        (f0, f1), (x0, x1) = force_range, position_range
        forces, positions = np.meshgrid([f0, (f0 + f1) / 2, f1], [x0, (x0 + x1) / 2, x1], indexing="ij")
        rows = _rows(forces.ravel(), positions.ravel())
        return cls(tuple(float(f) for f in forces.ravel()), tuple(float(x) for x in positions.ravel()),
                   np.linalg.inv(rows.T @ rows))

    def leverage(self, force, position):
        """``h = uᵀ (XᵀX)⁻¹ u``, ``u = (F x, F, 1)``: the fit's variance at the load as a multiple
        of one reading's."""
        import numpy as np

        u = _rows(force, position)
        h = np.einsum("...i,ij,...j->...", u, self.inverse, u)
        return float(h) if h.ndim == 0 else h

    def weights(self, force, position) -> list:
        """The fitted output at the load as weights on the calibration readings:
        ``uᵀ (XᵀX)⁻¹ Xᵀ``, one number (or array) per calibration load."""
        w = _rows(force, position) @ self.inverse @ _rows(self.forces, self.positions).T
        return [float(w[..., j]) if w.ndim == 1 else w[..., j] for j in range(len(self.forces))]


def _rows(force, position):
    """The fit's rows ``(F x, F, 1)``, one per load (the last axis)."""
    import numpy as np

    force, position = np.broadcast_arrays(np.asarray(force, float), np.asarray(position, float))
    return np.stack([force * position, force, np.ones_like(force)], axis=-1)


def budget_inputs(spec, material, ops: Ops = NUMERIC, rigidity=None) -> BudgetInputs:
    """The budget's figures for ``spec`` (with an ``environment``) and ``material`` (a
    ``MaterialParams``: numbers or the optimiser's parameters); docs/model.md §13.

    - A gauge on a material whose expansion its self-temperature compensation does not match
      reads ``|α_S − α_STC|`` of apparent strain per K (Micro-Measurements TN-504, transverse
      sensitivity aside), plus its residual ``thermal_output``. A quarter bridge carries all of it,
      the same on every bridge; a half or full bridge's arms cancel it but for the scatter
      between gauges, ``thermal_match`` per gauge, ``sqrt(n)`` of it for ``n`` active gauges.
    - The span follows ``k(T) = k(T_cal)·(1 + (α_G − α_E)(T − T_cal))``.
    - The front-end's offset and gain drift (its catalogue figures) differ between channels.
    - Creep is the material's figure over 30 min, scaled to the hold as ``(hold / 30 min)^(1/3)``
      (Andrade's law of primary creep).
    - With ``environment.tare`` the offsets are measured again, unloaded, at the operating
      temperature: no zero drift remains.
    - ``rigidity`` (EI, N m²), when given, adds the lever arm's shortening as the beam bends.
    """
    env, e, gauge = spec.environment, spec.electronics, spec.gauge
    swing = env.swing
    per_strain = volts_per_strain(e.excitation, gauge.factor, e.gain, 1)   # one active gauge's output per unit strain
    apparent = ops.fabs(material.expansion - gauge.compensated_for) + gauge.thermal_output
    quarter = spec.bridge == "quarter"
    fe = e.front_end
    offset_drift = fe.offset_drift if fe is not None and fe.offset_drift is not None else 0.0
    gain_drift = fe.gain_drift if fe is not None and fe.gain_drift is not None else 0.0
    load = spec.load
    zero_common = per_strain * apparent * swing if quarter else 0.0 * apparent
    zero_each = per_strain * spec.bridge_factor ** 0.5 * gauge.thermal_match * swing + offset_drift * e.gain * swing
    if env.tare:  # the offsets are measured again, unloaded, at the operating temperature
        zero_common, zero_each = 0.0 * zero_common, 0.0
    return BudgetInputs(
        sigma_v=spec.sigma_v,
        calibration=CalibrationFit.over((load.force_min, load.force_max), (load.position_min, load.position_max)),
        zero_common=zero_common,
        zero_each=zero_each,
        span=ops.fabs(gauge.factor_tc - material.modulus_tc) * swing,
        gain_each=gain_drift * swing,
        creep=material.creep * (env.hold / CREEP_HOLD) ** (1 / 3),
        weights=spec.calibration.weights_error,
        placement=spec.calibration.placement,
        quarter=quarter,
        gauge_factor=gauge.factor,
        rigidity=rigidity,
    )


CREEP_HOLD = 1800.0  # s: the hold of the materials' creep figures (OIML R 60's 30 min)


RECORDED = ("sigma_v", "zero_common", "zero_each", "span", "gain_each", "creep", "weights", "placement", "quarter",
            "gauge_factor", "rigidity")


def recorded_inputs(inputs: BudgetInputs) -> dict:
    """The inputs as design.json records them (numbers; the calibration fit as its region)."""
    return {k: (bool(inputs.quarter) if k == "quarter" else None if getattr(inputs, k) is None
                else float(getattr(inputs, k))) for k in RECORDED}


def inputs_from_record(recorded: dict, force_range, position_range) -> BudgetInputs:
    """``recorded_inputs`` read back, the calibration fit rebuilt over the region."""
    return BudgetInputs(calibration=CalibrationFit.over(force_range, position_range),
                        **{k: recorded.get(k) if k == "rigidity" else recorded[k] for k in RECORDED})


def corners(spec):
    """The four corners of the operating region, ``(F, x)``: each term is largest at one of them."""
    load = spec.load
    return [(f, x) for f in (load.force_min, load.force_max) for x in (load.position_min, load.position_max)]


def region_budget(k, d, strains_at_full_load, spec, material, ops: Ops = NUMERIC, rigidity=None):
    """``(force, position, points)``: the combined ``u_c(F)/F`` and ``u_c(x)``, each the largest
    over the region's corners, and every corner's ``(F, x, contributions)``. ``strains_at_full_load``
    are the gauge strains under ``F_max`` at ``x_max``; elsewhere they scale with the moment.
    ``rigidity``: EI for the large-deflection term (``effective_rigidity``)."""
    inputs = budget_inputs(spec, material, ops, rigidity)
    f_max, x_max = spec.load.force_max, spec.load.position_max
    points = []
    for force, position in corners(spec):
        strains = [s * force * (position - di) / (f_max * (x_max - di)) for s, di in zip(strains_at_full_load, d)]
        points.append((force, position, contributions(k, d, force, position, strains, inputs)))
    forces, positions = zip(*(combined(terms, ops) for _, _, terms in points))
    return _largest(forces, ops), _largest(positions, ops), points


def effective_rigidity(deflection, force, position, free_length):
    """The EI a prismatic cantilever would need to deflect its free end by ``deflection`` under
    ``force`` at ``position``: ``F x² (3 ℓ − x) / (6 w)``."""
    return force * position * position * (3 * free_length - position) / (6 * deflection)


def _largest(values, ops):
    out = values[0]
    for v in values[1:]:
        out = ops.fmax(out, v)
    return out
