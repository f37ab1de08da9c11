"""Answers onto the 0.01 mm grid (docs/model.md §5): the grid around an answer searched with the
numeric model, the section held at its neighbouring grid sizes with the rest solved again, and,
as the last resort, the limits that rounding broke tightened."""

from __future__ import annotations

import itertools
from dataclasses import replace

from designer import model
from designer.errors import InputError
from designer.result.evaluation import ROUNDING, Evaluation, evaluate
from designer.search.problem import MM, FamilyProblem, Solve, in_nlp_units
from designer.search.rounding import GridBox, depths_held, floor_ceil, only_targets_missed, pick, round_and_check

# When rounding to 0.01 mm breaks a limit that IPOPT's answer met, and no section on the grid
# near it checks out with the rest solved again (``_on_the_grid``), IPOPT solves again with the
# limits that rounding broke, and only those, tightened by these normalised margins in turn
# until the rounded design checks out.
ROUNDING_MARGINS = (1e-4, 1e-3, 1e-2, 5e-2)  # those below the violation rounding caused are skipped


def back_off(problem: FamilyProblem, params, material, s: Solve, ev: Evaluation, solves: list, fallbacks: list,
             where: str, front: bool = False):
    """Rounding broke a limit. First the grid around the answer is searched with the numeric
    model alone (``_nearby_on_the_grid``); its best is taken if it costs at most NEARBY_GAP over
    the continuous answer. Then the depth is held at its neighbouring grid values and the rest
    solved again (``_depth_held``), taken under the same rule. Otherwise the section sizes are
    also held at each of their neighbouring 0.01 mm values in turn and the rest (stations, depth)
    solved again, each answer rounded and checked (``_on_the_grid``), and the best of the three is
    the answer on the grid. If none checks out, the numeric box is searched again WIDE_REACH steps
    wide. Only if that finds nothing either are the limits that rounding broke (and no other)
    tightened, by each of ROUNDING_MARGINS in turn from the first as large as the violation
    rounding caused; the first answer whose rounded design breaks no limit of the NLP replaces it
    (under the error objective it may still miss the targets: a verdict). For a trade-off
    ``front``'s point the numeric grid's best is taken whatever it costs, and nothing is held on
    the grid (a front is a plotted trend; those re-solves took a third of the gripper finger's
    fronts)."""
    continuous = float(problem.functions(s.x, params)[0])

    def close(e: Evaluation, gap: float = NEARBY_GAP) -> bool:
        return in_nlp_units(e.objective, problem.spec.objective) <= continuous * (1 + gap)

    def tied(e: Evaluation) -> bool:
        return close(e, model.TIE_TOLERANCE)

    near = _nearby_on_the_grid(problem, material, s)
    if near is not None and (front or close(near)):
        fallbacks.append(f"{where}: rounding broke a limit; the best design on the grid around the answer "
                         "taken instead")
        return s, near
    # both neighbouring depths unless the first is within the tie band: the bench suite's
    # 033-loose-limits met the 1 % at 1.75 mm, 0.1 % above its design at 1.80 mm
    held = None if front else _depth_held(problem, params, material, s, solves, tied)
    if held is not None and close(held[1]):
        fallbacks.append(f"{where}: rounding broke a limit; the depth held at its neighbouring grid values and "
                         "the rest solved again")
        return held
    on_grid = None if front else _on_the_grid(problem, params, material, s, solves)
    found = [(s, near)] if near is not None else []
    found += [f for f in (held, on_grid) if f is not None and f[1].feasible]
    wide = None if found or front else _nearby_on_the_grid(problem, material, s, WIDE_REACH)
    if wide is not None:
        fallbacks.append(f"{where}: rounding broke a limit; the best design on a wider grid around the answer "
                         f"({WIDE_REACH} steps) taken instead")
        return s, wide
    if found:
        best = pick([e for _, e in found])
        fallbacks.append(f"{where}: rounding broke a limit; " + (
            "the best design on the grid around the answer taken instead" if best is near else
            "the depth held at its neighbouring grid values and the rest solved again" if held and best is held[1]
            else "the section held at its neighbouring 0.01 mm sizes and the rest solved again"))
        return next(f for f in found if f[1] is best)
    if on_grid is not None:
        fallbacks.append(f"{where}: rounding broke a limit; the section held at its neighbouring 0.01 mm sizes "
                         "and the rest solved again")
        return on_grid
    broken = [v for v in ev.violations if not (problem.epigraph and v.name in model.TARGET_LIMITS)]
    names = sorted({v.name for v in broken} & set(problem.limit_names))
    if not names:  # only bounds broke, which IPOPT keeps exactly: nothing to tighten
        return s, ev
    # a margin smaller than the violation rounding caused seldom survives the next rounding
    worst = max(float(v.normalised) for v in broken)
    for margin in [m for m in ROUNDING_MARGINS if m >= worst] or ROUNDING_MARGINS[-1:]:
        s2 = problem.solve_ipopt(params, s.x, margin=problem.margins(names, margin))
        solves.append(s2)
        ev2 = round_and_check(problem.design(s2.x, material), problem.spec) if s2.success else None
        if ev2 is not None and (ev2.feasible or only_targets_missed(ev2, problem.epigraph)):
            fallbacks.append(f"{where}: re-solved with {', '.join(names)} tightened by {margin:.0e}; "
                                  "the rounded design " + ("meets every limit" if ev2.feasible else
                                                           "misses only the accuracy targets"))
            return s2, ev2
    return s, ev


# The variables that rounding holds at their grid values (and a stock row holds at its sizes)
# while the others are solved again; the grid step in the NLP's units (mm), and how many steps
# the search on the grid takes at most from the rounded sizes' best combination.
SECTION_VARIABLES = ("width", "height", "side", "diameter", "wall")
GRID_MM = ROUNDING / MM
GRID_STEPS = 10


# Grid steps past the rounded values that the numeric search around an answer tries in each
# section size and in the feature's depth or hole (``_nearby_on_the_grid``).
GRID_REACH = 2
# ... in the section sizes when no IPOPT re-solve follows it (``onto_the_grid``), or when neither
# the near box nor the re-solves found a design (``back_off``): a depth step of 0.05 mm (the
# default ``cad.depth_step``) takes a section size step of about as much to make up (the
# gripper's 7075 round bar: its flat's chord and its fatigue limit both active, depth 1.07 ->
# 1.10 mm needs the diameter 8.13 -> 8.20 mm); the depth itself reaches rounding.DEPTH_REACH.
WIDE_REACH = 8
# The numeric search's best is taken without the IPOPT re-solves when its objective is within this
# of the continuous answer's (a bound on every design near it). On the bench suite's 54 specs
# rounding broke 93 answers; the numeric search found a design for about 30, the re-solves for 5;
# where both did, the re-solves' was better by 0.06 % (within the tie band) and, once, by 1.7 %
# (the numeric best 1.8 % over the continuous answer: this threshold sends it to the re-solves).
NEARBY_GAP = 1e-2


def closer_on_the_grid(problem: FamilyProblem, params, material, s: Solve, ev: Evaluation, solves: list,
                       neighbour: Evaluation | None = None) -> Evaluation:
    """``ev``, the rounded answer that meets every limit, or a better design on the grid around the
    answer (``_nearby_on_the_grid``) when rounding cost more than the tie band against the
    continuous answer: rounding each size down or up need not find the grid's best point. If the
    grid's best still costs more, the depth is held at its neighbouring grid values and the rest
    solved again (``_depth_held``, its solves added to ``solves``): a depth step of 0.05 mm takes a
    section step of several 0.01 mm to make up, and the stations may move far, beyond the grid
    around the answer (the bench suite's 024-kilonewton: with its flats held 1.60 mm deep and the
    rest solved again, a 6061-T6 bar 0.77 % lighter than the grid's best, its first station 71
    steps away). Given a ``neighbour`` (a trade-off front's design
    at the neighbouring level, on the grid), that design judged under this spec is the one tried
    instead of the grid around the answer: a front's point is a plotted trend, and the walk on
    every point of every front cost more than the search."""
    continuous = float(problem.functions(s.x, params)[0])

    def close(e: Evaluation) -> bool:
        return in_nlp_units(e.objective, problem.spec.objective) <= continuous * (1 + model.TIE_TOLERANCE)

    if close(ev):
        return ev
    if neighbour is not None:
        try:
            near = evaluate(replace(neighbour.design, material=material, adjustment=problem.adjustment), problem.spec)
        except InputError:
            return ev
        return near if near.feasible and model.ranks_before(near, ev) else ev
    near = _nearby_on_the_grid(problem, material, s)
    best = near if near is not None and model.ranks_before(near, ev) else ev
    if close(best):
        return best
    held = _depth_held(problem, params, material, s, solves, close)
    # kept only where it costs less: within the tie band a design with less deflection ranks first
    return held[1] if held is not None and held[1].feasible and held[1].objective < best.objective else best


def onto_the_grid(problem: FamilyProblem, material, s: Solve, ev: Evaluation) -> Evaluation:
    """For a method other than IPOPT whose answer rounding broke a limit: the best design on the
    grid around the answer (``_nearby_on_the_grid``, the numeric model alone; the re-solves of
    ``back_off`` are IPOPT's), or ``ev`` when none there meets every limit."""
    near = _nearby_on_the_grid(problem, material, s, WIDE_REACH)
    return near if near is not None else ev


def _nearby_on_the_grid(problem: FamilyProblem, material, s: Solve, reach: int = GRID_REACH) -> Evaluation | None:
    """The best design on the 0.01 mm grid around the answer ``s``, by the numeric model alone:
    every section size and the depth (or hole) from GRID_REACH steps below its rounded-down to as
    many above its rounded-up value, the stations rounded down or up, all checked at once
    (``round_and_check``'s ``reach``); then recentred on the box's lowest objective while that
    falls (at most GRID_STEPS times), and the tie rule applied in the last box. (Recentred on the
    tie rule's choice instead, the walk stops at the first step that gains less than the tie band:
    the bench suite's 022-loose-limits stayed 0.13 % above the grid's best.) None when no design
    there meets every limit."""
    spec = problem.spec
    ev = round_and_check(problem.design(s.x, material), spec, reach=reach, lowest=True)
    if ev is None or not ev.feasible:
        return None
    for _ in range(GRID_STEPS):
        box = GridBox.around(ev.design, spec, reach=GRID_REACH)
        moved = None if box is None else box.choose(lowest=True)
        if moved is None or not moved.feasible or not moved.objective < ev.objective:
            return None if box is None else box.choose()
        ev = moved
    return round_and_check(ev.design, spec, reach=GRID_REACH)


def _depth_held(problem: FamilyProblem, params, material, s: Solve, solves: list, close):
    """``(Solve, Evaluation)``: the checked design of the pocket's depth held at a neighbouring
    value of its grid (``cad.depth_step``) and the rest solved again (the sizes then rounded, and
    the numeric grid around that answer searched if rounding them breaks a limit): the nearer
    value first, and the other only when that gives no design ``close`` (a predicate) to the
    continuous answer; the better of the two then. None for a family without a pocket or when
    neither meets every limit. A depth step of 0.05 mm takes a section step of about as much to
    make up, which the 0.01 mm grid around the answer does not reach."""
    found = []
    for held in depths_held(problem, s.x):
        s2 = problem.solve_ipopt(params, s.x, fixed=held)
        solves.append(s2)
        if not s2.success:
            continue
        ev2 = round_and_check(problem.design(s2.x, material), problem.spec)
        if ev2 is not None and not ev2.feasible:
            ev2 = _nearby_on_the_grid(problem, material, s2)
        if ev2 is not None and ev2.feasible:
            found.append((s2, ev2))
        else:
            # the section held on its grid too, the stations solved again: a size step can move a
            # target more than the stations' rounding makes up (the held-out suite's 009-tight-
            # limits: its force error 0.3 % per 0.01 mm of diameter, met again 0.05 mm further in)
            both = _on_the_grid(problem, params, material, s2, solves, hold=held)
            if both is not None and both[1].feasible:
                found.append(both)
        if found and close(found[-1][1]):
            break
    if not found:
        return None
    best = pick([ev for _, ev in found])
    return next(f for f in found if f[1] is best)


def _on_the_grid(problem: FamilyProblem, params, material, s: Solve, solves: list, hold: dict | None = None):
    """``(Solve, Evaluation)``: the best checked design with the section sizes on the 0.01 mm grid
    near the answer and the other variables solved again with them held; None when no such design
    meets every limit (or, under the error objective, misses only the targets). The sizes start
    from each combination of rounding down and up; from the best of those, a step of 0.01 mm up
    or down in one size at a time is taken while it gives a better design (at most
    GRID_STEPS steps): the rounded sizes' best neighbour need not be the grid's best point (the
    bench suite's 029-long-beam under an earlier slot fit: 0.12 % better two steps away). ``hold`` (``{index: value}``, in
    the NLP's units) holds more variables at those values throughout (the depth on its grid)."""
    index = [i for i, name in enumerate(problem.names) if name in SECTION_VARIABLES]
    choices = [[v / MM for v in floor_ceil(float(s.x[i]) * MM)] for i in index]
    tried: dict = {}
    also = hold or {}

    def solve_held(combo):
        key = tuple(round(v / GRID_MM) for v in combo)
        if key not in tried:
            s2 = problem.solve_ipopt(params, s.x, fixed={**also, **dict(zip(index, combo))})
            solves.append(s2)
            ev2 = round_and_check(problem.design(s2.x, material), problem.spec) if s2.success else None
            ok = ev2 is not None and (ev2.feasible or only_targets_missed(ev2, problem.epigraph))
            tried[key] = (s2, ev2) if ok else None
        return tried[key]

    found = [f for f in map(solve_held, itertools.product(*choices)) if f is not None]
    if not found:
        return None
    best = pick([ev for _, ev in found])
    here = next(f for f in found if f[1] is best)
    for _ in range(GRID_STEPS):
        centre = [here[0].x[i] for i in index]
        steps = [centre[:k] + [centre[k] + sign * GRID_MM] + centre[k + 1:]
                 for k in range(len(index)) for sign in (-1, 1)]
        moves = [f for f in map(solve_held, steps) if f is not None]
        better = pick([here[1]] + [ev for _, ev in moves])
        if better is here[1] or not better.objective < here[1].objective:
            break
        here = next(f for f in moves if f[1] is better)
    return here
