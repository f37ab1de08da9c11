"""The discrete section search: the best design whose section is a row of the stock catalogue.

A family's section sizes (``SECTION_VARIABLES``) are taken from the rows of the material's
stock tables (``stock_system``: ``search.stock``, and for a tube always, as no bore is made but
from tube stock); stations and pocket depth stay continuous. The rows are searched by
branch and bound over boxes of rows: the NLP with the section sizes bounded to the box around a set
of rows is a relaxation of every row in the set, so its optimum bounds their objectives from below.
Sets are taken best bound first and split until a set is one row, which is solved with its section
held fixed, rounded and checked (``round_and_check``); a set whose bound is above the best checked
row's objective by more than the tie band is not opened. Each bound is a local IPOPT optimum, not
a certificate: the tests compare the search with every row solved (docs/model.md §5).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, replace

import numpy as np

from designer import model
from designer.search.problem import IPOPT_INFEASIBLE, MM, FamilyProblem, in_nlp_units
from designer.search.rounding import (broken_rules, buildable, depths_held, floor_ceil, only_targets_missed, pick,
                                      round_and_check)
from designer.spec import catalogue

# A row whose rounded design breaks a limit its solve met is solved again with the broken limits,
# and only those, tightened by these normalised margins in turn (as ongrid.ROUNDING_MARGINS).
ROW_MARGINS = (1e-4, 1e-3, 1e-2)
SIZE_TOLERANCE = 1e-9   # mm: a row on a variable bound is inside it


@dataclass(frozen=True)
class StockOutcome:
    """What the stock search found for one material x family."""

    evaluation: object          # Evaluation of the best row (checked), or None when no row could be solved
    solves: tuple
    rows: int                   # rows of the family's tables that fit the variable bounds
    solved: int                 # rows solved on their own (the leaves opened)
    note: str = ""              # why there is no stock design, when there is none
    outranked: bool = False     # every row is bounded above ``cap``: none was solved


def always_stocked(family) -> bool:
    """Whether ``family``'s sections come from stock whatever ``search.stock`` says: a tube's (a
    bore through a bar's length is not drilled: the tube is bought)."""
    return family.section == "tube"


def stock_system(spec, family) -> str:
    """The stock tables ``family``'s sections come from under ``spec``: ``search.stock``, or with
    ``stock: none`` ``any`` for a family ``always_stocked`` and ``none`` (continuous sizes) for the
    others."""
    if spec.search.stock != "none":
        return spec.search.stock
    return "any" if always_stocked(family) else "none"


def stock_rows(problem: FamilyProblem, material) -> tuple[list, str]:
    """``([(StockItem, sizes in mm by variable index, sizes in m by name)], note)``: the rows of ``material``'s
    stock tables for this family inside the NLP's variable bounds; the note says why there are
    none."""
    spec, fam = problem.spec, problem.family
    table = catalogue.stock()
    family = table.family_of(material.name)
    system = stock_system(spec, fam)
    rows = table.rows(material.name, fam.section, system, spec.axes)
    systems = "metric and imperial" if system == "any" else system
    shapes = {"round": "round bar", "tube": "round tube", "rectangle": "flat or square bar"}[fam.section]
    why = "" if spec.search.stock != "none" else \
        " (with stock: none a tube still comes from tube stock: a bore is not drilled)"
    if family is None:
        return [], (f"{material.name} is in no stock family (a catalogue of your own gives its materials one "
                    "under stock.families): this family is infeasible on stock" + why)
    if not rows:
        return [], (f"no {systems} stock {shapes} of {material.name} ({family}) in the stock catalogue: this "
                    "family is infeasible on stock" + why)
    index = {name: i for i, name in enumerate(problem.names)}
    fitting = []
    for item, values in rows:
        mm = {index[k]: v / MM for k, v in values.items()}
        if all(problem.lower[i] - SIZE_TOLERANCE <= v <= problem.upper[i] + SIZE_TOLERANCE for i, v in mm.items()):
            fitting.append((item, mm, values))
    if not fitting:
        return [], (f"none of the {len(rows)} {systems} stock {shapes} sizes of {material.name} fits "
                    "limits.width, limits.height and limits.min_wall: this family is infeasible on stock" + why)
    return fitting, ""


def on_stock(design, item, values_si: dict):
    """``design`` with its section set exactly to a stock row's sizes (m) and the row attached."""
    named = dict(values_si)
    if "side" in named:
        named["width"] = named["height"] = named.pop("side")
    return replace(design, geometry=replace(design.geometry, **named), stock=item)


def same_section(design, like):
    """``design`` with the section and the stock row of ``like`` (a design on stock), exactly."""
    g = like.geometry
    return replace(design, geometry=replace(design.geometry, width=g.width, height=g.height, diameter=g.diameter,
                                            wall=g.wall), stock=like.stock)


def search_stock(problem: FamilyProblem, material, x0, rows=None, cap: float = math.inf,
                 prune_infeasible: bool = False, margin: float = 0.0, closest: bool = False) -> StockOutcome:
    """The best stock row for one material x family, from ``x0`` (the continuous answer, NLP
    units); ``rows`` (as ``stock_rows`` gives them) limits the search to those rows. ``cap``
    (objective, SI): a design another family has on stock; rows bounded above it by more than the
    tie band are not solved, and when that is all of them the outcome is ``outranked``.

    A set of rows whose relaxation (the section free between the set's sizes) IPOPT finds
    infeasible holds no row that meets every limit. It is dropped when a design that meets every
    limit is known (the cap, or a row checked here), or always with ``prune_infeasible``: then the
    outcome has no least-infeasible design for such rows. IPOPT keeps every constraint ``margin``
    inside its limit (``run.resolve``). ``closest``: the least infeasible row is sought instead
    (``least_infeasible``), as ``stocked.candidates_on_stock`` asks when no stock design meets every
    limit."""
    rows, note = stock_rows(problem, material) if rows is None else (rows, "")
    if not rows:
        return StockOutcome(None, (), 0, 0, note)
    if closest:
        return least_infeasible(problem, material, x0, rows)
    spec = problem.spec
    params = problem.params(material)
    index, points = _sizes(rows)
    solves, checked = [], []
    best_nlp = in_nlp_units(cap, spec.objective)  # the best checked row's objective (or the cap), NLP units

    def objective(s) -> float:
        return float(problem.functions(s.x, params)[0])

    def relax(members, start, parent=None):
        box = _box(points, members, index)
        s = problem.solve_ipopt(params, start, box=box, margin=margin, least=True, warm=parent)
        solves.append(s)
        return s

    def leaf(member, start):
        nonlocal best_nlp
        item, fixed, exact = rows[member]
        found = []
        for x in [start] + problem.starts():
            s = problem.solve_ipopt(params, x, fixed=fixed, margin=margin)
            solves.append(s)
            ev = round_and_check(on_stock(problem.design(s.x, material), item, exact), spec)
            if ev is not None and s.success and not ev.feasible and not only_targets_missed(ev, problem.epigraph):
                broken = [v.name for v in ev.violations]  # rounding the stations or depth broke these
                for tighter in ROW_MARGINS:
                    s2 = problem.solve_ipopt(params, s.x, fixed=fixed,
                                           margin=np.maximum(margin, problem.margins(broken, tighter)))
                    solves.append(s2)
                    ev2 = round_and_check(on_stock(problem.design(s2.x, material), item, exact), spec) \
                        if s2.success else None
                    if ev2 is not None and (ev2.feasible or only_targets_missed(ev2, problem.epigraph)):
                        ev = ev2
                        break
            if ev is not None:
                found.append(ev)
            if s.success and "depth" in problem.names and not (
                    ev is not None and ev.feasible
                    and in_nlp_units(ev.objective, spec.objective) <= objective(s) * (1 + model.TIE_TOLERANCE)):
                found += depth_held(s, fixed, item, exact)
            if s.success:
                break   # a converged answer, checked: other starts are for a solve that failed
        ev = pick(found)
        if ev is not None:
            checked.append(ev)
            if ev.feasible:
                best_nlp = min(best_nlp, in_nlp_units(ev.objective, spec.objective))

    def depth_held(s, fixed, item, exact) -> list:
        """The row's designs with the pocket's depth also held, at each of its grid values (0.05 mm)
        beside the answer's, and the stations solved again: rounding the depth after the
        stations moves it up to 0.05 mm, which the stations' rounding box cannot make up."""
        i = problem.names.index("depth")
        found = []
        for depth in floor_ceil(float(s.x[i]) * MM, step=spec.cad.depth_step):
            s2 = problem.solve_ipopt(params, s.x, fixed={**fixed, i: depth / MM}, margin=margin)
            solves.append(s2)
            ev2 = round_and_check(on_stock(problem.design(s2.x, material), item, exact), spec) if s2.success else None
            if ev2 is not None:
                found.append(ev2)
        return found

    def dropped(s) -> bool:
        """No row of the set meets every limit, and that may drop it: none can rank before a design that does."""
        return s.message in IPOPT_INFEASIBLE and (prune_infeasible or math.isfinite(best_nlp))

    everything = list(range(len(rows)))
    root = relax(everything, x0)
    heap, pruned = [], 0
    if dropped(root):
        pruned = len(rows)
    else:
        heap.append((objective(root) if root.success else -math.inf, 0, everything, root))
    counter, leaves = 1, 0
    while heap:
        bound, _, members, parent = heapq.heappop(heap)
        start = parent.x
        if bound > best_nlp * (1 + model.TIE_TOLERANCE):
            break   # best bound first: every set left is bounded above the incumbent's tie band
        if len(members) == 1:
            leaf(members[0], start)
            leaves += 1
            continue
        for part in _split(points, members, start, index):
            s = relax(part, start, parent if parent.success else None)
            if dropped(s):
                pruned += len(part)
                continue
            child_bound = objective(s) if s.success else bound  # a failed relaxation bounds nothing new
            heapq.heappush(heap, (max(child_bound, bound), counter, part, s if s.success else parent))
            counter += 1
    return _outcome(problem, material, rows, checked, solves, leaves, pruned)


def least_infeasible(problem: FamilyProblem, material, x0, rows: list) -> StockOutcome:
    """The least infeasible of ``rows`` (as ``stock_rows`` gives them), from ``x0`` (NLP units),
    when no row meets every limit: the closest stock design, which the diagnosis reasons from. A
    row's design is its least violation (``FamilyProblem.least_violation``: the worst normalised
    row of the duty's limits, nominal and at the tolerance corners, least; the geometry's own rules
    held) with its section held, rounded and checked. The rows are searched by branch and bound as
    ``search_stock``'s: the least violation with the section free between a set's sizes (the
    tolerance corners at their least) bounds every row's in the set, and a set bounded above the
    least violation a row keeping the rules has is not opened. A set whose rows cannot keep the
    rules (IPOPT's infeasibility verdict) is set aside, and its rows are solved one by one, for the
    least violation of every limit and rule, only when no row keeps them. The least infeasible row
    is the first by the geometry's rules broken, then the worst violation. On the bench suite's seed 14
    013-kilonewton this solves 13 of each tube's 158 rows, where every row was once solved from
    the continuous answer for the limits, and the IPOPT answers that proved the rows infeasible
    left a closest tube breaking four of the geometry's rules (docs/model.md §5)."""
    spec, params, soft = problem.spec, problem.params(material), set(model.DUTY_LIMITS)
    index, points = _sizes(rows)
    solves, checked = [], []

    def relax(members, start, bound: float) -> tuple:
        box = _box(points, members, index)
        s, worst = problem.least_violation(params, start, soft, box=box, least=True)
        solves.append(s)
        if s.success:
            return max(worst, bound), s
        return (math.inf if s.message in IPOPT_INFEASIBLE else bound), None

    def leaf(member, start, rules: bool = True) -> float:
        """The row's least violation when its design keeps the geometry's rules, else infinity;
        without ``rules`` they are violations as the limits are, and the depth is not held."""
        item, fixed, exact = rows[member]
        s, _ = problem.least_violation(params, start, soft if rules else set(problem.row_names), fixed=fixed)
        solves.append(s)
        found = [round_and_check(on_stock(problem.design(s.x, material), item, exact), spec)]
        for held in depths_held(problem, s.x) if rules else ():   # the pocket's depth on its grid (``closest_designs``)
            s2, _ = problem.least_violation(params, s.x, soft, fixed={**fixed, **held})
            solves.append(s2)
            found.append(round_and_check(on_stock(problem.design(s2.x, material), item, exact), spec))
        found = [ev for ev in found if ev is not None]
        if not found:
            return math.inf
        ev = min(found, key=_farness)
        checked.append(ev)
        return ev.worst_violation if _farness(ev)[:2] == (False, 0) else math.inf

    everything = list(range(len(rows)))
    bound, root = relax(everything, x0, -math.inf)
    heap, aside = ([(bound, 0, everything, root)], []) if bound < math.inf else ([], everything)
    counter, leaves, best = 1, 0, math.inf
    while heap:
        bound, _, members, parent = heapq.heappop(heap)
        if bound > best:
            break   # best bound first: every set left is bounded above the least violation checked
        start = x0 if parent is None else parent.x
        if len(members) == 1:
            best = min(best, leaf(members[0], start))
            leaves += 1
            continue
        for part in _split(points, members, start, index):
            child, s = relax(part, start, bound)
            if child < math.inf:
                heapq.heappush(heap, (child, counter, part, s or parent))
                counter += 1
            else:
                aside += part
    if not math.isfinite(best):   # no row keeps the geometry's rules
        for member in aside:
            leaf(member, x0, rules=False)
        leaves += len(aside)
    evaluation = min(checked, key=_farness, default=None)
    return _outcome(problem, material, rows, [] if evaluation is None else [evaluation], solves, leaves, 0)


def _farness(ev) -> tuple:
    """An infeasible design's distance from meeting every limit, as ``closest.closeness`` orders
    it in short: a beam at all, the fewest of the geometry's rules broken, the least worst violation."""
    return (not buildable(ev), len(broken_rules(ev)), ev.worst_violation)


def _outcome(problem, material, rows, checked, solves, leaves: int, pruned: int) -> StockOutcome:
    """The stock search's outcome from the rows checked (``leaves`` solved, ``pruned`` dropped)."""
    evaluation = pick(checked)
    if evaluation is None and leaves == 0 and pruned == len(rows):
        return StockOutcome(None, tuple(solves), len(rows), 0,
                            f"no stock row of {material.name} {problem.family.label} meets every limit (with the "
                            "section free between the rows' sizes IPOPT finds no design that does)")
    if evaluation is None and leaves == 0:
        return StockOutcome(None, tuple(solves), len(rows), 0, "", outranked=True)
    note = ""
    if evaluation is None:
        note = f"no stock row of {material.name} {problem.family.label} could be solved"
    elif not evaluation.feasible:
        note = f"no stock row of {material.name} {problem.family.label} meets every limit"
    return StockOutcome(evaluation, tuple(solves), len(rows), leaves, note)


def _sizes(rows: list) -> tuple[list, np.ndarray]:
    """``(indices, points)``: the section's variable indices and each row's sizes at them (mm)."""
    index = sorted(rows[0][1])
    return index, np.array([[mm[i] for i in index] for _, mm, _ in rows])


def _box(points: np.ndarray, members: list, index: list) -> dict:
    """``{index: (low, high)}``: the box around the sizes of the rows ``members`` (NLP units)."""
    return {i: (points[members, k].min(), points[members, k].max()) for k, i in enumerate(index)}


def _split(points: np.ndarray, members: list, x, index: list) -> list:
    """Two sets of rows: split along the size that spreads most (on a log scale), at the
    relaxation's value of it, or at the median when that leaves one side empty."""
    sub = points[members]
    spread = np.log(sub.max(axis=0)) - np.log(sub.min(axis=0))
    k = int(np.argmax(spread))
    cut = float(x[index[k]])
    left = [m for m in members if points[m, k] <= cut]
    right = [m for m in members if points[m, k] > cut]
    if not left or not right:
        order = sorted(members, key=lambda m: points[m, k])
        half = len(order) // 2
        left, right = order[:half], order[half:]
    return [left, right]


def brute_force(problem: FamilyProblem, material, x0) -> list:
    """Every row solved on its own with its section held, rounded and checked (the reference of
    the tests): ``[(StockItem, Evaluation or None)]``."""
    rows, _ = stock_rows(problem, material)
    return [(row[0], search_stock(problem, material, x0, rows=[row]).evaluation) for row in rows]
