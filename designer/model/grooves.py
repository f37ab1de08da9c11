"""The load grooves' stress (docs/model.md §4): with ``cad.load_grooves``, U-grooves all around
the beam at the load positions, each a notch of the groove's depth ``t`` with half its width as
root radius ``r``, in the section left under it.

The groove nearest the clamp carries the largest moment, ``F_max (x_max - x_g)``; its nominal
stress is ``M c / I`` of the net section (a round bar's ``D - 2t``; a tube's outer diameter
``D - 2t`` over its bore; a rectangle's ``(b - 2t) x (h - 2t)``, the groove running over all
four faces), and its peak ``K_t`` times that. ``K_t`` is Roark's (W. C. Young and R. G. Budynas,
Roark's Formulas for Stress and Strain, 7th ed., Table 17.1): a U-notch in a circular shaft in
bending for round bars and tubes (for a tube an approximation: the chart is of a solid shaft),
two opposite U-notches in a rectangular bar in in-plane bending for rectangles, each
``K_t = C1 + C2 (2t/D) + C3 (2t/D)^2 + C4 (2t/D)^3`` with ``C_i = a + b sqrt(t/r) + c t/r`` on
``0.25 <= t/r <= 2`` and ``2 <= t/r <= 50`` (``D`` the section's size in the load direction); a
groove shallower than ``t/r = 0.25`` is taken at it; times ``FACTOR_3D``, the 3-D check's figures.
"""

from __future__ import annotations

import math

from designer.model.ops import NUMERIC, Ops
from designer.model.sections import Geometry

# The CAD's grooves: 0.5 mm wide holds the "very thin string" the paper hung its masses from; by
# default 0.3 mm deep or 5 % of the section's smaller side, whichever is less (docs/spec.md 2.8)
WIDTH = 0.5e-3
DEPTH = 0.3e-3
DEPTH_FRACTION = 0.05
ROOT_RADIUS = WIDTH / 2
# Roark's Table 17.1: (a, b, c) of C1..C4 on t/r <= 2 and on t/r >= 2
SHAFT = (((0.455, 3.354, -0.769), (0.891, -12.721, 4.593), (0.286, 15.481, -6.392), (-0.632, -6.115, 2.568)),
         ((0.935, 1.922, 0.004), (-0.552, -5.327, 0.086), (0.754, 6.281, -0.121), (-0.138, -2.876, 0.031)))
BAR = (((0.723, 2.845, -0.504), (-1.836, -5.746, 1.314), (7.254, -1.885, 1.646), (-5.140, 4.785, -2.456)),
       ((0.833, 2.069, -0.009), (0.024, -5.383, 0.126), (-0.856, 6.460, -0.199), (0.999, -3.146, 0.082)))
LEAST_RATIO, SPLIT_RATIO = 0.25, 2.0
# Roark's K_t times the 3-D check's (benchmarks/groove_kt_check.md: a submodel of the groove in pure
# bending, its root meshed to r/18-r/24 and converged within 0.2 %): a rectangle's 1.81, where
# its top and side grooves' roots meet at the section's edges, which the chart's two opposite
# notches leave out (a square, a flat and a tall bar: 1.80, 1.69, 1.63); a round bar's 0.98-1.04
# (rounded up to 1.05 for the runs' scatter); a tube takes the round bar's (three tubes, thick and
# thin-walled, read 0.98-0.99).
FACTOR_3D = {"rectangle": 1.81, "round": 1.05, "tube": 1.05}
# The limits model.limits judges the grooves by (docs/model.md §4)
LIMIT_NAMES = ("stress_groove", "fatigue_groove")


def default_positions(x_min: float, x_max: float) -> tuple:
    """Where the grooves are when ``cad.groove_positions`` is not given (m from the clamp face):
    ``x_min``, the middle of the load range and ``x_max``."""
    return x_min, (x_min + x_max) / 2, x_max


def positions(spec) -> tuple:
    """Where a spec's grooves are: ``cad.groove_positions``, or ``default_positions``."""
    if spec.cad.groove_positions:
        return tuple(spec.cad.groove_positions)
    return default_positions(spec.load.position_min, spec.load.position_max)


def overlapping(at) -> tuple | None:
    """The first two of the sorted positions ``at`` (m) that are not more than a groove's width
    apart (grooves exactly a width apart are one groove twice as wide), or None."""
    return next(((a, b) for a, b in zip(at, at[1:]) if not b - a > WIDTH + 1e-9), None)


def stations_end(spec) -> float:
    """Where the last gauge feature must end (m from the clamp face): ``limits.load_clearance``
    before the load region and, with load grooves, before the first groove's edge (docs/model.md
    §1), which the CAD cuts between the last feature and the free end."""
    first = min(positions(spec)) - WIDTH / 2 if spec.cad.load_grooves else spec.load.position_min
    return min(spec.load.position_min, first) - spec.limits.load_clearance


def default_depth(smaller_side, ops: Ops = NUMERIC):
    """The grooves' depth when ``cad.groove_depth`` is not given, before the CAD rounds it down to
    the 0.01 mm grid: 0.3 mm or 5 % of the section's smaller side, whichever is less."""
    return ops.fmin(DEPTH, DEPTH_FRACTION * smaller_side)


def cut_depth(smaller_side: float) -> float:
    """The default depth as the CAD cuts it: ``default_depth`` rounded down to the 0.01 mm grid
    (the model takes it unrounded, up to 0.01 mm deeper)."""
    from designer.model.sections import round_down

    return round_down(float(default_depth(smaller_side)), 1e-5)


def smaller_side(g: Geometry, ops: Ops = NUMERIC):
    """The section's smaller side (a round bar's or tube's diameter), of which the groove may take
    DEPTH_FRACTION."""
    return ops.fmin(g.width, g.height) if g.section == "rectangle" else g.diameter


def depth(g: Geometry, spec, ops: Ops = NUMERIC):
    """The grooves' depth on ``g``: ``cad.groove_depth``, or ``default_depth``."""
    given = spec.cad.groove_depth
    return given if given is not None else default_depth(smaller_side(g, ops), ops)


def stress_concentration(section: str, depth, size, ops: Ops = NUMERIC):
    """Roark's ``K_t`` of a groove ``depth`` deep in a section ``size`` across (h or D)."""
    ratio = ops.fmax(depth / ROOT_RADIUS, LEAST_RATIO)
    # the default depth (at most 0.3 mm, t/r 1.2) and any given one, a number, pick the range
    upper = isinstance(depth, (int, float)) and depth / ROOT_RADIUS > SPLIT_RATIO
    rows = (SHAFT if section != "rectangle" else BAR)[1 if upper else 0]
    root = ops.sqrt(ratio)
    c = [a + b * root + k * ratio for a, b, k in rows]
    s = 2 * depth / size
    return c[0] + s * (c[1] + s * (c[2] + s * c[3]))


def groove_stress(g: Geometry, spec, ops: Ops = NUMERIC):
    """``(nominal stress, K_t)`` at the groove nearest the clamp under ``F_max`` at ``x_max``; None
    without grooves or with none inside the load range's reach."""
    if not spec.cad.load_grooves:
        return None
    x_max = spec.load.position_max
    arm = x_max - min(positions(spec))
    if not arm > 0:
        return None
    t = depth(g, spec, ops)
    moment = spec.load.force_max * arm
    if g.section == "rectangle":
        b, h = g.width - 2 * t, g.height - 2 * t
        nominal = moment * (h / 2) / (b * h ** 3 / 12)
    else:
        d = g.diameter - 2 * t
        bore = g.diameter - 2 * g.wall if g.section == "tube" else 0.0
        nominal = moment * (d / 2) / (math.pi * (d ** 4 - bore ** 4) / 64)
    return nominal, FACTOR_3D[g.section] * stress_concentration(g.section, t, g.size, ops)
