"""Section geometry and section properties (docs/model.md §1-2), for numbers and casadi."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from designer.errors import metres
from designer.model.ops import NUMERIC, Ops, clipped_root, ops_for


def feature_length(feature: str, pocket_length, hole, gauge_length):
    """l_f, a feature's length along the beam: the pocket's length, the hole's diameter, or the
    gauge's length on a plain surface (docs/model.md §1). The one definition of l_f."""
    return {"pocket": pocket_length, "hole": hole, "none": gauge_length}[feature]


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
    grid_length: float = 0.0       # the gauge's active grid along the beam
    grid_width: float = 0.0        # ... and across it
    axes: int = 1
    floor_radius: float = 0.0      # the end mill's corner radius where a pocket's floor meets its end walls
    plan_radius: float = 0.0       # a slot's corner radius in plan: the radius of the end mill that cuts it
    channel_width: float = 0.0     # the wire channel along each pocketed face, clamp to last station (0: none)
    channel_depth: Any = 0.0

    @property
    def feature_length(self):
        """l_f: the feature's length along the beam (docs/model.md §1)."""
        return feature_length(self.feature, self.pocket_length, self.hole, self.gauge_length)

    @property
    def reduced_spans(self) -> tuple:
        """Where the reduced section acts: ``(d_i - l_f/2, d_i + l_f/2)`` for each station."""
        half = self.feature_length / 2
        return tuple((d - half, d + half) for d in self.stations)

    @property
    def size(self):
        """Section size in the load direction (h or D)."""
        return self.height if self.section == "rectangle" else self.diameter

    @property
    def breadth(self):
        """Section size across the load direction (b or D)."""
        return self.width if self.section == "rectangle" else self.diameter


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
    """Area of the circular segment beyond ``|z| = R cos(alpha)`` (docs/model.md §2)."""
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


# ----------------------------------------------------------------- wire channels

# The CAD's default wire channel (outputs.cad.beam): 1.5 mm takes four 0.3 mm lead wires side by
# side, 0.5 mm deep covers one; never more than half the pocket deep, nor wider than half a flat
# or 0.4 of a slot: a slot's channel enters through the straight part of its end wall, which the
# catalogue's end mill (at most 0.6 of the slot's width, outputs.cad.mills) leaves at least that
# wide. Both are rounded down to CHANNEL_STEP, as the CAD draws them.
CHANNEL_WIDTH = 1.5e-3
CHANNEL_DEPTH = 0.5e-3
CHANNEL_WIDTH_FRACTION = {"rectangle": 0.4, "round": 0.5, "tube": 0.5}
# The 0.01 mm grid a part's sizes are given on: the least cut the CAD details may give (the tool
# catalogue's finest corner radius is R0.01, on micro end mills), and the channels' step.
LEAST_CUT = 1e-5
CHANNEL_STEP = LEAST_CUT


def round_down(value, step: float = CHANNEL_STEP):
    """``value`` (a number or array) rounded down to ``step``, a hair's tolerance kept."""
    out = np.floor(np.asarray(value, dtype=float) / step + 1e-9) * step
    return float(out) if out.ndim == 0 else out


def default_channel(section: str, depth, pocket_width, end_mill=None, ops: Ops = NUMERIC) -> tuple:
    """``(width, depth)`` of the default wire channel of a pocket ``depth`` deep and
    ``pocket_width`` wide (the CAD's and the model's one rule): ``min(CHANNEL_WIDTH,
    CHANNEL_WIDTH_FRACTION[section] * w_p)`` wide, and on a slot cut by a given ``end_mill`` no wider than
    the straight part of its end wall, ``w_p - end_mill``; ``min(CHANNEL_DEPTH, depth / 2)`` deep;
    both rounded down to CHANNEL_STEP. For a casadi ``depth`` (the optimiser's graph) the depth is
    not rounded: the search sees a smooth channel at most one step deeper than the one built, and
    every reported design is evaluated with the built one."""
    width = min(CHANNEL_WIDTH, CHANNEL_WIDTH_FRACTION[section] * pocket_width)
    if end_mill is not None and section == "rectangle":
        width = min(width, pocket_width - end_mill)
    deep = ops.fmin(CHANNEL_DEPTH, depth / 2)
    return round_down(width), (round_down(deep) if ops is NUMERIC else deep)


def wire_channel(cad, section: str, feature: str, depth, pocket_width, ops: Ops = NUMERIC) -> tuple:
    """``(width, depth)`` of the wire channel the CAD cuts along each pocketed face from the clamp
    to the last station (``cad``: the spec's CadOptions; a size it gives, else
    ``default_channel``'s); ``(0, 0)`` without one."""
    if feature != "pocket" or not cad.wire_channels:
        return 0.0, 0.0
    width, deep = default_channel(section, depth, pocket_width, cad.end_mill_diameter, ops)
    return (cad.channel_width if cad.channel_width is not None else width,
            cad.channel_depth if cad.channel_depth is not None else deep)


def channel_inertia(g: Geometry, ops: Ops = NUMERIC):
    """What the wire channels on the two faces in the load direction take off the plain section's
    second moment: a ``w x t`` groove at the top of a bar, ``w (c^3 - (c - t)^3) / 3`` with
    ``c = h/2``; on a round bar or tube the part of the circle above ``z_0 = R - t`` within
    ``|y| <= a = w/2``: ``(2/3) (F(a) - z_0^3 a)``, ``F(a) = int_0^a (R^2 - y^2)^{3/2} dy
    = (a/8)(5R^2 - 2a^2) sqrt(R^2 - a^2) + (3R^4/8) asin(a/R)``. Both faces, 0 without channels."""
    w, t = g.channel_width, g.channel_depth
    if not w:
        return 0.0
    if g.section == "rectangle":
        c = g.height / 2
        return 2 * w * (c ** 3 - (c - t) ** 3) / 3
    R = g.diameter / 2
    z0 = R - t
    a = ops.fmin(w / 2, ops.sqrt(R * R - z0 * z0))
    big = a / 8 * (5 * R * R - 2 * a * a) * ops.sqrt(R * R - a * a) + 3 * R ** 4 / 8 * (math.pi / 2 - ops.acos(a / R))
    return 2 * 2 / 3 * (big - z0 ** 3 * a)


def flat_half_chord(radius: float, depth: float) -> float:
    """Half the chord of a flat ``depth`` deep on a circle of ``radius`` (m)."""
    return math.sqrt(max(radius * radius - (radius - depth) ** 2, 0.0))


def flat_depth(radius: float, width: float) -> float:
    """The depth (m) of a flat ``width`` wide on a circle of ``radius``, ``flat_half_chord``'s inverse:
    ``R - sqrt(R^2 - width^2/4)``; the radius when ``width`` is the diameter or more."""
    return radius - math.sqrt(max(radius * radius - width * width / 4, 0.0))


# A flat's clamp-side end wall, where its K_t peaks, is highest (the depth p) in the middle of the
# flat, where the wire channel runs into it: the channel, w_c wide and t_c deep, leaves a shoulder
# p - t_c high there, and beside it, at |y| = w_c/2 on the round, sqrt(R^2 - w_c^2/4) - (R - p).
def shoulder_ratio(g: Geometry):
    """The highest shoulder a round bar's or tube's flat keeps at its end wall beside the wire
    channel, over the flat's depth; 1 without a channel."""
    ops = ops_for(g.depth, g.diameter, g.channel_depth)
    R, p, half = g.diameter / 2, g.depth, g.channel_width / 2
    beside = clipped_root(R * R - half * half, ops) - (R - p)
    return ops.fmax(p - g.channel_depth, beside) / p


# Beam theory over-counts a wire channel's compliance: where a channel begins or ends (at the clamp
# face, at a pocket) the section carries the bending stress as if uncut for some way, so each
# channel span acts as if shorter by ``lambda``: ``CHANNEL_SHORTENING_ROUND * D`` on a round bar or
# tube, ``CHANNEL_SHORTENING_SLOT * h^(1 - q) * b^q`` on a rectangle (``h`` its size in the load
# direction, ``b`` the width of the face the channel is cut in). From 3-D solves of 90 bars
# (rectangles 0.6-8 times as wide as high with slots 0.6-0.9 of their width, round bars, tubes;
# channels 0.05-0.45 of the face wide and 1.5-15 % of the section deep; spans 0.3-15 sizes long)
# with and without their channels: q by least squares on the rectangles, each factor the lowest
# of its family's bars (benchmarks/channel_study.md), so that the model never counts less
# compliance than 3-D finds. The lowest are the deepest channels, and on a rectangle the widest
# slots: most channels act shorter still (up to 0.6 D on a round bar, 0.7 h on a 4:1 bar).
CHANNEL_SHORTENING_ROUND = 0.27
CHANNEL_SHORTENING_SLOT = 0.13
CHANNEL_SHORTENING_EXPONENT = 0.31


def channel_shortening(g: Geometry):
    """``lambda``, by which each wire-channel span acts shorter than it is (half at each end)."""
    if g.section != "rectangle":
        return CHANNEL_SHORTENING_ROUND * g.diameter
    q = CHANNEL_SHORTENING_EXPONENT
    return CHANNEL_SHORTENING_SLOT * g.size ** (1 - q) * g.breadth ** q


def channel_spans(g: Geometry, ops: Ops = NUMERIC, shortened: bool = True) -> tuple:
    """Where the wire channels alone reduce the section's stiffness: from the clamp face to the
    first feature and between features (the channel runs to the last station, inside the last
    feature's span, and a feature's own span is cut deeper than the channel), each shortened by
    ``channel_shortening`` (half at each end; a span shorter than that has none left), or where
    they are cut (``shortened=False``)."""
    if not g.channel_width:
        return ()
    spans = g.reduced_spans
    cut = ((0.0, spans[0][0]),) + tuple((spans[i][1], spans[i + 1][0]) for i in range(len(spans) - 1))
    if not shortened:
        return cut
    shorter = channel_shortening(g)
    # what is left of each span, max(l - lambda, 0) rounded off over a tenth of lambda (a kink
    # there would stall the gradient methods), at most 0.05 lambda long where nothing is left
    eps = 0.1 * shorter
    left = [(b - a - shorter + ops.sqrt((b - a - shorter) ** 2 + eps * eps)) / 2 for a, b in cut]
    return tuple((a + shorter / 2, a + shorter / 2 + rest) for (a, _), rest in zip(cut, left))


# ----------------------------------------------------------------- shear

def bore_ratio(g: Geometry):
    """``m``: a tube's bore over its outer diameter; 0 for a bar."""
    return (g.diameter - 2 * g.wall) / g.diameter if g.section == "tube" else 0.0


def shear_coefficient(section: str, m, poisson):
    """Timoshenko's shear coefficient ``kappa`` of a plain section, Cowper's from the exact flexure
    solution (G. R. Cowper, "The shear coefficient in Timoshenko's beam theory", J. Appl. Mech. 33
    (1966) 335-340, Table 1): ``10 (1 + nu) / (12 + 11 nu)`` for a rectangle, and for a hollow
    circle of bore ratio ``m`` (``bore_ratio``; 0: a solid bar)
    ``6 (1 + nu) (1 + m^2)^2 / ((7 + 6 nu)(1 + m^2)^2 + (20 + 12 nu) m^2)``."""
    nu = poisson
    if section == "rectangle":
        return 10 * (1 + nu) / (12 + 11 * nu)
    q = (1 + m * m) ** 2
    return 6 * (1 + nu) * q / ((7 + 6 * nu) * q + (20 + 12 * nu) * m * m)


def shear_stiffness(g: Geometry, sp, E, poisson):
    """``kappa G A`` of the plain section, ``G = E / (2 (1 + nu))``."""
    return shear_coefficient(g.section, bore_ratio(g), poisson) * E / (2 * (1 + poisson)) * sp.A


# ----------------------------------------------------------------- section properties

def section_properties(g: Geometry, ops: Ops = NUMERIC) -> SectionProperties:
    """Plain and reduced section properties (docs/model.md §2) for one station."""
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


def _mm(value) -> str:
    return f"{float(value) * 1e3:.6g} mm"


def unbuildable(g: Geometry) -> tuple[str, str] | None:
    """The first rule that keeps ``g`` (numbers) from being a beam at all, as ``(key, reason)``
    with the design.json key under ``design``; None for a buildable beam. These are not limits
    (a design may break limits and still be drawn, exported and simulated): a pocket deeper
    than the wall, a hole wider than the bar, a station off the beam."""
    dims = {"rectangle": ("width", "height"), "round": ("diameter",), "tube": ("diameter", "wall")}[g.section]
    for name in dims:
        if not getattr(g, name) > 0:
            return f"section.{name}", f"{metres(getattr(g, name))} must be positive"
    if g.section == "tube" and not g.wall < g.diameter / 2:
        return "section.wall", f"{metres(g.wall)} must be less than half the diameter ({_mm(g.diameter / 2)})"
    size = g.size
    if g.feature == "pocket":
        if not g.depth > 0:
            return "feature.depth", f"{metres(g.depth)} must be positive"
        limit, what = pocket_reach(g)
        if not g.depth < limit:
            return "feature.depth", f"{metres(g.depth)} is not less than {what} ({_mm(limit)})"
        if g.section == "rectangle" and not g.pocket_width < g.width:
            return "feature.width", f"{metres(g.pocket_width)} must be less than the section width ({_mm(g.width)})"
    if g.feature == "hole":
        if g.section != "rectangle":
            return "feature.kind", f"'hole' needs a rectangle section, not {g.section!r}"
        if not g.hole > 0:
            return "feature.diameter", f"{metres(g.hole)} must be positive"
        if not g.hole < size:
            return "feature.diameter", f"{metres(g.hole)} must be less than the section height ({_mm(size)})"
    for i, s in enumerate(g.stations):
        if not 0 < s < g.length:
            return f"stations[{i}]", (f"{metres(s)} is off the beam; must lie between 0 and the free length "
                                      f"{_mm(g.length)}")
    if any(b <= a for a, b in zip(g.stations, g.stations[1:])):
        return "stations", f"{[round(float(s) * 1e3, 6) for s in g.stations]} mm must increase from the clamp outwards"
    return None


def pocket_reach(g: Geometry) -> tuple:
    """How deep a pocket or flat may be before the part is no beam, and what that is: a tube's
    wall, or half the section height (numbers or arrays)."""
    return (g.wall, "the tube wall") if g.section == "tube" else (g.size / 2, "half the section height")


def no_beam(g: Geometry) -> np.ndarray:
    """``unbuildable``'s rules of the sizes, for each design of ``g`` (numbers or arrays, as the
    tolerance corners build them): a pocket or flat as deep as ``pocket_reach``, a hole as wide as
    the section, a tube's wall as thick as its radius. A pocket or hole of no depth is a plain
    section here (a tolerance corner leaves it uncut); the beam model still gives numbers past
    these (a flat past a round bar's centre), but no part has them."""
    size = np.asarray(g.size, dtype=float)
    lost = np.zeros(np.shape(size), dtype=bool)
    if g.section == "tube":
        lost |= np.asarray(g.wall, dtype=float) >= size / 2
    if g.feature == "pocket":
        lost |= np.asarray(g.depth, dtype=float) >= np.asarray(pocket_reach(g)[0], dtype=float)
    elif g.feature == "hole":
        lost |= np.asarray(g.hole, dtype=float) >= size
    return lost


def stations_before_load(stations, x_min: float) -> tuple[str, str] | None:
    """``("stations", reason)`` when the last station is not before the operating region, which
    starts at ``x_min``: a bridge at or past the load reads no moment of it, and the estimator's
    ``V_i = k_i F (x - d_i)`` (docs/model.md §3) no longer holds; None otherwise."""
    if stations[-1] < x_min:
        return None
    return "stations", (f"the last station ({_mm(stations[-1])}) must lie before the operating region, which "
                        f"starts at {_mm(x_min)}")


def features_apart(stations, length, l_f, feature: str) -> tuple[str, str] | None:
    """The first station whose feature (of length ``l_f`` along the beam: a pocket, a hole, or the
    gauge on a plain surface) crosses the clamp face or the free end, or overlaps its neighbour's,
    as ``(key, reason)`` with the design.json key under ``design``; None when each has its own
    length of beam. The model's sections and the CAD's cuts assume so."""
    what = {"pocket": "pocket", "hole": "hole", "none": "gauge"}[feature]
    lo, hi = l_f / 2, length - l_f / 2
    for i, s in enumerate(stations):
        if not lo < s < hi:
            return f"stations[{i}]", (f"{metres(s)} is off the beam: with its {_mm(l_f)} {what} it must lie between "
                                      f"{_mm(lo)} and {_mm(hi)} from the clamp face (free length {_mm(length)})")
    for i in range(len(stations) - 1):
        if not stations[i + 1] - stations[i] > l_f:
            return f"stations[{i + 1}]", (f"{metres(stations[i + 1])} is too close to station {i} at "
                                          f"{_mm(stations[i])}: the {_mm(l_f)} {what}s would overlap; stations "
                                          f"must increase by more than {_mm(l_f)}")
    return None


class Widened:
    """A Geometry whose reduced spans are ``delta`` longer (``delta/2`` at each end); ``delta`` one
    length for every span, or a tuple of one per span."""

    def __init__(self, g: Geometry, delta):
        self._g, self._delta = g, delta

    def __getattr__(self, name):
        return getattr(self._g, name)

    @property
    def reduced_spans(self) -> tuple:
        spans = self._g.reduced_spans
        deltas = self._delta if isinstance(self._delta, tuple) else (self._delta,) * len(spans)
        return tuple((a - d / 2, b + d / 2) for (a, b), d in zip(spans, deltas))
