"""Every method on every spec of the suite, and what is known of each spec.

For every spec the best known design is the best verified design over all methods and the
exhaustive reference search (``reference.reference_best``, no casadi, no nlopt), ranked by
``model.rank``; the spec is feasible when any of them found a design that meets every limit.
Every method's answer is re-checked from its design.json record alone (``designfile.rebuild`` +
``evaluation.evaluate``); its gap, time and failures are recorded both for the pipeline's final
answer and for the raw solver runs (``Candidate.solves``).
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from designer import model
from designer.bench.suite import DEFAULT_SEED, KINDS, SuiteSpec
from designer.errors import FpdError, InputError, describe_allowed
from designer.search.problem import METHODS
from designer.spec import catalogue

REFERENCE_LEVELS = 5           # grid points per variable of the reference search (coarse, fast)
SOLVER_TOLERANCE = 1e-6        # a solver's unrounded answer within this (normalised) meets a limit


# --------------------------------------------------------------------------- one method on one spec

@dataclass
class Run:
    """One method on one spec: what the pipeline answered, re-checked, and what its solvers did."""

    spec: str
    kind: str
    method: str
    seconds: float
    error: str = ""                   # an exception optimize() raised: the run gave no answer
    unreadable: str = ""              # why designfile.validate refused the design.json record
    status: str = ""                  # the record's status: optimal | infeasible
    objective: float | None = None    # of the reported design, re-evaluated from design.json
    worst_violation: float | None = None
    violated: tuple = ()
    deflection: float | None = None
    mass: float | None = None
    design: str = ""
    candidates: int = 0
    solves: int = 0                   # runs of the method itself (not its fallback)
    solver_successes: int = 0
    false_successes: int = 0          # said success, but its own answer breaks a limit it was given
    rounding_breaks: int = 0          # said success and met the limits, but no rounded design does
    solver_exceptions: int = 0        # the solver raised (caught by the adapter)
    fallback_solves: int = 0          # runs of the fallback method
    fallbacks: int = 0                # lines in record['solver']['fallbacks']
    raw_objective: float | None = None  # best verified design from the method's own runs alone
    evaluations: int = 0
    record: dict | None = field(default=None, repr=False)

    @property
    def feasible(self) -> bool:
        """The re-checked answer meets every limit."""
        return self.worst_violation is not None and self.worst_violation <= model.FEASIBILITY_TOLERANCE


def run_method(item: SuiteSpec, method: str) -> Run:
    """``optimize`` with one method; every exception is caught and recorded, never raised."""
    from designer.result.record import search_record
    from designer.search import optimize

    t0 = time.perf_counter()
    try:
        outcome = optimize(item.spec, method)
    except Exception as exc:  # noqa: BLE001 - the bench records every failure
        return Run(item.name, item.kind, method, time.perf_counter() - t0,
                   error=f"{type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - t0
    run = Run(item.name, item.kind, method, seconds, status=outcome.status,
              candidates=len(outcome.candidates), fallbacks=len(outcome.solver.get("fallbacks", [])),
              evaluations=outcome.evaluations)
    _recheck(run, search_record(item.spec, outcome))
    _solver_counts(run, item.spec, outcome)
    return run


def _recheck(run: Run, record: dict) -> None:
    """Re-evaluate the reported design from its design.json record alone."""
    from designer.result import designfile
    from designer.result.evaluation import evaluate

    try:
        copy_ = json.loads(json.dumps(record, allow_nan=False))
    except (ValueError, TypeError) as exc:
        run.unreadable = f"not valid JSON: {exc}"
        return
    try:
        designfile.validate(copy_)
    except FpdError as exc:  # the product's own reader refuses it; still judged below if it can be
        run.unreadable = str(exc)
    try:
        spec, design = designfile.rebuild(copy_)
        ev = evaluate(design, spec)
    except (FpdError, ValueError, KeyError, TypeError, ArithmeticError) as exc:
        run.unreadable = run.unreadable or f"cannot be rebuilt: {type(exc).__name__}: {exc}"
        return
    run.record = copy_
    run.objective = float(ev.objective)
    run.worst_violation = float(ev.worst_violation)
    run.violated = tuple(v.name for v in ev.violations)
    run.deflection = float(ev.analysis.deflection)
    run.mass = float(ev.analysis.mass)
    run.design = ev.design.label() + ("" if ev.design.geometry.feature in ("pocket", "none")
                                      else f"+{ev.design.geometry.feature}")


def _solver_counts(run: Run, spec, outcome) -> None:
    """The raw solver behaviour from the Solve records: successes, false successes, exceptions,
    and the best verified design the method found on its own (without its fallback)."""
    from designer.search import round_and_check

    own = []
    for cand in outcome.candidates:
        design_of = _solver_design(spec, cand.family)
        material = catalogue.material(cand.material)
        for s in cand.solves:
            if s.method != run.method:
                run.fallback_solves += 1
                continue
            run.solves += 1
            if _raised(s):
                run.solver_exceptions += 1
            try:
                ev = round_and_check(design_of(s.x, material), spec)
            except (FpdError, ValueError, ArithmeticError):
                ev = None
            if s.success:
                run.solver_successes += 1
                if ev is None or _breaks_limits(ev, spec):
                    if _unrounded_breaks(design_of(s.x, material), spec):
                        run.false_successes += 1
                    else:
                        run.rounding_breaks += 1
            if ev is not None:
                own.append(ev)
    feasible = [ev for ev in own if ev.feasible]
    if feasible:
        run.raw_objective = float(model.rank(feasible)[0].objective)


def _solver_design(spec, family):
    """``design(x, material)``: the Design a solver's ``x`` (mm) stands for in ``family``, from the
    family's variables alone; the bench has no use for the casadi graph ``FamilyProblem`` builds."""
    from designer.search import FamilyVariables

    return FamilyVariables.of(spec, family).design


def _raised(solve) -> bool:
    """The adapters turn a solver's exception into a failed Solve whose message names it."""
    message = solve.message
    return not solve.success and (message.startswith("IPOPT raised")
                                  or (message.startswith("nlopt ") and not message.startswith("nlopt result")))


def _unrounded_breaks(design, spec) -> bool:
    """The solver's own answer, before rounding, breaks a limit by more than SOLVER_TOLERANCE."""
    from designer.result.evaluation import evaluate

    try:
        with np.errstate(all="ignore"):
            ev = evaluate(design, spec)
    except (FpdError, ValueError, ArithmeticError):
        return True
    targets = model.TARGET_LIMITS if spec.objective == "error" else ()
    worst = [float(lim.normalised) for lim in ev.limits if lim.name not in targets]
    return not all(math.isfinite(w) and w <= SOLVER_TOLERANCE for w in worst)


def _breaks_limits(ev, spec) -> bool:
    """A limit the solver was asked to meet is broken. With the error objective the targets are
    the objective (e <= 1 is a verdict, not a constraint of the solve)."""
    targets = model.TARGET_LIMITS if spec.objective == "error" else ()
    return any(v.name not in targets for v in ev.violations)


# --------------------------------------------------------------------------- the best known design

@dataclass(frozen=True)
class Truth:
    """What is known of one spec after every method and the reference search."""

    spec: str
    kind: str
    expected: str | None
    feasible: bool
    lead: float | None          # the lowest verified objective (the tie band is measured from it)
    best: float | None          # the best known design's objective (MODEL.md 5 ranking)
    best_by: str                # who found it
    reference: float | None     # the reference search's objective
    reference_feasible: bool
    reference_seconds: float
    objective: str

    @property
    def verdict(self) -> str:
        return "feasible" if self.feasible else "infeasible"


def establish_truth(item: SuiteSpec, runs: list[Run], levels: int = REFERENCE_LEVELS) -> Truth:
    """The best known design of one spec: the reference search and every run's re-checked answer,
    ranked by ``model.rank`` (MODEL.md 5)."""
    from designer.result import designfile
    from designer.search import reference
    from designer.result.evaluation import evaluate

    t0 = time.perf_counter()
    try:
        ref = reference.reference_best(item.spec, levels=levels)
    except (FpdError, ValueError, ArithmeticError):
        ref = None
    ref_seconds = time.perf_counter() - t0
    ref_objective = None if ref is None else float(ref.objective)
    found = []  # (evaluation, who found it)
    if ref is not None and ref.feasible:
        found.append((ref, "reference"))
    for run in runs:
        if run.record is not None and run.feasible:
            spec, design = designfile.rebuild(run.record)
            found.append((evaluate(design, spec), run.method))
    if not found:
        return Truth(item.name, item.kind, item.expected, False, None, None, "", ref_objective, False, ref_seconds,
                     item.spec.objective)
    best = model.rank([ev for ev, _ in found])[0]
    who = sorted({w for ev, w in found if _same(ev, best)})
    lead = min(float(ev.objective) for ev, _ in found)
    return Truth(item.name, item.kind, item.expected, True, lead, float(best.objective), ", ".join(who),
                 ref_objective, bool(ref is not None and ref.feasible), ref_seconds, item.spec.objective)


def _same(a, b) -> bool:
    return a.design.label() == b.design.label() and abs(a.objective - b.objective) <= 1e-12 * abs(b.objective)


def gap(run: Run, truth: Truth) -> float | None:
    """Objective above the lowest verified objective, as a fraction; 0 inside the tie band
    (MODEL.md 5: designs within 0.1 % tie and rank by deflection, then mass); inf when the
    spec is feasible but the run gave no design that meets every limit; None for an
    infeasible spec."""
    if not truth.feasible:
        return None
    if run.error or not run.feasible or run.status != "optimal":
        return math.inf
    return _tie_gap(run.objective, truth.lead)


def raw_gap(run: Run, truth: Truth) -> float | None:
    """The same for the method's own runs, without the fallback method."""
    if not truth.feasible:
        return None
    if run.raw_objective is None:
        return math.inf
    return _tie_gap(run.raw_objective, truth.lead)


def exact_gap(run: Run, truth: Truth) -> float | None:
    """Objective above the lowest verified objective, without the tie band."""
    if not truth.feasible or run.objective is None or not run.feasible:
        return None
    return max(run.objective / truth.lead - 1, 0.0) if truth.lead > 0 else run.objective - truth.lead


def _tie_gap(objective: float, lead: float) -> float:
    if model.ties(objective, lead):
        return 0.0
    return objective / lead - 1 if lead > 0 else objective - lead


FAILURE_KINDS = ("exception", "violating", "missed", "unreadable")


def failures(run: Run, truth: Truth) -> dict:
    """The pipeline's failures on one spec, by kind (each 0 or 1)."""
    reported_optimal = not run.error and run.status == "optimal"
    return {
        "exception": int(bool(run.error)),
        "violating": int(reported_optimal and not run.feasible),        # optimal, yet a limit is broken
        "missed": int(not run.error and truth.feasible and run.status != "optimal"),  # feasible called infeasible
        "unreadable": int(bool(run.unreadable)),                        # design.json its reader refuses
    }


# --------------------------------------------------------------------------- the bench

@dataclass
class BenchResult:
    """Every run of every method on every spec, and what is known of each spec."""

    suite: list
    methods: tuple
    runs: list
    truths: dict                 # spec name -> Truth
    seed: int
    count: int
    levels: int
    skipped: list = field(default_factory=list)   # example files left out (fixed designs)
    seconds: float = 0.0

    def truth(self, run: Run) -> Truth:
        return self.truths[run.spec]

    @property
    def kinds(self) -> list[str]:
        present = {item.kind for item in self.suite}
        return [k for k in ("example",) + KINDS if k in present]


def run_bench(suite: list, methods=METHODS, levels: int = REFERENCE_LEVELS, progress=None, seed: int = DEFAULT_SEED,
              count: int | None = None, skipped=()) -> BenchResult:
    """Run every method on every spec of ``suite``, then the reference search; ``progress(done,
    total, name)`` is called after each spec. The methods' order turns by one from spec to spec,
    so that no method always runs first on a busy machine."""
    methods = tuple(methods)
    for m in methods:
        if m not in METHODS:
            raise InputError(f"methods: {m!r} is not allowed; must be {describe_allowed(METHODS)}")
    t0 = time.perf_counter()
    if suite:
        _warm_up(suite[0], methods)
    runs, truths = [], {}
    for i, item in enumerate(suite):
        order = methods[i % len(methods):] + methods[:i % len(methods)]
        spec_runs = {m: run_method(item, m) for m in order}
        truths[item.name] = establish_truth(item, list(spec_runs.values()), levels)
        runs += [spec_runs[m] for m in methods]
        if progress is not None:
            progress(i + 1, len(suite), item.name)
    return BenchResult(list(suite), methods, runs, truths, seed,
                       sum(1 for s in suite if s.kind != "example") if count is None else count, levels,
                       list(skipped), time.perf_counter() - t0)


def _warm_up(item: SuiteSpec, methods) -> None:
    """One small untimed search per method: libraries and solver plugins load before the clock runs."""
    from designer.search import optimize

    spec = item.spec
    small = replace(spec, search=replace(spec.search, materials=spec.search.materials[:1],
                                         sections=spec.search.sections[:1]))
    for m in methods:
        try:
            optimize(small, m)
        except Exception:  # noqa: BLE001 - the timed run records it
            pass

