"""The candidates whose sections come from stock rows (``search.stock``, and tubes always), searched
row by row from their continuous answers (``stock.search_stock``), and the best continuous design
beside the stock one ("stock costs x %")."""

from __future__ import annotations

import math
from dataclasses import replace

from designer import model
from designer.result.evaluation import Evaluation
from designer.search.diagnosis import no_room
from designer.search.ongrid import back_off, closer_on_the_grid
from designer.search.problem import in_nlp_units, start_from
from designer.search.rounding import pick, round_and_check
from designer.search.stock import always_stocked, search_stock, stock_rows, stock_system
from designer.spec import catalogue


def candidates_on_stock(spec, problems: dict, candidates: list, skip=()) -> list:
    """Every candidate whose family's sections come from stock (``search.stock``, and tubes
    always: ``stock.stock_system``) with its section a row of the stock catalogue, searched from
    its continuous answer (``search.stock.search_stock``). The candidates go best continuous
    answer first, and the best design so far (on stock, or of continuous sizes in a family that
    is not on stock) caps the others' search: a family whose rows are all bounded above it is
    ``outranked`` without a row solved. Sets of rows that a relaxation shows infeasible are
    dropped; when that leaves no design that meets every limit (and no bar of continuous sizes
    has one to report), every row is solved again, so that the least-infeasible stock design is
    reported. A candidate in ``skip`` (``optimize``'s: a trade-off front's that a looser level
    left without a feasible design) has none here either, on stock or not: it is left as it is."""
    stocked = [stock_system(spec, c.family) != "none" and (c.material, c.family) not in skip for c in candidates]
    if not any(stocked):
        return candidates
    found = _on_stock(spec, problems, candidates, stocked, prune_infeasible=True)
    if any(c.evaluation is not None and c.evaluation.feasible for c in found):
        return found
    if any(c.evaluation is not None and not s for c, s in zip(found, stocked)):
        return found  # a bar of continuous sizes is the least infeasible design; tubes add no better one
    if no_room(spec):
        return found  # the stations cannot fit whatever the section: no row's design would say more
    return _on_stock(spec, problems, candidates, stocked, prune_infeasible=False)


def _on_stock(spec, problems: dict, candidates: list, stocked: list, prune_infeasible: bool) -> list:
    order = sorted((i for i in range(len(candidates)) if stocked[i]), key=lambda i: _continuous_key(candidates[i]))
    out = list(candidates)
    cap = min((c.evaluation.objective for c, s in zip(candidates, stocked)
               if not s and c.evaluation is not None and c.evaluation.feasible), default=math.inf)
    # under stock: none (tubes alone on stock) a tube with no feasible continuous design is not
    # searched row by row unless nothing else has a design (``candidates_on_stock``)
    bars_continuous = prune_infeasible and spec.search.stock == "none"
    for i in order:
        cand = candidates[i]
        if cand.outranked:  # by its continuous answer already (``solve_candidate``'s cap): no row is solved,
            rows, note = stock_rows(problems[cand.family], catalogue.material(cand.material, "search.materials"))
            if not rows:    # but a material with no stock of this shape at all is said to have none
                out[i] = replace(cand, outranked=False, unrounded=False, stock_note=note)
            continue
        if (math.isfinite(cap) or bars_continuous) and (cand.evaluation is None or not cand.evaluation.feasible):
            # no design of continuous sizes met every limit, so no stock size (a subset) can
            out[i] = replace(cand, evaluation=None, continuous=cand.evaluation,
                             stock_note=f"{cand.material} {cand.family.label}: no design of continuous sizes meets "
                                        "every limit, so no stock size was tried")
            continue
        problem = problems[cand.family]
        material = catalogue.material(cand.material, "search.materials")
        rows, note = stock_rows(problem, material)
        if not rows:
            out[i] = replace(cand, evaluation=None, continuous=cand.evaluation, stock_note=note)
            continue
        if cand.evaluation is not None and cand.evaluation.objective > cap * (1 + model.TIE_TOLERANCE):
            out[i] = replace(cand, evaluation=None, continuous=cand.evaluation, outranked=True)
            continue  # its continuous optimum bounds every row: none can rank before the cap
        x0 = start_from(problem, cand.evaluation) if cand.evaluation is not None else problem.starts()[0]
        found = search_stock(problem, material, x0, rows=rows, cap=cap, prune_infeasible=prune_infeasible,
                             closest=not prune_infeasible)
        ev = found.evaluation
        out[i] = replace(cand, evaluation=ev, solves=cand.solves + found.solves, continuous=cand.evaluation,
                         stock_note=found.note if ev is None or not ev.feasible else "", outranked=found.outranked)
        if ev is not None and ev.feasible:
            cap = min(cap, ev.objective)
    return out


def _continuous_key(cand) -> tuple:
    ev = cand.evaluation
    if ev is None:
        return (2, math.inf)
    return (0, ev.objective) if ev.feasible else (1, ev.worst_violation)


def continuous_optimum(spec, problems: dict, candidates: list) -> Evaluation | None:
    """With ``search.stock``, the best design of continuous sizes the stock search began from, on
    the 0.01 mm grid and checked. The families' answers were kept before rounding or repaired by
    the numeric box alone (they were only the rows' starts and bounds), so they are rounded and
    repaired here as any answer is (``back_off``, ``closer_on_the_grid``), best continuous answer
    first, until the next one (a bound on its rounded design) ranks after the best rounded so far.
    A tube is bought under ``stock: none`` too (``stock.always_stocked``: no bore is drilled), so
    its family's design on stock stands for it: a tube of continuous sizes is no design to compare
    with. None without stock, or when none meets every limit."""
    if spec.search.stock == "none":
        return None
    answers, found = [], []
    for c in candidates:
        if always_stocked(c.family):
            if c.evaluation is not None and c.evaluation.feasible:
                found.append(c.evaluation)
            continue
        if c.continuous is not None and c.continuous.feasible:
            problem = problems[c.family]
            material = catalogue.material(c.material)
            params = problem.params(material)
            bound = in_nlp_units(c.continuous.objective, spec.objective)
            if c.solution is not None:  # its answer's, unless a design held in a smaller range beat it
                bound = min(bound, float(problem.functions(c.solution.x, params)[0]))
            answers.append((bound, c, problem, material, params))
    for bound, c, problem, material, params in sorted(answers, key=lambda a: a[0]):
        if found and bound > in_nlp_units(pick(found).objective, spec.objective) * (1 + model.TIE_TOLERANCE):
            break
        ev = round_and_check(c.continuous.design, spec)
        if ev is not None and c.solution is not None:
            if not ev.feasible:
                _, ev = back_off(problem, params, material, c.solution, ev, [], [], "")
            if ev.feasible:
                # with the depth-held re-solves (their record unkept), as the search without stock
                # repairs its answers: without them the gripper finger's continuous optimum was a
                # Ø7.94 mm bar with 1.60 mm flats, 0.4 % behind the Ø8.00 mm bar the search finds
                ev = closer_on_the_grid(problem, params, material, c.solution, ev, [])
        if ev is not None and ev.feasible:
            found.append(ev)
    return pick(found)
