"""The 3-D check as a correction loop (docs/model.md §11).

Round 0 checks the design the search chose. When a 3-D figure breaks a limit, the beam model is
adjusted by the 3-D/model ratios measured at that design (gauge strain per station, free-end
deflection, peak stress at the feature; ``model.Adjustment``), composed with the factors the
design was already solved with; the chosen design's material and section family are solved
again with the adjusted model, rounded to the 0.01 mm grid and checked in 3-D again. The loop
stops when every limit holds with the 3-D figures, when the adjusted model has no design
meeting every limit, when it chooses the design it already checked, or after ``max_rounds``
corrected rounds.

Only the chosen family and material are solved again: the ratios were measured on that
design's shape and carry over to its neighbours, not to another section or material.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from designer.model import Adjustment
from designer.result.evaluation import Evaluation
from designer.result.record import build_record

MAX_ROUNDS = 3  # corrected rounds after the first 3-D check
# Each corrected solve keeps every limit this share inside (g <= -margin): the 3-D/model ratios
# shift a little from one design to the next (and with the remeshing), and a design solved
# exactly onto a limit would land just over it about every other round.
CORRECTION_MARGIN = 0.01


@dataclass(frozen=True)
class Round:
    """One round: the model's factors, the design they gave, and its 3-D check.

    ``verification`` is None when the round had nothing new to check; ``stopped`` says why.
    """

    number: int
    adjustment: Adjustment | None     # the factors the design was solved with (None: the plain model)
    evaluation: Evaluation | None     # the rounded design, judged with the adjusted model
    verification: object = None       # checks.fea.VerifyResult
    candidate: object = None          # search.run.Candidate of a corrected solve
    seconds: float = 0.0
    stopped: str = ""

    @property
    def passed(self) -> bool:
        return self.verification is not None and self.verification.passed

    def ratios(self) -> Adjustment:
        """The 3-D/model ratios at this round's design: gauge strains, deflection, and the peak
        stress at the feature over the model's ``K_t`` times its nominal stress there."""
        v, a = self.verification, self.evaluation.analysis
        return Adjustment(v.ratios, v.deflection_fea / v.deflection_model,
                          v.stress_feature_fea / float(a.stress_peak_axis))   # (the 3-D check loads along an axis)

    def worst(self) -> tuple[str, float] | None:
        """The limit the 3-D figures come closest to breaking (or break most) and its ratio
        ``value/limit`` (``limit/value`` for a lower limit; above 1: broken), among the limits
        whose 3-D value is the check's own rather than the model's."""
        if self.verification is None:
            return None
        measured = [c for c in self.verification.limits if c.fea_value != c.model_value and c.limit != 0]
        ratios = [(c.name, c.fea_value / c.limit if c.upper else c.limit / c.fea_value) for c in measured]
        return max(ratios, key=lambda r: r[1]) if ratios else None

    def record(self) -> dict:
        """As design.json's ``verify_rounds`` holds it."""
        out = {"round": self.number,
               "adjustment": None if self.adjustment is None else self.adjustment.as_dict(),
               "design": None, "objective": None, "passed": self.passed, "worst_limit": None, "worst_ratio": None,
               "failed": [], "seconds": self.seconds}
        if self.evaluation is not None:
            d = self.evaluation.design.shape_dict()
            out["design"] = {k: d[k] for k in ("material", "section", "feature", "stations")}
            out["objective"] = self.evaluation.objective
        if self.verification is not None:
            worst = self.worst()
            if worst is not None:
                out["worst_limit"], out["worst_ratio"] = worst
            out["failed"] = [c.name for c in self.verification.limits if not c.satisfied]
            out["ratios"] = self.ratios().as_dict()
        if self.stopped:
            out["stopped"] = self.stopped
        return out

    def summary(self) -> str:
        """One line for the report."""
        factors = "the plain model" if self.adjustment is None else "factors " + _factors_text(self.adjustment)
        if self.verification is None:
            return f"round {self.number} ({factors}): {self.stopped}"
        verdict = "every limit holds in 3-D" if self.passed else \
            "fails in 3-D: " + ", ".join(c.name for c in self.verification.limits if not c.satisfied)
        worst = self.worst()
        tail = "" if worst is None else f" (worst {worst[0]} at {worst[1]:.3f} of its limit)"
        return f"round {self.number} ({factors}): {verdict}{tail}"


@dataclass(frozen=True)
class Correction:
    """Every round of the loop; ``final`` is the design to report."""

    rounds: tuple

    @property
    def passed(self) -> bool:
        return any(r.passed for r in self.rounds)

    @property
    def final(self) -> Round:
        """The round that passed or, when none did, the checked round whose worst 3-D limit is least broken."""
        checked = [r for r in self.rounds if r.verification is not None]
        passed = [r for r in checked if r.passed]
        if passed:
            return passed[0]
        return min(checked, key=lambda r: (r.worst() or ("", 0.0))[1])

    @property
    def corrected(self) -> bool:
        return self.final.number > 0


def run(spec, found, mesh: str, max_rounds: int = MAX_ROUNDS, method: str = "ipopt", progress=None,
        verify=None) -> Correction:
    """The loop for the search result ``found`` (``search.SearchResult``, status optimal).

    ``verify(record, mesh)`` is the 3-D check (``checks.fea.verify_design`` by default);
    ``progress(done, total)`` is called before each check.
    """
    from designer.search.run import resolve

    if verify is None:
        from designer.checks.fea import verify_design as verify
    family = found.candidates[0].family
    evaluation, adjustment, candidate = found.best, None, None
    rounds: list[Round] = []
    for number in range(max_rounds + 1):
        start = time.perf_counter()
        if number > 0:
            previous = rounds[-1]
            ratios = previous.ratios()
            adjustment = ratios if adjustment is None else adjustment.times(ratios)
            candidate = resolve(spec, family, previous.evaluation, adjustment, method, CORRECTION_MARGIN)
            evaluation = candidate.evaluation
            stopped = ""
            if evaluation is None or not evaluation.feasible:
                stopped = "with these factors the model finds no design of this material and section that meets " \
                          "every limit"
            elif evaluation.design.geometry == previous.evaluation.design.geometry:
                stopped = "with these factors the model keeps the design already checked"
            if stopped:
                rounds.append(Round(number, adjustment, evaluation, None, candidate, time.perf_counter() - start,
                                    stopped))
                break
        if progress is not None:
            progress(number, max_rounds + 1)
        verification = verify(build_record("optimal", spec, evaluation), mesh)
        rounds.append(Round(number, adjustment, evaluation, verification, candidate, time.perf_counter() - start))
        if verification.passed:
            break
    return Correction(tuple(rounds))


def messages(correction: Correction) -> list[str]:
    """What the loop did, for design.json's ``messages`` and the report."""
    n = len(correction.rounds)
    final = correction.final
    if correction.passed and not correction.corrected:
        return []
    lines = [r.summary() for r in correction.rounds]
    if correction.passed:
        head = (f"corrected by the 3-D check: the first design broke limits in 3-D; round {final.number} solved the "
                f"model adjusted by the 3-D/model ratios ({_factors_text(final.adjustment)}) and its design meets "
                "every limit in 3-D")
    else:
        head = (f"infeasible in 3-D: the design of no round ({_span(n)}) meets every limit with the 3-D figures; "
                f"the design shown is round {final.number}'s, the least over its limits")
    return [head] + lines


def _span(n: int) -> str:
    return "round 0" if n == 1 else f"rounds 0-{n - 1}"


def _factors_text(adjustment: Adjustment) -> str:
    strain = ", ".join(f"{f:.3f}" for f in adjustment.gauge_strain)
    return (f"gauge strain {strain}; deflection {adjustment.deflection:.3f}; "
            f"stress concentration {adjustment.stress_concentration:.3f}")
