"""What would resolve an infeasible spec, found by searching again: the designs the diagnosis
names beside its advice (``diagnosis.diagnose``'s ``farther`` and ``looser``). Each searches the
closest candidate's material and family again with the spec changed one way, by ``solve``
(``run.solve_candidate``, given by the search that calls these), and names a change only where that
search finds a design meeting every limit on the grid.
"""

from __future__ import annotations

import math
from dataclasses import replace

from designer.result.evaluation import Evaluation
from designer.search.closest import farther_load
from designer.search.problem import FamilyProblem, start_from
from designer.search.stock import stock_system
from designer.spec import catalogue

# How far (m) past the least start of a load region (``closest.farther_load``, to 0.1 mm) its
# material and family are searched, in turn, for a design that meets every limit on the grid.
FARTHER = (0.0, 5e-4, 2e-3)
# Over the least allowed deflection the least-violation solve gives (``looser_deflection``), the
# levels at which the closest candidate's material and family are searched, in turn, for a design
# that meets every limit on the grid (rounding its sizes takes a little of the room).
LOOSER = (1.0, 1.02, 1.1, 1.5)

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


def looser_deflection(spec, problems: dict, cand, method: str, solve) -> tuple[float, Evaluation] | None:
    """When ``cand``'s closest design breaks ``limits.max_deflection``: an allowed deflection (m) at
    which its material and family have a design that meets every limit, found by the search, and
    that design. The level is first the least violation of the deflection limit alone, every other
    limit met (``FamilyProblem.least_violation``; its normalised row is ``v`` at the answer, so the
    limit it needs is ``max_deflection (1 + v)``), then LOOSER's steps over it. None when no search
    there finds one, or for sizes from stock."""
    ev, limit = cand.evaluation, spec.limits.max_deflection
    problem = problems.get(cand.family)
    if (limit is None or ev is None or problem is None or stock_system(spec, cand.family) != "none"
            or not any(v.name == "deflection" for v in ev.violations)):
        return None
    material = catalogue.material(cand.material)
    _, worst = problem.least_violation(problem.params(material), start_from(problem, ev), soft=("deflection",))
    if not math.isfinite(worst):
        return None
    for past in LOOSER:
        level = limit * (1 + max(worst, 0.0)) * past
        moved = replace(spec, limits=replace(spec.limits, max_deflection=level))
        found = solve(FamilyProblem(moved, cand.family), material, method).evaluation
        if found is not None and found.feasible:
            return level, found
    return None
