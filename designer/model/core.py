"""The sensor model of MODEL.md, written once for numbers and for casadi expressions.

Every function takes its math through an ``Ops`` backend: ``NUMERIC`` (numpy) for checking
and reporting a design, ``casadi_ops()`` for the optimiser's symbolic graph. The same
expressions therefore drive the solver and the check of its answer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from designer.model.estimator import normal_matrix_inverse

# First root of 1 + cos(b) cosh(b) = 0 for a clamped-free beam (Euler-Bernoulli).
CLAMPED_FREE_ROOT = 1.8751040687
# A deflection above this fraction of the free length leaves small-deflection theory.
LARGE_DEFLECTION_RATIO = 0.10
# Constraints whose normalised slack is below this bind (0.5 % of the limit).
ACTIVE_TOLERANCE = 5e-3


@dataclass(frozen=True)
class Ops:
    sqrt: Callable
    sin: Callable
    cos: Callable
    acos: Callable
    fmax: Callable
    fmin: Callable


NUMERIC = Ops(np.sqrt, np.sin, np.cos, np.arccos, np.fmax, np.fmin)


def casadi_ops() -> Ops:
    import casadi

    return Ops(casadi.sqrt, casadi.sin, casadi.cos, casadi.acos, casadi.fmax, casadi.fmin)


@dataclass(frozen=True)
class Geometry:
    """A beam's shape. Sizes are SI floats, or casadi expressions inside the optimiser."""

    section: str                   # rectangle | round | tube
    feature: str                   # pocket | hole | none
    stations: tuple                # d_i, m
    length: Any                    # free length, m
    width: Any = None              # rectangle b
    height: Any = None             # rectangle h
    diameter: Any = None           # round, tube D
    wall: Any = None               # tube t
    depth: Any = 0.0               # pocket depth p
    hole: Any = 0.0                # hole diameter d_h
    pocket_length: float = 0.0     # l_p
    pocket_width: float = 0.0      # w_p
    gauge_length: float = 0.0
    axes: int = 1

    @property
    def feature_length(self):
        """l_f: the feature's length along the beam (MODEL.md section 1)."""
        return {"pocket": self.pocket_length, "hole": self.hole, "none": self.gauge_length}[self.feature]

    @property
    def size(self):
        """Section size in the load direction (h or D)."""
        return self.height if self.section == "rectangle" else self.diameter


@dataclass(frozen=True)
class MaterialParams:
    """The material as the model needs it; floats, or casadi parameters."""

    E: Any
    allowable: Any   # allowable stress, Pa
    density: Any


@dataclass(frozen=True)
class SectionProperties:
    A: Any          # plain section area
    I: Any          # plain second moment about the bending axis
    y_root: Any     # extreme fibre used for the root stress
    A_s: Any        # reduced section at a station
    I_s: Any
    y_g: Any        # gauge distance from the neutral axis
    y_e: Any        # extreme fibre at the reduced section
    feature_volume: Any  # material removed at one station (all faces)


# ----------------------------------------------------------------- circular segments

def segment_area(R, alpha, ops: Ops = NUMERIC):
    """Area of the circular segment beyond ``|z| = R cos(alpha)`` (MODEL.md section 2)."""
    return R * R * (alpha - ops.sin(alpha) * ops.cos(alpha))


def segment_inertia_normal(R, alpha, ops: Ops = NUMERIC):
    """Second moment of that segment about the centre, along its own normal (int z^2 dA)."""
    s, c = ops.sin(alpha), ops.cos(alpha)
    return R ** 4 / 4 * (alpha - s * c + 2 * s ** 3 * c)


def segment_inertia_across(R, alpha, ops: Ops = NUMERIC):
    """Second moment of a segment beyond ``|y| = R cos(alpha)`` about the y axis (int z^2 dA).

    Integrating ``(2/3)(R^2 - y^2)^(3/2)`` from ``R cos(alpha)`` to ``R`` gives
    ``R^4 (alpha/4 - sin(2 alpha)/6 + sin(4 alpha)/48)``; a half disc (alpha = pi/2) gives pi R^4/8.
    """
    return R ** 4 * (alpha / 4 - ops.sin(2 * alpha) / 6 + ops.sin(4 * alpha) / 48)


def flat_half_angle(R, depth, ops: Ops = NUMERIC):
    """Half angle of a flat milled to ``depth`` on a circle of radius ``R``."""
    return ops.acos((R - depth) / R)


# ----------------------------------------------------------------- section properties

def section_properties(g: Geometry, ops: Ops = NUMERIC) -> SectionProperties:
    """Plain and reduced section properties (MODEL.md section 2) for one station."""
    biaxial = g.axes == 2
    if g.section == "rectangle":
        b, h = g.width, g.height
        A, I = b * h, b * h ** 3 / 12
        # A biaxial square bent at 45 degrees puts its corner at (h/2)(cos + sin) = h/sqrt(2).
        corner = math.sqrt(2.0) if biaxial else 1.0
        y_root = corner * h / 2
        if g.feature == "pocket":
            p, w, lp = g.depth, g.pocket_width, g.pocket_length
            I_slot = w * p ** 3 / 12 + w * p * (h / 2 - p / 2) ** 2
            A_s, I_s = A - 2 * w * p, I - 2 * I_slot
            faces = 2
            if biaxial:  # slots on the side faces, centred on the neutral axis
                A_s, I_s = A_s - 2 * w * p, I_s - 2 * p * w ** 3 / 12
                faces = 4
            return SectionProperties(A, I, y_root, A_s, I_s, h / 2 - p, corner * h / 2, faces * w * p * lp)
        if g.feature == "hole":
            d = g.hole
            return SectionProperties(A, I, y_root, b * (h - d), b * (h ** 3 - d ** 3) / 12, h / 2, h / 2,
                                     math.pi * d * d / 4 * b)
        return SectionProperties(A, I, y_root, A, I, h / 2, y_root, 0.0)

    R = g.diameter / 2
    A, I = math.pi * R ** 2, math.pi * R ** 4 / 4
    if g.section == "tube":
        r = R - g.wall
        A, I = A - math.pi * r ** 2, I - math.pi * r ** 4 / 4
    if g.feature != "pocket":
        return SectionProperties(A, I, R, A, I, R, R, 0.0)
    p, lp = g.depth, g.pocket_length
    alpha = flat_half_angle(R, p, ops)
    seg_A = segment_area(R, alpha, ops)
    A_s, I_s = A - 2 * seg_A, I - 2 * segment_inertia_normal(R, alpha, ops)
    faces = 2
    y_e = R - p
    if biaxial:  # flats on the side faces too; the arcs between flats stay at R
        A_s, I_s = A_s - 2 * seg_A, I_s - 2 * segment_inertia_across(R, alpha, ops)
        faces, y_e = 4, R
    return SectionProperties(A, I, R, A_s, I_s, R - p, y_e, faces * seg_A * lp)


# ----------------------------------------------------------------- the analysis

@dataclass(frozen=True)
class Analysis:
    """Every predicted quantity of MODEL.md sections 3-4 for one design (SI)."""

    props: SectionProperties
    sensitivity: Any          # k, V/(N m), the same at every station
    sigma_v: float            # V
    force_error: Any          # sigma_F / F_min
    position_error: Any       # sigma_x(F_min, x_max), m
    stress_root: Any
    stress_feature: Any
    gauge_strain: tuple       # at F_max, x_max, per station
    min_signal_snr: Any
    deflection: Any           # free end, m
    natural_frequency: Any
    mass: Any
    noise_strain: Any         # the noise as an equivalent gauge strain

    @property
    def max_stress(self):
        return max(self.stress_root, self.stress_feature)


def analyse(g: Geometry, m: MaterialParams, spec, ops: Ops = NUMERIC) -> Analysis:
    """The forward model for geometry ``g`` of material ``m`` under ``spec`` (a Spec)."""
    load, e = spec.load, spec.electronics
    sp = section_properties(g, ops)
    n = spec.bridge_factor
    k = e.excitation * spec.gauge.factor * e.gain * n * sp.y_g / (4 * m.E * sp.I_s)
    sigma_v = spec.sigma_v
    d = list(g.stations)
    m11, m12, m22 = normal_matrix_inverse([k] * len(d), d)
    f_min, f_max, x_min, x_max = load.force_min, load.force_max, load.position_min, load.position_max
    force_error = sigma_v * ops.sqrt(m22) / f_min
    position_error = sigma_v * ops.sqrt(m11 - 2 * x_max * m12 + x_max ** 2 * m22) / f_min

    l_f = g.feature_length
    stress_root = f_max * x_max * sp.y_root / sp.I
    stress_feature = f_max * (x_max - (d[0] - l_f / 2)) * sp.y_e / sp.I_s
    strains = tuple(f_max * (x_max - di) * sp.y_g / (m.E * sp.I_s) for di in d)
    snr = k * f_min * (x_min - d[-1]) / sigma_v

    deflection = tip_deflection(g, sp, m.E, f_max, x_max)
    frequency = CLAMPED_FREE_ROOT ** 2 / (2 * math.pi) * ops.sqrt(m.E * sp.I / (m.density * sp.A * g.length ** 4))
    mass = m.density * (sp.A * g.length - len(d) * sp.feature_volume)
    noise_strain = 4 * sigma_v / (e.excitation * spec.gauge.factor * e.gain * n)
    return Analysis(sp, k, sigma_v, force_error, position_error, stress_root, stress_feature, strains,
                    snr, deflection, frequency, mass, noise_strain)


def _moment_arm_integral(s, x, ell):
    """Antiderivative of (x - s)(ell - s) in s."""
    return x * ell * s - (x + ell) * s ** 2 / 2 + s ** 3 / 3


def tip_deflection(g: Geometry, sp: SectionProperties, E, force, x):
    """Free-end deflection for ``force`` at ``x`` with EI piecewise (unit-load method).

    ``w(ell) = F * integral_0^x (x - s)(ell - s) / EI(s) ds`` equals ``w(x) + theta(x)(ell - x)``;
    each feature's reduced section acts over its length ``l_f``.
    """
    ell = g.length
    plain = ((ell - x) * x ** 2 / 2 + x ** 3 / 3) / (E * sp.I)
    extra = 1 / (E * sp.I_s) - 1 / (E * sp.I)
    half = g.feature_length / 2
    for di in g.stations:
        plain = plain + extra * (_moment_arm_integral(di + half, x, ell) - _moment_arm_integral(di - half, x, ell))
    return force * plain


def objective_value(a: Analysis, spec):
    """The objective the spec names (MODEL.md section 5), for numbers only."""
    if spec.objective == "deflection":
        return float(a.deflection)
    if spec.objective == "mass":
        return float(a.mass)
    return error_ratio(a, spec)


def error_ratio(a: Analysis, spec) -> float:
    """``e = max(force error / target, position error / target)``; ``e <= 1`` meets the targets."""
    return max(float(a.force_error) / spec.targets.force_error,
               float(a.position_error) / spec.targets.position_error)


# ----------------------------------------------------------------- limits

@dataclass(frozen=True)
class Limit:
    """One limit: ``value <= limit`` (``upper``) or ``value >= limit``, in SI.

    ``normalised`` is the optimiser's ``g <= 0`` form: ``value/limit - 1`` (or ``1 - value/limit``);
    limits at zero are scaled by ``scale`` instead.
    """

    name: str
    value: Any
    limit: Any
    upper: bool = True
    scale: Any = None
    unit: str = ""

    @property
    def normalised(self):
        scale = self.scale if self.scale is not None else self.limit
        gap = self.value - self.limit if self.upper else self.limit - self.value
        return gap / scale

    def record(self) -> dict:
        """As written to design.json: ``margin`` is the slack as a fraction of the limit
        (``1 - value/limit`` for an upper bound), whatever scale the optimiser uses; a limit
        of zero reports the slack itself. ``satisfied`` is judged on the normalised form."""
        value, limit = float(self.value), float(self.limit)
        slack = (limit - value) if self.upper else (value - limit)
        margin = slack / abs(limit) if limit != 0 else slack
        return {"name": self.name, "value": value, "limit": limit,
                "sense": "<=" if self.upper else ">=", "margin": margin,
                "active": bool(abs(margin) <= ACTIVE_TOLERANCE),
                "satisfied": bool(float(self.normalised) <= 1e-9), "unit": self.unit}


def limits(g: Geometry, a: Analysis, m: MaterialParams, spec, include_targets: bool = True,
           ops: Ops = NUMERIC) -> list[Limit]:
    """Every limit of MODEL.md section 4 and the geometry rules of section 1."""
    lim, load = spec.limits, spec.load
    mm = 1e-3  # scale for geometric rules whose limit may be zero
    d = list(g.stations)
    l_f = g.feature_length
    out = [
        Limit("stress_root", a.stress_root, m.allowable, unit="Pa"),
        Limit("stress_feature", a.stress_feature, m.allowable, unit="Pa"),
        Limit("gauge_strain", a.gauge_strain[0], spec.gauge.max_strain, unit="strain"),
        Limit("min_signal_snr", a.min_signal_snr, lim.min_snr, upper=False),
        Limit("clamp_clearance", d[0] - l_f / 2, lim.clamp_clearance, upper=False, scale=mm, unit="m"),
        Limit("load_clearance", d[-1] + l_f / 2 + lim.load_clearance, load.position_min, scale=mm, unit="m"),
    ]
    out += [Limit(f"station_gap_{i + 1}", d[i + 1] - d[i], l_f + lim.gauge_gap, upper=False, scale=mm, unit="m")
            for i in range(len(d) - 1)]
    if lim.max_deflection is not None:
        out.append(Limit("deflection", a.deflection, lim.max_deflection, unit="m"))
    if lim.min_frequency is not None:
        out.append(Limit("natural_frequency", a.natural_frequency, lim.min_frequency, upper=False, unit="Hz"))
    if include_targets:
        out += [Limit("force_error", a.force_error, spec.targets.force_error),
                Limit("position_error", a.position_error, spec.targets.position_error, unit="m")]
    out += section_limits(g, spec, ops)
    return out


def worst_normalised(limits: list[Limit], n: int) -> np.ndarray:
    """The largest normalised value of ``limits`` for each of ``n`` designs evaluated at once
    (numeric arrays; a limit that does not vary is broadcast)."""
    return np.max(np.stack([np.broadcast_to(np.asarray(lim.normalised, dtype=float), (n,)) for lim in limits]),
                  axis=0)


def section_limits(g: Geometry, spec, ops: Ops = NUMERIC) -> list[Limit]:
    """Size bounds and the manufacturing rules of a section and its feature."""
    lim = spec.limits
    mm = 1e-3
    out = []
    if g.section == "rectangle":
        out += [Limit("width_min", g.width, lim.width[0], upper=False, unit="m"),
                Limit("width_max", g.width, lim.width[1], unit="m"),
                Limit("height_min", g.height, lim.height[0], upper=False, unit="m"),
                Limit("height_max", g.height, lim.height[1], unit="m")]
    else:
        out += [Limit("diameter_min", g.diameter, max(lim.width[0], lim.height[0]), upper=False, unit="m"),
                Limit("diameter_max", g.diameter, min(lim.width[1], lim.height[1]), unit="m")]
    if g.section == "tube":
        out += [Limit("wall_min", g.wall, lim.min_wall, upper=False, unit="m"),
                Limit("bore_min", g.diameter - 2 * g.wall, lim.min_wall, upper=False, unit="m")]
    if g.feature == "pocket":
        size = g.size
        out += [Limit("pocket_depth_min", g.depth, lim.min_pocket_depth, upper=False, unit="m"),
                Limit("pocket_depth_max", g.depth, lim.max_pocket_fraction * size, scale=lim.max_pocket_fraction * mm,
                      unit="m")]
        if g.section == "rectangle":
            out.append(Limit("pocket_side_wall", (g.width - g.pocket_width) / 2, lim.min_wall, upper=False, unit="m"))
            if g.axes == 2:  # side slots must not reach the top and bottom slots
                out.append(Limit("pocket_corner", g.depth + g.pocket_width / 2, g.width / 2 - lim.min_wall,
                                 scale=mm, unit="m"))
        else:
            R = g.diameter / 2
            half_chord = ops.sqrt(ops.fmax(R * R - (R - g.depth) ** 2, 0.0))
            out.append(Limit("flat_chord", 2 * half_chord, g.pocket_width, upper=False, unit="m"))
            if g.axes == 2:  # neighbouring flats must not meet
                out.append(Limit("flat_corner", half_chord, R - g.depth, scale=mm, unit="m"))
            if g.section == "tube":
                out.append(Limit("flat_wall", g.depth, g.wall - lim.min_wall, scale=mm, unit="m"))
    if g.feature == "hole":
        out += [Limit("hole_ligament", (g.height - g.hole) / 2, lim.min_wall, upper=False, unit="m"),
                Limit("hole_min", g.hole, lim.min_wall, upper=False, unit="m")]
    return out
