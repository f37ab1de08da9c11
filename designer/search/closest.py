"""The closest design of a spec that no design meets: the one its diagnosis reasons from.

A candidate's answer when none of its designs meets every limit is where its solver gave up:
IPOPT's restoration phase, which lowers the sum of the violations of every row at once and so
often buys a lower stress with a pocket shallower than the least allowed, or stations closer
than their gap. Its figures then answer no question a user asks (how much less load, how much
more room). Here each such candidate is solved again in two stages from its own design, with the
geometry's own rules held (every limit but the duty's, ``model.DUTY_LIMITS``): first for the
least worst violation of the duty's limits but the accuracy targets (stress, strain, signal,
deflection, frequency, nominal and at the tolerance corners); when those can all be met, then
for the least worst violation of the targets with every other limit met. Rounded to the grid,
the design is kept when it comes closer by ``closeness``. Each duty limit that scales with the
largest force is then met by that one design at ``load.force[1] / (1 + its violation)``.
"""

from __future__ import annotations

import math
from dataclasses import replace

from designer import model
from designer.errors import InputError
from designer.result.evaluation import Evaluation, evaluate
from designer.search.problem import start_from
from designer.search.rounding import (ANSWER_TOLERANCE, GridBox, broken_rules, buildable, depths_held,
                                      only_targets_missed)
from designer.search.stock import stock_system
from designer.spec import catalogue

# the duty's limits but the accuracy targets
BEARING = tuple(name for name in model.DUTY_LIMITS if name not in model.TARGET_LIMITS)
# Grid steps beyond the neighbouring grid points that the rounding of a closest design reaches,
# one more at a time, for a point meeting the geometry's rules (and the duty's limits but the
# targets, when its answer meets them): its answer is held by several of them at once (the
# stations between both clearances, their gap, a size and the pocket's depth), and a size a step
# smaller gives the stations room (the gripper finger under 300 N: one step).
REACH = 2
# How far inside their limits (normalised) the second stage holds the other limits, in turn, when
# the grid's points around its answer break one: a 0.01 mm step moves a stress or a strain by up
# to 3 s/D (0.35 % on a Ø8.6 mm bar), a 0.05 mm step of a pocket's depth by more.
MARGINS = (0.0, 3e-3, 1e-2, 3e-2)
# How near (relative, on 1 + the normalised violation) two closest designs' worst violations of the
# duty's limits count as one, so that the others decide (``_closest_of``): a 0.01 mm step moves a
# stress or a strain by up to 0.35 % (above).
WORST_TIE = 5e-3


def meets_rules(ev: Evaluation) -> bool:
    """Whether ``ev`` meets every limit but its duty's: the geometry's own rules, at its nominal
    sizes and its tolerance corners."""
    return not broken_rules(ev)


def closeness(ev: Evaluation) -> tuple:
    """How far an infeasible design is from one that meets every limit, least first: a beam at
    all, then one within the sizes the spec allows (``model.SIZE_LIMITS``), then the fewest of
    the geometry's own rules broken (none: ``meets_rules``; a spec may leave no section its gauge
    fits on, and a design breaking that rule need not break others), then the worst violation of
    the duty's limits but the targets (a lower load, a stronger or stiffer material would meet
    them), then the worst of the targets' (less noise, a larger least force), each met counting
    as met, however much room it keeps."""
    tol, broken = model.FEASIBILITY_TOLERANCE, broken_rules(ev)
    bearing = _worst(ev, lambda name: name in BEARING)
    targets = _worst(ev, lambda name: name in model.TARGET_LIMITS)
    return (not buildable(ev), bool(broken & set(model.SIZE_LIMITS)), len(broken), max(bearing, tol),
            max(targets, tol))


def _worst(ev: Evaluation, which) -> float:
    return max((float(lim.normalised) for lim in ev.judged if which(lim.name)), default=-math.inf)


def closest_designs(spec, problems: dict, candidates: list) -> list:
    """``candidates`` (none with a feasible design) with each one whose family is searched over
    continuous sizes solved again for its least violation from its own design, and given that
    design when it comes closer (``closeness``); the IPOPT solves join the candidate's."""
    out = []
    for c in candidates:
        problem = problems.get(c.family)
        ev = c.evaluation
        if (problem is None or ev is None or c.outranked or stock_system(spec, c.family) != "none"
                or only_targets_missed(ev, problem.epigraph)):
            out.append(c)   # (the least error of a family that only misses the targets is its own answer)
            continue
        material = catalogue.material(c.material)
        params = problem.params(material)
        s, worst = problem.least_violation(params, start_from(problem, ev), soft=BEARING, free=model.TARGET_LIMITS)
        solves = [s]
        found = [near for near in [_rounded(problem.design(s.x, material), spec)] if near is not None]
        if worst > model.FEASIBILITY_TOLERANCE:
            # a pocket's depth steps on its grid (cad.depth_step) move the stress and the strain more
            # than the 0.01 mm grid around the answer makes up (seed 13's 036-infeasible-noise: a flat
            # 1.057 -> 1.1 mm deep, its worst violation 13.2 % -> 16.0 %): held at its neighbouring
            # grid values, the rest solved again, as ``ongrid`` does for a design
            for held in depths_held(problem, s.x):
                s2, _ = problem.least_violation(params, s.x, soft=BEARING, free=model.TARGET_LIMITS, fixed=held)
                solves.append(s2)
                near = _rounded(problem.design(s2.x, material), spec) if s2.success else None
                if near is not None:
                    found.append(near)
        # every limit but the targets met: the targets' least violation, the others held, a little
        # inside them when the grid's points around the answer held at them break one
        for margin in MARGINS if worst <= model.FEASIBILITY_TOLERANCE else ():
            solves.append(problem.least_violation(params, s.x, soft=model.TARGET_LIMITS, margin=margin)[0])
            near = _rounded(problem.design(solves[-1].x, material), spec)
            if near is not None:
                found.append(near)
                if closeness(near)[:4] == (False, False, 0, model.FEASIBILITY_TOLERANCE):
                    break
        near = _closest_of(found)
        if near is not None and closeness(near) < closeness(ev):
            c = replace(c, evaluation=near, solution=None, winner=None,
                        fallbacks=c.fallbacks + ("closest design: solved again for the least violation of the "
                                                 "duty's limits, the geometry's rules held: worst "
                                                 f"{near.worst_violation:.3g}",))
        out.append(replace(c, solves=c.solves + tuple(solves)))
    return out


def _closest_of(found: list) -> Evaluation | None:
    """The closest of ``found`` by ``closeness``; but where others' worst violation of the duty's
    limits lies within WORST_TIE of its own, the one of those whose other duty limits are broken
    least (worst first): ``closeness`` looks at the worst alone, and a re-solve 0.13 % nearer on
    the deflection lost 4 % on the signal (seed 13's 032-infeasible-deflection, its depth held)."""
    if not found:
        return None
    keyed = [(closeness(ev), ev) for ev in found]
    head = min(key for key, _ in keyed)
    tied = [(key, ev) for key, ev in keyed
            if key[:3] == head[:3] and 1 + key[3] <= (1 + head[3]) * (1 + WORST_TIE)]
    tol = model.FEASIBILITY_TOLERANCE

    def others(ev):
        return sorted((max(float(lim.normalised), tol) for lim in ev.judged if lim.name in BEARING), reverse=True)[1:]
    return min(tied, key=lambda pair: (others(pair[1]), pair[0]))[1]


def farther_load(spec, problems: dict, cand) -> float | None:
    """When the room before the load region binds ``cand``'s closest design: the least start of
    the load region (m) that a design of its material and family could meet every limit from,
    by the least violation of the load clearance alone, every other limit met (``run`` checks
    it). None when no design would, with load grooves (they move with the region), or for sizes
    from stock."""
    problem, ev = problems.get(cand.family), cand.evaluation
    if (spec.cad.load_grooves or problem is None or ev is None or stock_system(spec, cand.family) != "none"
            or not any(lim.name == "load_clearance" and lim.record()["active"] for lim in ev.limits)):
        return None
    material = catalogue.material(cand.material)
    s, _ = problem.least_violation(problem.params(material), start_from(problem, ev), soft=("load_clearance",))
    design = problem.design(s.x, material)
    g = design.geometry
    reach = float(g.stations[-1]) + float(g.feature_length) / 2 + spec.limits.load_clearance
    try:
        met = evaluate(design, replace(spec, load=replace(spec.load, position_min=reach)))
    except InputError:
        return None
    # its answer, unrounded, meets every limit from there (to IPOPT's tolerance): the solve is not trusted
    if any(float(v.normalised) > ANSWER_TOLERANCE for v in met.violations) or not reach < spec.load.position_max:
        return None
    return max(reach, spec.load.position_min)


def _rounded(design, spec) -> Evaluation | None:
    """``design`` on the manufacturing grid, the closest of its grid points by ``closeness``'s
    order: the neighbouring ones, then up to REACH steps farther while none of them meets what
    ``design`` itself meets of the geometry's rules and the duty's limits but the targets (a
    design held at its limits by the solve loses them to the grid one way or another)."""
    try:
        unrounded = evaluate(design, spec)
    except InputError:
        return None
    tol = model.FEASIBILITY_TOLERANCE
    rules = meets_rules(unrounded)
    bearing = rules and _worst(unrounded, lambda name: name in BEARING) <= tol
    try:
        for reach in range(REACH + 1):
            box = GridBox.around(design, spec, reach)
            if box is None:
                return None
            kept = box.valid & (box.rules <= tol if rules else True) & (box.bearing <= tol if bearing else True)
            if kept.any():
                break
        return box.choose(closest=True)
    except InputError:
        return None
