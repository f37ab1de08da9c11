"""The search: every allowed material x section family solved, checked and ranked."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from designer import model
from designer.errors import SolverError, SpecError, describe_allowed
from designer.result.evaluation import Evaluation
from designer.search import remedies
from designer.search.closest import closeness, closest_designs
from designer.search.diagnosis import diagnose, no_room
from designer.search.methods import solve
from designer.search.ongrid import SECTION_VARIABLES, back_off, closer_on_the_grid, onto_the_grid
from designer.search.problem import (IPOPT_INFEASIBLE, MM, METHODS, TOLERANCED, Family, FamilyProblem, Solve,
                                     families, in_nlp_units, start_from, unsearchable)
from designer.search.rounding import (only_targets_missed, outranked_before_rounding, pick, round_and_check,
                                      what_broke)
from designer.search.stock import same_section, search_stock, stock_system
from designer.search.stocked import candidates_on_stock, continuous_optimum
from designer.spec import catalogue


@dataclass(frozen=True)
class Candidate:
    """One material x family: the best checked design its solves gave, and how they went."""

    material: str
    family: Family
    evaluation: Evaluation | None
    solves: tuple = ()
    fallbacks: tuple = ()
    continuous: Evaluation | None = None   # on stock: the continuous answer the stock search began from
    stock_note: str = ""                   # on stock: why no stock row meets every limit
    outranked: bool = False                # on stock: every row bounded below the chosen design; or ...
    unrounded: bool = False                # ... its answer before rounding, ``continuous``, already far below
    tried: tuple = ()                      # the start points the first method ran from, in order
    winner: object = None                  # the start point whose answer was verified, if one was
    solution: object = None                # the Solve whose answer gave ``evaluation`` (a warm start nearby)

    @property
    def status(self) -> str:
        """optimal | infeasible | failed (no answer could be evaluated); outranked: on stock, no
        row solved (the continuous optimum, IPOPT's bound on every row, ranks below the chosen
        stock design), or not rounded (``unrounded``: its answer before rounding already ranked far
        below); on stock also infeasible when there is no row to try."""
        if self.outranked:
            return "outranked"
        if self.evaluation is None:
            return "infeasible" if self.stock_note else "failed"
        return "optimal" if self.evaluation.feasible else "infeasible"

    def record(self) -> dict:
        ev = self.evaluation
        out = {"material": self.material, "section": self.family.label, "status": self.status,
               "objective": None, "error_ratio": None, "deflection": None, "mass": None,
               "natural_frequency": None, "worst_violation": None}
        if ev is not None:
            a = ev.analysis
            out.update(objective=ev.objective, error_ratio=ev.error_ratio, deflection=float(a.deflection),
                       mass=float(a.mass), natural_frequency=float(a.natural_frequency),
                       worst_violation=ev.worst_violation,
                       violated=[lim.name for lim in ev.violations])
        if self.fallbacks:
            out["fallbacks"] = list(self.fallbacks)
        if self.continuous is not None or self.stock_note:
            if not self.unrounded:  # a family on stock: its item (none when outranked before rounding)
                stock = None if ev is None else ev.design.stock
                out["stock"] = None if stock is None else stock.label
            out.update(continuous_objective=None if self.continuous is None else self.continuous.objective,
                       continuous_status=None if self.continuous is None else
                       ("optimal" if self.continuous.feasible else "infeasible"))
            if self.stock_note:
                out["stock_note"] = self.stock_note
        return out


FALLBACK = {"ipopt": "slsqp"}  # every other method falls back to ipopt
# Two starts' answers this close (each variable in the NLP's units), with the same verdict, are one:
# the later takes the earlier's rounding, repair and check (functions of the answer). Starts at one
# optimum agree to about 1e-9 (IPOPT's tolerance); 1e-7 moves a 0.01 mm rounding only at its boundary.
SAME_ANSWER = 1e-7


def _same_answer(a: Solve, b: Solve) -> bool:
    return (a.success == b.success and a.message == b.message and a.method == b.method
            and np.shape(a.x) == np.shape(b.x) and float(np.max(np.abs(a.x - b.x), initial=0.0)) <= SAME_ANSWER)


class SearchResult(dict):
    """What ``optimize`` found, complete when returned: a dict whose keys read as attributes too
    (in the style of scipy's ``OptimizeResult``, without loading scipy.optimize: a quarter of a
    second at every start).

    Keys: ``success`` (a design meets every limit), ``status`` (optimal | infeasible),
    ``message``, ``x`` (the chosen Design), ``best`` (its Evaluation), ``candidates`` (every
    material x family, ranked), ``solver`` (method, time, evaluations, solves, fallbacks),
    ``messages`` (the diagnosis of an infeasible spec), ``seconds``, ``nfev``; ``continuous``:
    with ``search.stock``, the best design of continuous sizes the stock search began from, on the
    0.01 mm grid (None without stock, or when none met every limit).
    """

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError as exc:
            raise AttributeError(name) from exc

    __setattr__ = dict.__setitem__
    __delattr__ = dict.__delitem__

    @property
    def evaluations(self) -> int:
        return self.nfev


def solve_candidate(problem: FamilyProblem, material, method: str, all_starts: bool = False, starts=None,
                    margin: float = 0.0, proves=None, neighbour: Evaluation | None = None,
                    warm: Solve | None = None, cap: float | None = None, repair: bool = True) -> Candidate:
    """Solve one material x family from several starts (``problem.starts()`` unless given); fall
    back to another method when no start gives a verified design. Every answer is rounded and
    checked. IPOPT keeps every constraint ``margin`` inside its limit. ``proves``, if given, is
    called when IPOPT's first start ends in an infeasibility verdict and returns a note and the
    solves it ran: with a note (a relaxation covering this material is infeasible too,
    ``optimize``), the other starts and the fallback are not run and the note joins the fallbacks.
    ``neighbour``: a trade-off front's design at the neighbouring level (``ongrid.closer_on_the_grid``),
    the first start; ``warm``: the solve that gave it, whose multipliers start IPOPT there.
    ``cap``: when IPOPT's first answer, before rounding, is already above it and rounding breaks a
    limit, the candidate is ``outranked`` (its continuous optimum kept as the bound) instead of
    repaired: ``optimize`` gives the best design found so far, CONTENDER_BAND over. Without ``repair``
    (a family whose sections come from stock rows, searched later from this answer), an answer
    is only the rows' start and bound: it is kept before rounding when it meets every limit there,
    and otherwise repaired as a front's point is (the numeric box alone); its sizes are not
    reported (``stocked.continuous_optimum`` rounds and repairs the best families')."""
    spec = problem.spec
    params = problem.params(material)
    evaluation, solves, fallbacks = None, [], []
    starts = problem.starts() if starts is None else list(starts)
    checked = []
    if method in ("grid", "isres", "direct"):
        starts = starts[:1]  # global methods do not depend on the start
    methods = [method, FALLBACK.get(method, "ipopt")]
    tried, winner, proved, answers = [], None, "", {}
    for m in dict.fromkeys(methods):
        verdicts = 0  # starts that ended in a verdict rather than a failure of the solver
        done = []     # this method's starts so far: (answer, answer after repair, checked design, start)
        for i, x0 in enumerate(starts):
            s = (problem.solve_ipopt(params, x0, margin=margin, warm=warm) if i == 0 and warm is not None and m == "ipopt"
                 else solve(problem, m, params, x0, margin))
            solves.append(s)
            if m == method:
                tried.append(x0)
            if m == "ipopt" and s.message in IPOPT_INFEASIBLE:
                verdicts += 1
            twin = next((d for d in done if _same_answer(d[0], s)), None)
            if twin is not None:   # (a front's infeasible level: every start ends at one optimum)
                _, s, ev, k = twin
                fallbacks.append(f"{m} start {i + 1}: the same answer as start {k + 1}; its design as that start's")
            else:
                raw = s
                ev = round_and_check(problem.design(s.x, material), spec)
                if ev is None:
                    fallbacks.append(f"{m} start {i + 1}: the answer could not be evaluated ({s.message})")
                    continue
                # on stock (not ``repair``) a converged answer that meets every limit is kept as it is
                kept = (None if repair or m != "ipopt"
                        else outranked_before_rounding(problem, material, s, -math.inf, model.FEASIBILITY_TOLERANCE))
                if kept is not None and ev.feasible:
                    ev = kept
                elif not s.success:
                    fallbacks.append(f"{m} start {i + 1}: {s.message}")
                elif not ev.feasible and ev.violations and not only_targets_missed(ev, problem.epigraph):
                    fallbacks.append(f"{m} start {i + 1}: {what_broke(problem, material, s, ev)}")
                    bound = outranked_before_rounding(problem, material, s, cap) if m == "ipopt" and i == 0 else None
                    if bound is not None:
                        fallbacks.append(f"outranked: its answer before rounding, {bound.objective:.4g}, is more than "
                                         f"{CONTENDER_BAND:.0%} above the best design found before it; not repaired")
                        return Candidate(material.name, problem.family, None, tuple(solves), tuple(fallbacks),
                                         continuous=bound, outranked=True, unrounded=True, tried=tuple(tried))
                    if kept is not None:
                        fallbacks.append(f"{m} start {i + 1}: on stock: rounding broke a limit; its answer before "
                                         "rounding kept as the rows' start and bound")
                        ev = kept
                    elif m == "ipopt":
                        s, ev = back_off(problem, params, material, s, ev, solves, fallbacks,
                                          f"{m} start {i + 1}", front=neighbour is not None or not repair)
                    else:
                        ev = onto_the_grid(problem, material, s, ev)
                if m == "ipopt" and s.success and ev.feasible and repair:
                    ev = closer_on_the_grid(problem, params, material, s, ev, solves, neighbour)
                done.append((raw, s, ev, i))
            if m == "ipopt" and s.success and only_targets_missed(ev, problem.epigraph):
                verdicts += 1  # the least error this family reaches misses the targets
            checked.append(ev)
            answers[id(ev)] = s
            evaluation = pick(checked)
            if (proves is not None and i == 0 and m == method == "ipopt" and len(starts) > 1
                    and s.message in IPOPT_INFEASIBLE and not ev.feasible):
                proved, relaxation = proves()
                solves.extend(relaxation)
                if proved:
                    break
            if s.success and ev.feasible and winner is None and m == method:
                winner = x0
            if s.success and ev.feasible and not all_starts:
                break  # a verified answer: the other starts are kept for failures
        if proved:
            fallbacks.append(proved)
            break
        # a feasible design from a solver that failed on every start is only its start point:
        # the fallback method still runs
        if evaluation is not None and evaluation.feasible and any(x.success for x in solves):
            break
        if m != method or method == "grid":
            break
        if verdicts == len(starts):
            fallbacks.append(f"{m}: every start ended in a verdict (locally infeasible, or the targets out of "
                                  "reach); no fallback")
            break
    return Candidate(material.name, problem.family, evaluation, tuple(solves), tuple(fallbacks), tried=tuple(tried),
                     winner=winner, solution=answers.get(id(evaluation)))


def _unmachinable(spec, fam: Family) -> str:
    """Why no design of ``fam`` can be machined under ``spec`` ('' when one can): a slot needs an
    end mill that cuts it with the spec's corner radius and leaves the gauge a flat floor, and
    that depends on the spec alone (``outputs.cad.mills.slot_end_mill``)."""
    if fam.section != "rectangle" or fam.feature != "pocket":
        return ""
    from designer.errors import DesignFileError
    from designer.outputs.cad.mills import slot_end_mill

    try:
        slot_end_mill(spec)
    except DesignFileError as exc:
        return f"no slot can be machined: {exc}"
    return ""


def optimize(spec, method: str = "ipopt", progress=None, materials=None, tie_break: bool = True,
             problems: dict | None = None, warm: dict | None = None, skip=(), outrank: bool = True,
             known: dict | None = None, closest: bool = True) -> SearchResult:
    """Search every allowed material and section family; return the verified best design.

    ``progress``, if given, is called as ``progress(done, total)`` after each candidate.
    ``problems`` maps a family to the ``FamilyProblem`` to solve it with (built here when not
    given); ``warm`` maps ``(material name, family)`` to a Candidate whose checked design that
    candidate's solves start from before the usual starts, IPOPT with its solve's multipliers: a
    trade-off front's neighbouring level (the contenders are then not solved again from every
    start: the warm start is their other one).
    ``skip`` holds ``(material name, family)`` pairs not solved (no design; a trade-off front's
    candidates that a looser level of its limit already left without a feasible design);
    ``known`` maps such pairs to the Candidate taken as it is (a front's design that the swept
    limit does not bind, from the neighbouring level).
    ``outrank``: a candidate whose first answer, before rounding, is CONTENDER_BAND above the best
    design found before it is not repaired (``solve_candidate``'s ``cap``); a trade-off front, which
    draws every candidate of its materials, asks for each. ``closest``: when no candidate has a
    feasible design, each is solved again for its closest one (``closest.closest_designs``), which
    the diagnosis reasons from; a trade-off front's levels, whose infeasible points are not
    reported, do without.
    """
    if method not in METHODS:
        raise SpecError(f"method: {method!r} is not allowed; must be {describe_allowed(METHODS)}")
    t0 = time.perf_counter()
    mats = [catalogue.material(m, "search.materials") for m in (materials or spec.search.materials)]
    fams = families(spec)
    candidates: list[Candidate] = []
    given, problems = problems or {}, {}
    warm = warm or {}
    total = len(mats) * len(fams)
    unmachinable = {}
    # groups of materials with no design that meets every limit, found by a relaxation
    # (``_relaxing``): (family, the relaxations' solves, the proving one's answer, the material
    # whose verdict began it, the others)
    proved = []
    for fam in fams:
        problem = given.get(fam) or FamilyProblem(spec, fam)
        problems[fam] = problem
        why = _unmachinable(spec, fam)
        if why:
            unmachinable[fam] = why
        usual = problem.starts()  # the family's own; the one that gave the last verified answer goes first
        relaxed, done = [], set()  # relaxations run in this family; materials they proved infeasible
        for k, mat in enumerate(mats):
            if mat.name in done:
                continue
            if (mat.name, fam) in (known or {}):
                candidates.append(known[(mat.name, fam)])
                continue
            if (mat.name, fam) in skip:
                candidates.append(Candidate(mat.name, fam, None, (), ("not solved: no feasible design at a looser "
                                                                      "level of the same limit",)))
                continue
            prior = warm.get((mat.name, fam))
            start = None if prior is None else prior.evaluation
            leads = _continuous_leads(spec, candidates)
            cap = min(leads) * (1 + CONTENDER_BAND) if leads and method == "ipopt" and outrank else None
            rest = [m for m in mats[k + 1:] if (m.name, fam) not in skip and m.name not in done]
            proves = (None if why or method != "ipopt" or any((m.name, fam) in warm for m in [mat] + rest)
                      else _relaxing(problem, mat, rest, usual, relaxed, done, proved))
            cand = (Candidate(mat.name, fam, None, (), (why,)) if why
                    else solve_candidate(problem, mat, method, proves=proves, neighbour=start, cap=cap,
                                         repair=stock_system(spec, fam) == "none",
                                         warm=None if prior is None else prior.solution,
                                         starts=usual if start is None else [start_from(problem, start)] + usual))
            if any(x is cand.winner for x in usual):  # the next material is near it: that start first
                usual = [cand.winner] + [x for x in usual if x is not cand.winner]
            candidates.append(cand)
            if progress is not None:
                progress(len(candidates), total)
    if proved:
        candidates = _proved_infeasible(problems, proved, candidates, method, progress, total)
    if method == "ipopt" and not warm:
        candidates = every_start_for_contenders(spec, candidates, problems)
    candidates = candidates_on_stock(spec, problems, candidates, skip)
    if method == "ipopt" and tie_break:  # the other methods are compared as they are (``bench``)
        candidates = break_ties(candidates, problems)
    if closest and not any(c.evaluation is not None and c.evaluation.feasible for c in candidates):
        candidates = closest_designs(spec, problems, candidates)
    candidates += [Candidate(m.name, fam, None, (), (f"not searched: {why}",))
                   for fam, why in unsearchable(spec).items() for m in mats]
    seconds = time.perf_counter() - t0
    evaluations = sum(s.evaluations for c in candidates for s in c.solves)
    feasible = model.rank([c.evaluation for c in candidates if c.evaluation is not None and c.evaluation.feasible])
    order = {id(ev): i for i, ev in enumerate(feasible)}

    def cand_key(c):
        # an outranked candidate stands at its answer before rounding (no bound on its designs,
        # docs/model.md section 5): before the first design above it, never before the chosen one
        # (a stock search's outranked flag comes from its rows' bounds, tighter than the continuous one)
        if c.outranked:
            bound = c.continuous.objective
            if not feasible:
                return (2, 0, bound, 0)
            return (0, max(1, next((i for i, ev in enumerate(feasible) if ev.objective > bound), len(feasible))),
                    0, bound)
        if c.evaluation is None:
            return (2, 1, 0, 0)
        if c.evaluation.feasible:
            return (0, order[id(c.evaluation)], 1, 0)
        return (1, *closeness(c.evaluation), c.evaluation.objective)

    candidates.sort(key=cand_key)
    solver = {"method": method, "seconds": seconds, "evaluations": evaluations,
              "solves": sum(len(c.solves) for c in candidates),
              "fallbacks": [f"{c.material} {c.family.label}: {f}" for c in candidates for f in c.fallbacks]}
    if not any(c.evaluation is not None for c in candidates):
        if crowded := no_room(spec):
            raise SpecError(crowded)
        if unmachinable:
            raise SpecError("search.sections: " + "; ".join(f"{fam.label}: {why}" for fam, why in unmachinable.items()))
        notes = "; ".join(dict.fromkeys(c.stock_note for c in candidates if c.stock_note))
        if spec.search.stock != "none":
            raise SpecError(f"search.stock: {spec.search.stock!r} leaves no stock size to try: {notes}; try stock: "
                            "any, other materials or sections, or wider limits")
        if notes:
            raise SpecError(f"search.sections: {', '.join(spec.search.sections)} leaves no size to try: {notes}; "
                            "try rectangle or round sections, other materials, or wider limits")
        raise SolverError("no solver returned a design that could be evaluated; try another method")
    best = candidates[0].evaluation
    if best.feasible:
        status, messages = "optimal", []
        message = f"{best.design.label()} meets every limit"
    else:
        # (with no room for the stations whatever the section, the diagnosis names that alone)
        found = {} if not closest or no_room(spec) else {
            "plain": remedies.plain(spec, lambda moved: optimize(moved, method, closest=False)),
            **{name: how(spec, problems, candidates[0], method, solve_candidate)
               for name, how in (("farther", remedies.farther), ("looser", remedies.looser))}}
        status, messages = "infeasible", diagnose(spec, best, candidates, **found)
        message = messages[0]
    if best.design.stock is not None:
        message = f"{best.design.label()} ({best.design.stock.label}) " + ("meets every limit" if best.feasible
                                                                         else "is the least infeasible stock design")
    return SearchResult(success=best.feasible, status=status, message=message, x=best.design, best=best,
                        candidates=candidates, solver=solver, messages=messages, seconds=seconds, nfev=evaluations,
                        continuous=continuous_optimum(spec, problems, candidates))


# Materials whose Young's moduli are within this of each other are relaxed together when a
# relaxation over every remaining material of the family finds a design: the modulus sets the
# stiffness and the strain, the limits that most often leave a material without a design.
ALIKE = 0.10
# ... when the relaxation would spare this many other materials at least (it takes as many solves
# as one material: every start)
RELAXED_AT_LEAST = 2


def _relaxing(problem: FamilyProblem, material, rest: list, usual: list, relaxed: list, done: set, proved: list):
    """What ``solve_candidate`` calls when ``material``'s first start ends in an infeasibility
    verdict: IPOPT on the relaxation (``FamilyProblem.infeasible_for_every``) over ``material`` and
    the family's other remaining materials (the family's first relaxation), then, if that finds a
    design, over those of a Young's modulus within ALIKE of its own. When one is infeasible too,
    none of its materials has a design: they join ``done`` and ``proved``, and the note for
    ``material`` is returned with no solves (they go with the materials proved); else '' and the
    relaxations' solves. Each relaxation tries first the starts the material has not. None when
    no group has RELAXED_AT_LEAST other materials."""
    alike = [m for m in rest if abs(m.E / material.E - 1) <= ALIKE]
    groups = [g for g in ([] if relaxed else [rest]) + [alike]
              if len(g) >= RELAXED_AT_LEAST and (g is rest or relaxed or len(g) < len(rest))]
    if not groups:
        return None

    def proves() -> tuple[str, tuple]:
        ran = []
        for group in groups:
            relaxed.append(group)
            infeasible, solves = problem.infeasible_for_every([material] + group, starts=usual[1:] + usual[:1])
            if infeasible:
                proved.append((problem.family, tuple(ran) + tuple(solves), solves[0].x, material, group))
                done.update(m.name for m in group)
                return (f"its other starts not run: with the material's properties free between the least and the "
                        f"greatest of {_names([material] + group)}, IPOPT finds no design of {problem.family.label} "
                        "that meets every limit (every start)"), ()
            ran += solves
        return "", tuple(ran)
    return proves


def _names(materials) -> str:
    names = [m.name for m in materials]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _proved_infeasible(problems: dict, proved: list, candidates: list, method: str, progress, total: int) -> list:
    """The candidates of the materials a relaxation proved to have no feasible design in their
    family (``_relaxing``): each material's design at the relaxation's answer, rounded and checked
    (its least violation found there). When no candidate has a feasible design, they are solved in
    full instead, as every candidate is, so that the least-infeasible design (and the diagnosis
    built on it) is each candidate's own: the material whose verdict began a relaxation is then
    solved from its other starts too. Returns ``candidates`` with these added."""
    solved_elsewhere = any(c.evaluation is not None and c.evaluation.feasible for c in candidates)
    if not solved_elsewhere:
        began = {(first.name, fam) for fam, _, _, first, _ in proved}
        candidates = [_in_full(problems[c.family], c, method) if (c.material, c.family) in began else c
                      for c in candidates]
    out = []
    for fam, relaxation, at, first, materials in proved:
        problem = problems[fam]
        for i, mat in enumerate(materials):
            if not solved_elsewhere:
                cand = solve_candidate(problem, mat, method)
                cand = replace(cand, solves=(tuple(relaxation) if i == 0 else ()) + cand.solves)
            else:
                ev = round_and_check(problem.design(at, mat), problem.spec)
                # said in full once a group, on the candidate that carries the relaxation's solves
                note = (f"not solved: infeasible, as {first.name} is; with the material's properties free between the "
                        f"least and the greatest of {_names([first] + materials)}, IPOPT finds no design of "
                        f"{fam.label} that meets every limit (every start); the design shown is the one at that answer"
                        if i == 0 else f"not solved: infeasible, as {first.name} is (see {materials[0].name})")
                cand = Candidate(mat.name, fam, ev, tuple(relaxation) if i == 0 else (), (note,))
            out.append(cand)
            if progress is not None:
                progress(len(candidates) + len(out), total)
    return candidates + out


def _in_full(problem: FamilyProblem, cand: Candidate, method: str) -> Candidate:
    """``cand``, stopped after its first start by a relaxation's verdict, solved from every start."""
    again = solve_candidate(problem, catalogue.material(cand.material), method)
    return replace(again, solves=cand.solves + again.solves)


def resolve(spec, family: Family, previous: Evaluation, adjustment, method: str = "ipopt",
            margin: float = 0.0) -> Candidate:
    """``previous``'s material and ``family`` solved again with the model adjusted by
    ``adjustment`` (a ``model.Adjustment``), from ``previous`` first and then the usual starts;
    IPOPT keeps every constraint ``margin`` inside its limit. A family on stock
    (``stock.stock_system``) has its rows searched again, the section staying a row. No tie-break
    stage: it would move the design back onto the limits the margin keeps it off."""
    problem = FamilyProblem(spec, family, adjustment)
    material = previous.design.material
    if stock_system(spec, family) != "none":  # the section stays a stock row: the rows are searched again
        found = search_stock(problem, material, start_from(problem, previous), margin=margin)
        return Candidate(material.name, family, found.evaluation, found.solves, stock_note=found.note)
    starts = [start_from(problem, previous)] + problem.starts()
    return solve_candidate(problem, material, method, starts=starts, margin=margin)


# Candidates whose verified objective is within this of the best are solved from every start, not
# only up to the first verified answer: the feature corrections (docs/model.md §7) leave the NLP
# more than one local optimum, and the first start's may lose to a runner-up's by a few per cent.
CONTENDER_BAND = 0.05
# ... from these starts (the sections' share of their range): the usual two, and one between them
# for those within LEADER_BAND of the best (on the bench suite's 039-nearly-infeasible only that
# start finds the Ti-6Al-4V rectangle's best, 0.18 % better)
CONTENDER_STARTS = (0.35, 0.7, 0.5)
LEADER_BAND = 0.01


def _continuous_leads(spec, candidates: list) -> list[float]:
    """The objectives of the feasible candidates that bound the others: a family on stock is searched
    on its rows later, so its continuous design is no lead (on the bench suite's 011-loose-limits the
    tubes' continuous answer kept the rectangles out of the contenders, though their start at 70 %
    gives a bar 5 % lighter than the tubes' stock row)."""
    return [c.evaluation.objective for c in candidates if c.evaluation is not None and c.evaluation.feasible
            and stock_system(spec, c.family) == "none"]


def every_start_for_contenders(spec, candidates: list, problems: dict) -> list:
    """``candidates`` with each contender (feasible, within CONTENDER_BAND of the best objective of
    ``_continuous_leads``) solved again from every start, keeping the better verified design."""
    feasible = _continuous_leads(spec, candidates)
    if not feasible:
        return candidates
    lead = min(feasible)
    out = []
    for c in candidates:
        problem = problems[c.family]
        ev = c.evaluation
        if ev is None or not ev.feasible or ev.objective > lead * (1 + CONTENDER_BAND):
            out.append(c)
            continue
        material = catalogue.material(c.material)
        stocked = stock_system(spec, c.family) != "none"  # its rows are searched later from this answer
        fractions = CONTENDER_STARTS if ev.objective <= lead * (1 + LEADER_BAND) else CONTENDER_STARTS[:2]
        # (a family on stock: its answer is the rows' start and bound, and its rows are searched from
        # several starts anyway; only the smaller ranges, which the reported continuous optimum needs)
        untried = [] if stocked else [x for x in problem.starts(fractions)
                                      if not any(np.array_equal(x, t) for t in c.tried)]
        if untried:
            again = solve_candidate(problem, material, "ipopt", all_starts=True, starts=untried)
            better = (again.evaluation is not None and again.evaluation.feasible
                      and again.evaluation.objective < ev.objective)
            c = (replace(again, solves=c.solves + again.solves, fallbacks=c.fallbacks + again.fallbacks)
                 if better else replace(c, solves=c.solves + again.solves))
        solves, ranged = _in_smaller_ranges(problem, material, c.evaluation)
        c = replace(c, solves=c.solves + tuple(solves))
        if ranged is not None and ranged.objective < c.evaluation.objective:
            c = replace(c, evaluation=ranged, fallbacks=c.fallbacks + (
                "held below the end of a smaller size range of the tolerance class, where its deviation is smaller",))
        out.append(c)
    return out


def _in_smaller_ranges(problem: FamilyProblem, material, ev: Evaluation) -> tuple[list, Evaluation | None]:
    """With an ISO 2768 class (docs/model.md §14), each toleranced size of ``ev`` held at most at the
    end of the next smaller size range, where the class's deviation is smaller, and the rest solved
    again from ``ev``: the solves, and the best of their checked designs that meets every limit (None
    if none does). The deviations step up with the size, so an optimum may sit at a range's end,
    which a solve with the deviations of one range does not see."""
    x = start_from(problem, ev)
    lo, _ = problem.bounds()
    solves, found = [], []
    for i in problem.moved:
        end = problem.spec.tolerances.smaller_range_end(x[i] * MM, TOLERANCED[problem.names[i]])
        if end is None or end / MM <= lo[i]:
            continue
        s = problem.solve_ipopt(problem.params(material), x, box={i: (lo[i], end / MM)})
        solves.append(s)
        checked = round_and_check(problem.design(s.x, material), problem.spec) if s.success else None
        if checked is not None and checked.feasible:
            found.append(checked)
    return solves, pick(found)


def break_ties(candidates: list, problems: dict) -> list:
    """The tie rule as a second stage (docs/model.md §5).

    Near the optimum the objective is often flat (a strain-limited design has a sensitivity
    that does not depend on the material), so many designs lie within 0.1 % of the best. Each
    candidate inside that band is re-solved for the secondary objective (deflection, or mass
    when deflection is the objective) with its primary objective capped at half the band; the
    answer is kept only if it checks out, stays under that cap once rounded, and ranks before the
    candidate's first answer (kept to the whole band, the bench suite's 033-loose-limits chose a
    design 0.09 % above its lead, 0.103 % above CCSAQ's design: outside the band of the best found).
    """
    feasible = [c for c in candidates if c.evaluation is not None and c.evaluation.feasible]
    if not feasible:
        return candidates
    lead = min(c.evaluation.objective for c in feasible)
    cap = lead * (1 + model.TIE_TOLERANCE / 2)
    in_band = {id(c) for c in feasible if c.evaluation.objective <= lead * (1 + model.TIE_TOLERANCE)}
    out = []
    for cand in candidates:
        if id(cand) not in in_band:
            out.append(cand)
            continue
        problem = problems[cand.family]
        material = cand.evaluation.design.material
        x0 = start_from(problem, cand.evaluation)
        if problem.epigraph:
            x0[-1] = min(x0[-1], cap)
        # the NLP's primary objective is in mm (deflection) or g (mass), Evaluation.objective in SI
        nlp_cap = in_nlp_units(cap, problem.spec.objective)
        stock = cand.evaluation.design.stock  # a stock section stays the row it is
        fixed = None if stock is None else {i: x0[i] for i, n in enumerate(problem.names) if n in SECTION_VARIABLES}
        s = problem.solve_ipopt(problem.params(material, nlp_cap), x0, stage="secondary", fixed=fixed)
        design = problem.design(s.x, material)
        if stock is not None:
            design = same_section(design, cand.evaluation.design)
        ev = round_and_check(design, problem.spec)
        better = ev is not None and ev.feasible and ev.objective <= cap and \
            model.ranks_before(ev, cand.evaluation)
        out.append(replace(cand, evaluation=ev if better else cand.evaluation, solves=cand.solves + (s,)))
    return out
