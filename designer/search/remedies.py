"""What would resolve an infeasible spec, found by searching again: the designs the diagnosis
names beside its advice (``diagnosis.diagnose``'s ``farther``, ``looser`` and ``plain``). Each
searches again with the spec changed one way, by ``solve`` (``run.solve_candidate``: the closest
candidate's material and family) or ``search`` (``run.optimize``: every material and section, given
by the search that calls these), and names a change only where that search finds a design meeting
every limit on the grid.
"""

from __future__ import annotations

import math
from dataclasses import replace

from designer.errors import FpdError
from designer.result.evaluation import Evaluation
from designer.search.closest import farther_load
from designer.search.problem import SWEPT_LIMIT, FamilyProblem, start_from
from designer.search.stock import stock_system
from designer.spec import catalogue

# How far (m) past the least start of a load region (``closest.farther_load``, to 0.1 mm) its
# material and family are searched, in turn, for a design that meets every limit on the grid.
FARTHER = (0.0, 5e-4, 2e-3)
# The limits a looser level of which may resolve a spec (``looser``), by spec key: the level the
# least violation v of its limit asks for, and the levels then searched, in turn, over it (rounding
# the sizes to the grid takes a little of the room): 2, 10 and 50 % looser.
LOOSER = {"max_deflection": (lambda level, v: level * (1 + v), (1.0, 1.02, 1.1, 1.5)),
          "min_frequency": (lambda level, v: level * (1 - v), (1.0, 1 / 1.02, 1 / 1.1, 1 / 1.5))}


def farther(spec, problems: dict, cand, method: str, solve) -> tuple[float, Evaluation] | None:
    """A start of the load region, to 0.1 mm, from which ``cand``'s material and family have a design
    that meets every limit, found by the search, and that design; None when there is none."""
    least = farther_load(spec, problems, cand)
    for past in FARTHER if least is not None else ():
        start = round(math.ceil(least / 1e-4 - 1e-9) * 1e-4 + past, 7)
        moved = replace(spec, load=replace(spec.load, position_min=start))
        found = solve(FamilyProblem(moved, cand.family), catalogue.material(cand.material), method).evaluation
        if found is not None and found.feasible:
            return start, found
    return None


def looser(spec, problems: dict, cand, method: str, solve) -> dict:
    """For each limit of LOOSER that ``cand``'s closest design breaks (the deflection, the natural
    frequency): ``{limit: (level, design)}``, a level of its spec key at which its material and
    family have a design that meets every limit, found by the search, and that design. The level is
    first the least violation of that limit alone, every other limit met
    (``FamilyProblem.least_violation``, its normalised row ``v`` at the answer), then LOOSER's steps
    from it, each solved on one graph with the limit's level as a parameter (``FamilyProblem``'s
    ``swept``, as the trade-off fronts are). A limit is left out when no search there finds a
    design, and all for sizes from stock."""
    ev, problem = cand.evaluation, problems.get(cand.family)
    if ev is None or problem is None or stock_system(spec, cand.family) != "none":
        return {}
    material, out = catalogue.material(cand.material), {}
    broken = {v.name for v in ev.violations}
    for key, (level_for, steps) in LOOSER.items():
        name = SWEPT_LIMIT[key]
        if name not in broken:
            continue
        _, worst = problem.least_violation(problem.params(material), start_from(problem, ev), soft=(name,))
        least = level_for(getattr(spec.limits, key), max(worst, 0.0))
        graph = FamilyProblem(spec, cand.family, swept=key) if math.isfinite(least) and least > 0 else None
        for level in (least * step for step in steps) if graph is not None else ():
            moved = replace(spec, limits=replace(spec.limits, **{key: level}))
            found = solve(graph.at(moved, level), material, method).evaluation
            if found is not None and found.feasible:
                out[name] = (level, found)
                break
    return out


def plain(spec, search) -> Evaluation | None:
    """The best design without a feature (``search.feature: none``: the gauges bonded on the bar's
    own faces) when it meets every limit, found by ``search`` (``run.optimize`` over the spec's
    materials and sections, without closest designs) for a spec that asks for a pocket or a hole;
    None otherwise. A pocket's stress concentration, its fatigue stress above all, and the rules
    that fit it on the bar (a flat as wide as the pocket, a slot's side walls, the pocket study's
    range) can leave a spec no design that a plain bar has (the bench suite's seed 14
    023-millinewton: no flat as wide as its gauge fits the round bars allowed, and a slot leaves
    no side walls, while a plain Ti-6Al-4V bar meets every limit)."""
    if spec.search.feature == "none":
        return None
    try:
        found = search(replace(spec, search=replace(spec.search, feature="none")))
    except FpdError:   # no section left to try without a feature (a tube on no stock)
        return None
    return found.best if found.success and found.best.feasible else None
