"""Every limit a design must meet, in the optimiser's normalised form (docs/model.md §1, §4)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from designer.model.analysis import fatigue_factor, notch_sensitivity
from designer.model.electronics import volts_per_strain
from designer.model.grooves import LIMIT_NAMES as GROOVE_LIMITS, ROOT_RADIUS, WIDTH as GROOVE_WIDTH, groove_stress
from designer.model.grooves import DEPTH_FRACTION as GROOVE_DEPTH_FRACTION, depth as groove_depth
from designer.model.grooves import positions as groove_positions, smaller_side as groove_smaller_side
from designer.model.objective import FEASIBILITY_TOLERANCE
from designer.model.ops import NUMERIC, Ops, clipped_root
from designer.model.sections import LEAST_CUT, Geometry, feature_length

# Constraints whose normalised slack is below this bind (0.5 % of the limit).
ACTIVE_TOLERANCE = 5e-3
TARGET_LIMITS = ("force_error", "position_error")
# The limits of the sensor's duty (the load, the material, the electronics and the targets); the
# others are the geometry's own rules, which some design of the section meets whatever the duty.
DUTY_LIMITS = ("stress_root", "stress_feature", "fatigue_feature", "gauge_strain", "min_signal_snr", "adc_range",
               "deflection", "natural_frequency", *TARGET_LIMITS)
# Of the geometry's rules, the section's sizes the spec allows (limits.width and limits.height): the
# room the sensor is built into, which a closest design of an infeasible spec keeps before the others.
SIZE_LIMITS = ("width_min", "width_max", "height_min", "height_max", "diameter_min", "diameter_max")
# Neighbouring holes at least this many section heights apart, edge to edge: two Ø0.43 h holes in
# a 0.3:1 bar 0.15 h apart read +6 % and -3 % of the isolated holes' gauge strain in 3-D, 0.4 h
# apart within 0.6 % (tests/validation/test_corrections_study.py).
HOLE_GAP = 0.5
# Neighbouring slots and round flats at least this many section sizes apart, end to end: a pair
# 0.05 sizes apart reads 2-3 % below the isolated pair's gauge strain in 3-D, 0.5 apart within
# 0.8 % (benchmarks/feature_gap_study.py; the corrections' fits are of features 4 sizes apart).
# A middle one of three, with a neighbour on each side 0.5 sizes apart, reads at most 0.5 % (flats)
# and 1.2 % (slots 0.28 h deep) below its isolated self, 3-D/model at least 0.993: inside the rooms
# u_eps of the fits (1.3 %, 3.4 %; benchmarks/neighbour_study.py).
# Flats on tubes, made at least a diameter long, read within 0.2 % at any gap: no limit.
POCKET_GAP = 0.5
# ... and slots at least this many bar widths apart too: past a slot the load flows back from its
# side walls over about the bar's width, so in a wide bar neighbours half a height apart read each
# other (slots 1.1 heights wide, 0.5 heights apart: -0.9 % in a 3.6:1 bar, -1.7 % in a 5.2:1 bar,
# -2.8 % in an 8:1 bar; a quarter width apart, 3.6-8:1 bars within 0.7 %: benchmarks/feature_gap_study.py --wide).
SLOT_WIDTH_GAP = 0.25


@dataclass(frozen=True)
class Limit:
    """One limit: ``value <= limit`` (``upper``) or ``value >= limit``, in SI.

    ``normalised`` is the optimiser's ``g <= 0`` form: ``value/limit - 1`` (or ``1 - value/limit``);
    limits at zero are scaled by ``scale`` instead. ``rating``, where given, is the limit the built
    part must meet, of which ``limit`` keeps room for the model's own uncertainty (the 3-D check
    holds its figures to ``rating``).
    """

    name: str
    value: Any
    limit: Any
    upper: bool = True
    scale: Any = None
    unit: str = ""
    rating: Any = None

    @property
    def part_limit(self):
        """The limit the built part must meet: ``rating``, or ``limit`` where the model keeps no room."""
        return self.limit if self.rating is None else self.rating

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
                "satisfied": bool(float(self.normalised) <= FEASIBILITY_TOLERANCE), "unit": self.unit}


def limits(g: Geometry, a, m, spec, include_targets: bool = True,
           ops: Ops = NUMERIC, table=None, rules: bool = True) -> list[Limit]:
    """Every limit of docs/model.md §4 and the geometry rules of §1 (``rules=False``: the limits of
    §4 alone, without the section's sizes and manufacturing rules and the fits' domain, which a
    tolerance corner does not judge)."""
    from designer.model import corrections, poisson

    lim, load = spec.limits, spec.load
    mm = 1e-3  # scale for geometric rules whose limit may be zero
    d = list(g.stations)
    l_f = g.feature_length
    table = corrections.load() if table is None else table
    # the strain-borne limits, the deflection and the fatigue limit at a feature keep room for the
    # corrections' own uncertainty (docs/model.md §4, §7), and for the material's Poisson's ratio
    allowance = corrections.strain_allowance(g, table) + poisson.strain_room(corrections.family(g), m.poisson, ops)
    out = [
        Limit("stress_root", a.stress_root, m.allowable, unit="Pa"),
        Limit("stress_feature", a.stress_feature, m.static_allowable, unit="Pa"),
        Limit("gauge_strain", a.gauge_strain[0], spec.gauge.max_strain / (1 + allowance), unit="strain",
              rating=spec.gauge.max_strain),
        Limit("min_signal_snr", a.min_signal_snr, lim.min_snr * (1 + allowance), upper=False, rating=lim.min_snr),
        Limit("clamp_clearance", d[0] - l_f / 2, lim.clamp_clearance, upper=False, scale=mm, unit="m"),
        # the room kept between the last feature's end and the load region (or the first groove's edge)
        Limit("load_clearance", load.position_min - d[-1] - l_f / 2, lim.load_clearance, upper=False, scale=mm,
              unit="m"),
    ]
    if spec.cad.load_grooves and (first := min(groove_positions(spec))) - GROOVE_WIDTH / 2 < load.position_min:
        # the first groove's edge before the load region: the load clearance is kept from it as from
        # the load (the groove is a notch of its own, and the CAD cuts it beyond the last feature)
        out.append(Limit("groove_clearance", first - GROOVE_WIDTH / 2 - d[-1] - l_f / 2, lim.load_clearance,
                         upper=False, scale=mm, unit="m"))
    front_end = spec.front_end_noise
    if front_end is not None:
        # the bridge's output at F_max, x_max (station 1, the largest) inside the front-end's input range
        signal = volts_per_strain(spec.electronics.excitation, spec.gauge.factor, 1.0, spec.bridge_factor) * \
            a.gauge_strain[0]
        out.append(Limit("adc_range", signal, front_end.full_scale / (1 + allowance), unit="V",
                         rating=front_end.full_scale))
    if lim.fatigue and g.feature != "none":
        room = corrections.stress_allowance(g, table)
        out.append(Limit("fatigue_feature", a.stress_fatigue, m.allowable / (1 + room), unit="Pa", rating=m.allowable))
    groove = groove_stress(g, spec, ops)
    if groove is not None:   # the load grooves of cad.load_grooves: static and fatigue as at a feature
        nominal, kt = groove
        static, fatigue = GROOVE_LIMITS
        out.append(Limit(static, nominal, m.static_allowable, unit="Pa"))
        if lim.fatigue:
            factor = fatigue_factor(notch_sensitivity(ROOT_RADIUS, m.notch_length), kt)
            out.append(Limit(fatigue, factor * nominal, m.allowable, unit="Pa"))
    out += [Limit(f"station_gap_{i + 1}", d[i + 1] - d[i], l_f + lim.gauge_gap, upper=False, scale=mm, unit="m")
            for i in range(len(d) - 1)]
    if g.feature == "hole" or (g.feature == "pocket" and g.section != "tube"):
        # the web between neighbouring features: the fits are of isolated ones (docs/model.md §7)
        webs = [(f"{g.feature}_gap", (HOLE_GAP if g.feature == "hole" else POCKET_GAP) * g.size)]
        if g.feature == "pocket" and g.section == "rectangle":
            webs.append(("slot_width_gap", SLOT_WIDTH_GAP * g.width))
        out += [Limit(f"{name}_{i + 1}", d[i + 1] - d[i] - l_f, least, upper=False, scale=mm, unit="m")
                for name, least in webs for i in range(len(d) - 1)]
    if lim.max_deflection is not None:
        room = corrections.deflection_allowance(g, table) + poisson.deflection_room(corrections.family(g), m.poisson,
                                                                                      ops)
        out.append(Limit("deflection", a.deflection, lim.max_deflection / (1 + room), unit="m",
                         rating=lim.max_deflection))
    if lim.min_frequency is not None:
        out.append(Limit("natural_frequency", a.natural_frequency, lim.min_frequency, upper=False, unit="Hz"))
    if include_targets:
        # the errors scale as 1/strain: a gauge strain up to ``allowance`` below the corrected
        # model's in 3-D raises them by as much, so the targets keep that room too
        out += [Limit("force_error", a.force_error, spec.targets.force_error / (1 + allowance),
                      rating=spec.targets.force_error),
                Limit("position_error", a.position_error, spec.targets.position_error / (1 + allowance), unit="m",
                      rating=spec.targets.position_error)]
    if rules:
        out += section_limits(g, spec, ops)
        out += domain_limits(g, table, spec)
    return out


def domain_limits(g: Geometry, table=None, spec=None) -> list[Limit]:
    """The fitted domain of the feature corrections (docs/model.md §7) as limits on the
    dimensionless geometry: ``domain_<parameter>_min`` and ``_max``. With the ``spec``, a station's
    distance from the clamp over the width is left out where the clamp clearance already keeps
    every station far enough out for the widest section the spec allows: an idle constraint
    only makes the optimiser's path harder."""
    from designer.model import corrections, domain

    table = corrections.load() if table is None else table
    stations = {domain.station_bound_name(i): d for i, d in enumerate(g.stations)}
    out = []
    for name, value, lo, hi in domain.domain_bounds(g, table):
        if name in stations and math.isfinite(lo) and not math.isfinite(hi):
            if spec is not None and _clamp_room(g, spec) >= lo * _widest(g, spec):
                continue
            # d_i >= lo b, linear in the sizes
            out.append(Limit(f"domain_{name}_min", stations[name], lo * g.breadth, upper=False, scale=1e-3,
                             unit="m"))
            continue
        if name == domain.LP_GRID and spec is not None and not _is_number(g.feature_length) \
                and _longest_pocket(g, spec, table) <= hi * g.grid_length:
            continue    # idle in the search: no section the spec allows needs a pocket that long
        if name == domain.NEAR_STATION:
            # d_1 >= lo h (or D), linear in the sizes
            out.append(Limit(f"domain_{name}_min", g.stations[0], lo * g.size, upper=False, scale=1e-3, unit="m"))
            continue
        if name == domain.PLAIN_STATION:
            # d_1 >= lo min(max(b, h), cap h)
            out.append(Limit(f"domain_{name}_min", g.stations[0], lo * domain.plain_clamp_scale(g.width, g.height),
                             upper=False, scale=1e-3, unit="m"))
            continue
        if name == domain.NEAR_CLAMP_BOUND:
            # d_1 - l_f/2 >= lo h (or D), linear in the sizes
            start = g.stations[0] - g.feature_length / 2
            out.append(Limit(f"domain_{name}_min", start, lo * g.size, upper=False, scale=1e-3, unit="m"))
            continue
        if name.startswith(domain.NOTCH_HULL):
            # notch_ratio <= a hull line's at the depth, linear in both ratios; the line may be
            # below zero far under the study's least depth, so the gap itself is the row (ratios 1.5-7)
            out.append(Limit(f"domain_{name}_max", value, hi, scale=1.0))
            continue
        if math.isfinite(lo):
            out.append(Limit(f"domain_{name}_min", value, lo, upper=False, scale=max(abs(lo), 0.1)))
        if math.isfinite(hi):
            out.append(Limit(f"domain_{name}_max", value, hi, scale=max(abs(hi), 0.1)))
    return out


def _clamp_room(g: Geometry, spec) -> float:
    """The nearest a first station may come to the clamp face (the clamp-clearance limit); for a
    pocket, with the shortest one the spec allows (a searched pocket may be longer where the
    corrections need it, ``search.problem.pocket_as_needed``: the same rows for the numeric model
    and the NLP, whose length is an expression)."""
    if g.feature == "pocket":
        least = smallest_feature_length(spec, "pocket")
        if _is_number(g.feature_length):    # a fixed design's pocket may be shorter than the rule
            least = min(least, float(g.feature_length))
        return spec.limits.clamp_clearance + least / 2
    return spec.limits.clamp_clearance + float(g.feature_length) / 2 if _is_number(g.feature_length) else 0.0


def _longest_pocket(g: Geometry, spec, table) -> float:
    """The longest pocket the search may give ``g``'s family under the spec: the rule's, or what the
    corrections need on the largest section the spec allows (``domain.least_pocket_length`` grows
    with the size), with room for the search's excess over that: its smooth maximum adds at most
    half of ``search.problem.POCKET_SMOOTHING`` (0.01) of the rule, rounding up one 0.01 mm step."""
    from dataclasses import replace

    from designer.model import domain

    largest = spec.limits.height[1] if g.section == "rectangle" else min(spec.limits.width[1], spec.limits.height[1])
    big = replace(g, **({"height": largest} if g.section == "rectangle" else {"diameter": largest}))
    rule = smallest_feature_length(spec, "pocket")
    return max(rule, float(domain.least_pocket_length(big, table))) + 0.01 * rule + 1e-5


def _widest(g: Geometry, spec) -> float:
    """The widest section (b, or D) the spec's size limits allow."""
    lim = spec.limits
    return lim.width[1] if g.section == "rectangle" else min(lim.width[1], lim.height[1])


def _is_number(value) -> bool:
    return isinstance(value, (int, float))


def worst_normalised(limits: list[Limit], n: int) -> np.ndarray:
    """The largest normalised value of ``limits`` for each of ``n`` designs evaluated at once
    (numeric arrays; a limit that does not vary is broadcast)."""
    worst = np.full(n, -np.inf)
    for lim in limits:
        np.maximum(worst, lim.normalised, out=worst)
    return worst


def shallowest_pocket(spec) -> float:
    """The least depth of a pocket or flat (m): ``limits.min_pocket_depth``, and a step of the
    0.01 mm grid deeper than a given ``cad.channel_depth`` and than the end mill's
    ``cad.corner_radius``, which the CAD cuts in no shallower pocket."""
    return pocket_floors(spec)[0][0]


def pocket_floors(spec) -> list[tuple[float, str, float]]:
    """What sets a pocket's least depth, deepest first: ``(least depth (m), spec key, its value
    (m))`` for ``limits.min_pocket_depth``, ``cad.corner_radius`` and a given
    ``cad.channel_depth``."""
    cad = spec.cad
    out = [(spec.limits.min_pocket_depth, "limits.min_pocket_depth", spec.limits.min_pocket_depth),
           (cad.corner_radius + LEAST_CUT, "cad.corner_radius", cad.corner_radius)]
    if cad.wire_channels and cad.channel_depth:
        out.append((cad.channel_depth + LEAST_CUT, "cad.channel_depth", cad.channel_depth))
    return sorted(out, key=lambda floor: -floor[0])


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
    if spec.cad.load_grooves:   # the CAD's rules for the grooves' depth (docs/spec.md 2.8)
        t = groove_depth(g, spec, ops)
        if spec.cad.groove_depth is not None:   # (the default is at most the share itself)
            out.append(Limit("groove_depth", t, GROOVE_DEPTH_FRACTION * groove_smaller_side(g, ops), unit="m"))
        if g.section == "tube":
            out.append(Limit("groove_wall", g.wall - t, lim.min_wall, upper=False, unit="m"))
    if g.feature == "pocket":
        size = g.size
        out += [Limit("pocket_depth_min", g.depth, shallowest_pocket(spec), upper=False, unit="m"),
                Limit("pocket_depth_max", g.depth, lim.max_pocket_fraction * size, scale=lim.max_pocket_fraction * mm,
                      unit="m")]
        if g.section == "rectangle":
            out.append(Limit("pocket_side_wall", (g.width - g.pocket_width) / 2, lim.min_wall, upper=False, unit="m"))
            if g.axes == 2:  # side slots must not reach the top and bottom slots
                out.append(Limit("pocket_corner", g.depth + g.pocket_width / 2, g.width / 2 - lim.min_wall,
                                 scale=mm, unit="m"))
        else:
            R = g.diameter / 2
            half_chord = clipped_root(R * R - (R - g.depth) ** 2, ops)
            out.append(Limit("flat_chord", 2 * half_chord, g.pocket_width, upper=False, unit="m"))
            if g.axes == 2:  # neighbouring flats must not meet
                out.append(Limit("flat_corner", half_chord, R - g.depth, scale=mm, unit="m"))
            if g.section == "tube":
                out.append(Limit("flat_wall", g.depth, g.wall - lim.min_wall, scale=mm, unit="m"))
    if g.feature == "hole":
        out += [Limit("hole_ligament", (g.height - g.hole) / 2, lim.min_wall, upper=False, unit="m"),
                Limit("hole_min", g.hole, lim.min_wall, upper=False, unit="m")]
    if g.feature != "pocket":
        # the gauge's backing lies on the face it reads (a pocket's or flat's own limits see to it
        # there): a rectangle's face at least as wide, a round surface at least as wide across
        face = g.width if g.section == "rectangle" else g.diameter
        out.append(Limit("gauge_face", face, spec.gauge.width, upper=False, unit="m"))
        if g.section == "rectangle" and g.axes == 2:
            out.append(Limit("gauge_face_side", g.height, spec.gauge.width, upper=False, unit="m"))
    return out


def smallest_feature_length(spec, feature: str):
    """The shortest l_f the spec allows for ``feature``: a hole no narrower than ``min_wall``."""
    return feature_length(feature, spec.pocket_size()[0], spec.limits.min_wall, spec.gauge.length)


def minimum_room(spec, feature: str | None = None) -> float:
    """The least length from the clamp face to the end of the last gauge feature that the stations
    need (the geometry rules of docs/model.md §1), to be set against ``grooves.stations_end``."""
    lim, n = spec.limits, spec.stations
    lf = smallest_feature_length(spec, feature or spec.search.feature)
    return lim.clamp_clearance + n * lf + (n - 1) * lim.gauge_gap
