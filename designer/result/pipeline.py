"""The library pipeline: a spec in, a complete and frozen design result out.

``design(spec, options)`` runs the search, the large-deflection check (elastica), the optional
3-D check with its correction loop (``result.correct``) and the trade-off fronts, and builds the
design.json record once from all of them;
``evaluate_fixed(spec)`` does the same for the spec's fixed ``design:`` block. The commands
only parse, call these and write files.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

from designer import model
from designer.errors import InputError
from designer.result import correct
from designer.result.evaluation import Evaluation, evaluate, fixed_design
from designer.result.record import build_record, search_record, stock_summary


@dataclass(frozen=True)
class DesignOptions:
    """How ``design`` runs: the search method, the 3-D check and its correction rounds, the
    fronts, progress reports."""

    method: str = "ipopt"
    verify: bool = False
    verify_mesh: str = "normal"
    verify_rounds: int = correct.MAX_ROUNDS  # corrected rounds after the first 3-D check
    tradeoff: bool = True
    progress: Callable[[str, int, int], None] | None = None  # progress(stage, done, total)


@dataclass(frozen=True)
class DesignResult:
    """Everything a run found. ``record`` is design.json; ``verification`` the 3-D verdict."""

    record: dict
    evaluation: Evaluation
    search: object = None          # search.SearchResult, for optimised designs
    verification: object = None    # checks.fea.VerifyResult of the reported design, when the 3-D check ran
    tradeoff: dict | None = None
    correction: object = None      # result.correct.Correction: every round of the 3-D check

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
    record = _with_large_deflection(search_record(spec, found))
    evaluation, verification, correction = found.best, None, None
    if options.verify and found.status == "optimal":
        if options.verify_rounds < 0:
            raise InputError(f"verify_rounds: {options.verify_rounds} is not allowed; must be 0 or more")
        correction = correct.run(spec, found, options.verify_mesh, options.verify_rounds, options.method,
                                 progress=None if report is None else (lambda done, total:
                                                                       report("3-D check", done, total)))
        evaluation, verification = correction.final.evaluation, correction.final.verification
        record = _verified(spec, found, record, correction)
    result = DesignResult(record, evaluation, found, verification, None, correction)
    if options.tradeoff:
        result = replace(result, tradeoff=tradeoff_fronts(spec, result, report))
    return result


def tradeoff_fronts(spec, result: DesignResult, progress=None) -> dict | None:
    """The trade-off fronts around an optimised design (``search.tradeoff``), or None where they do
    not apply: no optimum, an objective other than the error, a design the 3-D check corrected
    (the fronts are the plain model's, and such a design is not on them) or a search on stock (the
    fronts are of continuous sizes, but for tubes, which are always from stock)."""
    found, correction = result.search, result.correction
    if found is None or not found.success or spec.objective != "error" or (correction and correction.corrected):
        return None
    if spec.search.stock != "none":
        return None  # the fronts are of continuous sizes (tubes apart); a stock design is not on them
    from designer.search.tradeoff import fronts

    return fronts(spec, found, progress=None if progress is None else
                  (lambda done, total: progress("trade-off fronts", done, total)))


def evaluate_fixed(spec) -> DesignResult:
    """Judge the spec's fixed ``design:`` block, rounded to 0.01 mm as every reported design is."""
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    broken = dict.fromkeys(v.name for v in ev.violations)   # a limit broken nominally and at a corner: once
    messages = [] if ev.feasible else ["the design violates: " + ", ".join(broken)]
    messages += _bore_not_from_stock(spec, ev.design)
    record = build_record("feasible" if ev.feasible else "infeasible", spec, ev, messages=messages)
    _cad_options_fit(record)
    return DesignResult(_with_large_deflection(record), ev)


def _cad_options_fit(record: dict) -> None:
    """The spec's ``cad:`` options checked against its fixed design, as the CAD would cut it (a
    wire channel deeper than the pocket, a corner radius that leaves the gauge no flat floor, an
    end mill wider than a flat is long): SpecError naming the key, whether or not the design meets
    its limits and whether or not CAD outputs are asked for (the model judges the channel as given)."""
    from designer.errors import DesignFileError, SpecError
    from designer.outputs.cad.beam import resolve

    try:
        resolve(record)
    except DesignFileError as exc:
        if str(exc).startswith("spec.cad."):
            raise SpecError(str(exc).replace("spec.cad.", "cad.")) from None


# A fixed tube's sizes match a stock row when each is within half the 0.01 mm step designs are
# written to (m): a 1/2 x 0.065 in tube written 12.7 x 1.65 mm is that row.
STOCK_MATCH = 5e-6


def _bore_not_from_stock(spec, design) -> list[str]:
    """A warning when a fixed tube is no tube stock size of its material (``materials/stock.yaml``,
    metric or imperial): its bore would be drilled along the beam, which the search never offers."""
    g = design.geometry
    if g.section != "tube":
        return []
    from designer.spec import catalogue

    rows = catalogue.stock().rows(design.material.name, "tube", "any", spec.axes)
    if any(abs(v["diameter"] - g.diameter) <= STOCK_MATCH and abs(v["wall"] - g.wall) <= STOCK_MATCH for _, v in rows):
        return []
    bore = g.diameter - 2 * g.wall
    return [f"design.section: a tube Ø{g.diameter * 1e3:.2f} x {g.wall * 1e3:.2f} mm is no metric or imperial tube "
            f"stock size of {design.material.name} (materials/stock.yaml, `fpdesign materials`): its Ø{bore * 1e3:.2f} mm "
            f"bore would be drilled {g.length * 1e3:.0f} mm deep"]


# Beyond this free-end deflection by linear theory, in free lengths, the elastica is not computed:
# the beam hangs from its clamp (a tip load's tip angle is past 80 degrees at 3 lengths, the
# Bisshopp-Drucker load parameter 9), the shooting method finds curled branches of the elastica
# and, far beyond, integrates for hours (a modulus of 1 Pa did); no sensor works there.
ELASTICA_REACH = 3.0


def _with_large_deflection(record: dict) -> dict:
    """The record with the elastica's figures where linear theory stops holding (up to
    ELASTICA_REACH; a message beyond)."""
    deflection, length = record["predicted"]["deflection"], record["design"]["length"]
    if not model.is_large_deflection(deflection, length):
        return record
    if deflection > ELASTICA_REACH * length:
        return {**record, "messages": record["messages"] + [
            f"large deflection: linear theory puts the free end {deflection / length:.3g} free lengths down under "
            f"F_max at x_max; beyond {ELASTICA_REACH:g} the beam hangs from its clamp and no elastica is computed"]}
    from designer.checks.elastica import large_deflection

    result = large_deflection(record)
    messages = [result.summary()]
    spec = record["spec"]
    targets = spec.get("targets") or {}
    force, position = targets.get("force_error"), targets.get("position_error")
    over = []
    if isinstance(force, (int, float)) and result.force_error_max > force:
        over.append(f"force errors up to {result.force_error_max:.2%} against the {force * 100:.3g} % target")
    if isinstance(position, (int, float)) and result.position_error_max > position:
        over.append(f"position errors up to {result.position_error_max * 1e3:.2f} mm against the "
                    f"{position * 1e3:.3g} mm target")
    if over and not spec.get("environment"):
        # the targets hold the noise alone without an environment (docs/spec.md 2.10)
        messages.append(f"large deflection: the bending alone leaves {' and '.join(over)}; the targets are judged "
                        "on the noise alone without environment: its error budget takes in the lever arm's "
                        "shortening (docs/model.md §13); or a smaller limits.max_deflection keeps the beam linear")
    return {**record, "large_deflection": result.as_dict(), "messages": record["messages"] + messages}


def _verified(spec, found, record: dict, correction) -> dict:
    """The record of the design the 3-D check's loop reports: the first that passed in 3-D, or,
    when none did, the least failing, reported infeasible (never shipped)."""
    final = correction.final
    if final.number > 0:  # a corrected design replaces the search's choice and its candidate record
        solver = dict(found.solver)
        solves = [r.candidate for r in correction.rounds if r.candidate is not None]
        solver["solves"] = solver.get("solves", 0) + sum(len(c.solves) for c in solves)
        solver["evaluations"] = solver.get("evaluations", 0) + sum(s.evaluations for c in solves for s in c.solves)
        solver["fallbacks"] = list(solver.get("fallbacks", [])) + [
            f"{c.material} {c.family.label} (3-D round {r.number}): {f}"
            for r in correction.rounds if (c := r.candidate) is not None for f in c.fallbacks]
        chosen = {**final.candidate.record(), "adjustment": final.adjustment.as_dict()}
        candidates = [chosen] + [c.record() for c in found.candidates[1:]]
        stock = record.get("stock")
        record = _with_large_deflection(build_record("optimal", spec, final.evaluation, candidates, solver))
        if stock is not None:
            record["stock"] = stock_summary(spec, final.evaluation, found.get("continuous"))
    verdict = final.verification
    summary = verdict.as_dict()
    summary.pop("profile", None)  # the strain profile goes to verify.json only
    messages = list(record["messages"])
    if not correction.passed:
        failed = [c.name for c in verdict.limits if not c.satisfied]
        messages.append("the 3-D check finds limits the beam model missed: " + ", ".join(failed) + "; see verify.md")
    messages += correct.messages(correction)
    messages.extend(m for m in verdict.messages if m not in messages)
    return {**record, "status": "optimal" if correction.passed else "infeasible", "verification": summary,
            "verify_rounds": [r.record() for r in correction.rounds], "messages": messages}
