"""The library pipeline: a spec in, a complete and frozen design result out.

``design(spec, options)`` runs the search, the large-deflection check (elastica), the optional
3-D check and the trade-off fronts, and builds the design.json record once from all of them;
``evaluate_fixed(spec)`` does the same for the spec's fixed ``design:`` block. The commands
only parse, call these and write files.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from designer import model
from designer.result.evaluation import Evaluation, evaluate, fixed_design
from designer.result.record import build_record, search_record


@dataclass(frozen=True)
class DesignOptions:
    """How ``design`` runs: the search method, the 3-D check, the fronts, progress reports."""

    method: str = "ipopt"
    verify: bool = False
    verify_mesh: str = "normal"
    tradeoff: bool = True
    progress: Callable[[str, int, int], None] | None = None  # progress(stage, done, total)


@dataclass(frozen=True)
class DesignResult:
    """Everything a run found. ``record`` is design.json; ``verification`` the 3-D verdict."""

    record: dict
    evaluation: Evaluation
    search: object = None          # search.SearchResult, for optimised designs
    verification: object = None    # checks.fea.VerifyResult, when the 3-D check ran
    tradeoff: dict | None = None

    @property
    def status(self) -> str:
        return self.record["status"]

    @property
    def success(self) -> bool:
        return self.status in ("optimal", "feasible")


def design(spec, options: DesignOptions = DesignOptions()) -> DesignResult:
    """Search ``spec`` for the best design and check it (docs/model.md §5)."""
    from designer.search.run import optimize

    report = options.progress
    found = optimize(spec, method=options.method,
                     progress=None if report is None else (lambda done, total: report("search", done, total)))
    status = found.status
    record = _with_large_deflection(search_record(spec, found))
    verification = None
    if options.verify and status == "optimal":
        if report is not None:
            report("3-D check", 0, 1)
        verification, record = _verified(record, options.verify_mesh)
    tradeoff = None
    if options.tradeoff and found.success and spec.objective == "error":
        from designer.search.tradeoff import fronts

        if report is not None:
            report("trade-off fronts", 0, 1)
        tradeoff = fronts(spec, found)
    return DesignResult(record, found.best, found, verification, tradeoff)


def evaluate_fixed(spec) -> DesignResult:
    """Judge the spec's fixed ``design:`` block, rounded to 0.01 mm as every reported design is."""
    ev = evaluate(fixed_design(spec).rounded(), spec)
    messages = [] if ev.feasible else ["the design violates: " + ", ".join(v.name for v in ev.violations)]
    record = build_record("feasible" if ev.feasible else "infeasible", spec, ev, messages=messages)
    return DesignResult(_with_large_deflection(record), ev)


def _with_large_deflection(record: dict) -> dict:
    """The record with the elastica's figures where linear theory stops holding."""
    if not model.is_large_deflection(record["predicted"]["deflection"], record["design"]["length"]):
        return record
    from designer.checks.elastica import large_deflection

    result = large_deflection(record)
    return {**record, "large_deflection": result.as_dict(), "messages": record["messages"] + [result.summary()]}


def _verified(record: dict, mesh: str):
    """The 3-D check of the chosen design; one that fails it is reported infeasible, never shipped."""
    from designer.checks import fea

    verdict = fea.verify_design(record, mesh=mesh)
    summary = verdict.as_dict()
    summary.pop("profile", None)  # the strain profile goes to verify.json only
    messages = list(record["messages"])
    status = record["status"]
    if not verdict.passed:
        failed = [c.name for c in verdict.limits if not c.satisfied]
        status = "infeasible"
        messages.append("the 3-D check finds limits the beam model missed: " + ", ".join(failed) + "; see verify.md")
    messages.extend(m for m in verdict.messages if m not in messages)
    return verdict, {**record, "status": status, "verification": summary, "messages": messages}
