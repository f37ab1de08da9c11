"""Where the feature corrections hold (docs/model.md §7): the box of each family's 3-D study as
bounds on a design's dimensionless geometry, which ``model.limits`` makes the ``domain_…`` limits,
and the shortest pocket the fits allow, which the search makes a pocket at least as long as."""

from __future__ import annotations

import math

from designer.model.corrections import (CLAMP_NEAR, GAP_RATES, Corrections, clamp_fit, clamp_ratios, family,
                                        parameters, station_ratios, station_width_ratios, stiffness_fit)
from designer.model.ops import ops_for
from designer.model.sections import Geometry

# The domain bound of the first station's feature's distance from the clamp face in section sizes
# (``clamp_ratios``): the study put no feature nearer the clamp than its fits' ``clamp_ratio``.
NEAR_CLAMP_BOUND = "clamp_ratio_1"


# The domain bound of the first station's (gauge grid centre's) distance from the clamp face in
# section sizes (``station_ratios``), which the near-clamp fits' decays are fitted over.
NEAR_STATION = "station_ratio"


# A plain rectangular bar's first station near the clamp (``rectangle-none``): the clamp face's own
# restraint lowers the gauge strain over about the larger of the bar's height and width, beyond
# what the clamp fit (``ClampFit``: the plate effect of a wide bar, studied on bars 2-16 times as
# wide as high, 3 mm high) gives. A tall bar's station 0.3 heights out reads 2.4 % under the
# model, a square bar's 5 %, a 2:1 bar's 0.5 widths out 1 % (benchmarks/plain_clamp_check.md).
# The first station stays at least PLAIN_STATION_MIN times ``plain_clamp_scale`` from the clamp
# face, where the 3-D check reads the model within the clamp fit's left-out error.
PLAIN_STATION = "plain_station"
PLAIN_STATION_MIN = 0.65
# The scale is min(max(b, h), cap h): from a 4:1 bar out the clamp fit holds from a quarter width
# (its own domain), so the bound is not to grow with a wide plate's width.
PLAIN_STATION_CAP = 3.0


def plain_clamp_scale(width, height):
    """``min(max(b, h), PLAIN_STATION_CAP h)`` of a rectangular bar: what its first plain station's
    distance from the clamp face is measured in (``PLAIN_STATION``)."""
    ops = ops_for(width, height)
    return ops.fmin(ops.fmax(width, height), PLAIN_STATION_CAP * height)


def station_bound_name(i: int) -> str:
    """The domain bound of station ``i``'s (0-based) distance from the clamp over the width."""
    return f"station_width_ratio_{i + 1}"


# A pocket's length over its gauge's grid length, ``l_p / grid_length``. The pocket study sampled it
# in this box (``checks.study``'s ``lp_grid``: the catalogue's gauges with the spec's pocket margins
# give 2.4-4), and the fits' parameters do not bound it: a flat 0.4 D long under a grid 0.036 D long
# (a Ø87 mm bar under a 3.18 mm grid, 11 grid lengths) has its depth, length and grid gaps inside
# their ranges, yet no study point is like it. A shorter grid on the same pocket reads -1.5 % to
# +0.7 % of what the study's grid reads, 4 to 10 grid lengths long, and at the round flats' corner
# that tips the model's error over the 3-D check's 2 % (benchmarks/grid_length_study.md). Designs
# keep under the box's top, but for LP_GRID_TOP's families (benchmarks/grid_length_study.md):
# a tube's flat, from one diameter long, 8 (its gauge strain is nearly level along the flat, and a
# shorter grid on the same flat, 4-8 grid lengths long, reads within 0.4 % of the study's grid);
# a round bar's flat 6 (25 round flats 4-6 grid lengths long, short ones and near the clamp among
# them, read within 0.75 % of the model, and the Ø87 mm corner design 1.014-1.015 at 5 and 6,
# where it read 1.027 at 11).
LP_GRID = "lp_grid"
LP_GRID_BOX = (2.4, 4.0)
LP_GRID_TOP = {"tube-pocket": 8.0, "round-pocket": 6.0}


# A pocket's sharpness against the sharpest the study had at its depth: ``notch_ratio`` (sqrt(p/r))
# under each line through two consecutive vertices of the rising part of the upper hull of the K_t
# fit's study points in (depth_ratio, notch_ratio), the fit's ``notch_top``: one limit per line,
# ``domain_notch_hull_<k>_max``, linear in the two ratios (a minimum of the lines, or a ratio to
# it, has kinks and poles that stalled nlopt's COBYLA for good). The box bounds each parameter
# alone, while the study's sharp radii are on the deeper pockets (a slot's notch_ratio to 3.0 at
# 0.066 h deep, to 4.8 at 0.28 h): a sharp corner radius on a shallow pocket is inside the box but
# far from any point the fit was made on. The greatest notch is the box's own bound.
NOTCH_HULL = "notch_hull"


def upper_hull(points) -> tuple:
    """The rising part of the upper convex hull of ``points`` (x, y), as vertices from the least x
    to the greatest y: below the lines through consecutive vertices lies every point."""
    hull = []
    for p in sorted(set((float(x), float(y)) for x, y in points)):
        while len(hull) >= 2 and ((hull[-1][0] - hull[-2][0]) * (p[1] - hull[-2][1])
                                  - (hull[-1][1] - hull[-2][1]) * (p[0] - hull[-2][0])) >= 0:
            hull.pop()
        hull.append(p)
    top = max(range(len(hull)), key=lambda i: hull[i][1])
    return tuple(hull[:top + 1])


def notch_lines(depth_ratio, vertices) -> list:
    """The notch_ratio at ``depth_ratio`` of each line through consecutive ``vertices``
    (``upper_hull``): a pocket is no sharper than the study's at its depth where it is under all of
    them (a number or an expression, as ``depth_ratio``)."""
    return [y0 + (y1 - y0) / (x1 - x0) * (depth_ratio - x0) for (x0, y0), (x1, y1) in zip(vertices, vertices[1:])]


def notch_hull_name(k: int) -> str:
    """The bound of the ``k``-th line of ``notch_lines`` (from 1): ``notch_hull_<k>``."""
    return f"{NOTCH_HULL}_{k}"


def notch_top(depth_ratio, vertices):
    """The sharpest ``notch_ratio`` the study had at ``depth_ratio``: the least of the lines through
    the consecutive ``vertices`` (``upper_hull``), and their greatest notch (a number or an
    expression, as ``depth_ratio``)."""
    ops = ops_for(depth_ratio)
    out = vertices[-1][1]
    for line in notch_lines(depth_ratio, vertices):
        out = ops.fmin(out, line)
    return out


def lp_grid_top(fam: str) -> float:
    """The most gauge grids a pocket of family ``fam`` may be long (``domain_lp_grid_max``)."""
    return LP_GRID_TOP.get(fam, LP_GRID_BOX[1])


def domain_box(fam: str, table: Corrections) -> dict:
    """``{parameter: (low, high)}``: where every fit of family ``fam`` holds (where fits share a
    parameter, inside all of their ranges); the first station's clamp ratio as ``NEAR_CLAMP_BOUND``."""
    box = {}
    for quantity in ("strain", "extra_length", "stress", "stress_face", "near_clamp"):
        fit = table.fit(fam, quantity)
        for name, (lo, hi) in (fit.domain.items() if fit is not None else ()):
            if name == CLAMP_NEAR:      # the same bound as the first feature's clamp ratio's
                continue
            name = NEAR_CLAMP_BOUND if name == "clamp_ratio" else name
            old_lo, old_hi = box.get(name, (lo, hi))
            box[name] = (max(lo, old_lo), min(hi, old_hi))
    return box


def least_pocket_length(g: Geometry, table: Corrections):
    """The shortest pocket (slot or flat) of ``g``'s section that its family's fits hold for: the
    domain's least ``length_ratio`` times the section size and, where the fits read the gauge grid's
    gap to the flat's ends (``grid_gap_decays``), the gap their largest decays allow; 0 without
    fits or without a pocket (a number, an array or a casadi expression, as ``g``'s sizes)."""
    if g.feature != "pocket":
        return 0.0
    box = domain_box(family(g), table)
    size, ops = g.size, ops_for(g.size)
    out = 0.0
    lo = box.get("length_ratio", (-math.inf, math.inf))[0]
    if math.isfinite(lo) and lo > 0:
        out = ops.fmax(out, lo * size)
    for name, rate in GAP_RATES.items():    # exp(-k (l - l_grid) / (2 size)) <= high
        high = box.get(name, (-math.inf, math.inf))[1]
        if 0 < high < 1:
            out = ops.fmax(out, g.grid_length + 2 * size * math.log(1 / high) / rate)
    return out


def domain_bounds(g: Geometry, table: Corrections) -> list[tuple]:
    """``(name, value, low, high)`` for every parameter a fit of ``g``'s family uses: the design must
    stay inside the box the study covered (infinite bounds are open). Clamp ratios per station; the
    first feature no nearer the clamp than the study's (``NEAR_CLAMP_BOUND``); a pocket no more grid
    lengths long than the study's (``LP_GRID``); a pocket no sharper than the study's at its depth
    (``NOTCH_HULL``: one bound per hull line, whose high is the line's notch at the pocket's depth)."""
    # a fit's clamp_ratio bounds the first station's (the others are further out)
    values = {**parameters(g), NEAR_CLAMP_BOUND: clamp_ratios(g)[0], NEAR_STATION: station_ratios(g)[0]}
    box = domain_box(family(g), table)
    out = [(name, values[name], lo, hi) for name, (lo, hi) in box.items()]
    if g.feature == "pocket" and box and g.grid_length > 0:
        out.append((LP_GRID, g.feature_length / g.grid_length, -math.inf, lp_grid_top(family(g))))
    vertices = getattr(table.fit(family(g), "stress"), "notch_top", ())
    if "notch_ratio" in values:
        out += [(notch_hull_name(k), values["notch_ratio"], -math.inf, line)
                for k, line in enumerate(notch_lines(values["depth_ratio"], vertices), start=1)]
    clamp = clamp_fit(table)
    if clamp is not None:
        for name, (lo, hi) in clamp.domain.items():
            if name == "station_width_ratio":
                out += [(station_bound_name(i), u, lo, hi) for i, u in enumerate(station_width_ratios(g))]
            elif all(name != o[0] for o in out):
                out.append((name, values[name], lo, hi))
    if family(g) == "rectangle-none" and clamp is not None:
        out.append((PLAIN_STATION, g.stations[0] / plain_clamp_scale(g.width, g.height), PLAIN_STATION_MIN, math.inf))
    stiffness = stiffness_fit(table)
    if stiffness is not None:
        values["slenderness"] = g.length / g.size
        out += [(name, values[name], lo, hi) for name, (lo, hi) in stiffness.domain.items()
                if all(name != o[0] for o in out)]
    return out
