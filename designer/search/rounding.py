"""Rounding an answer to 0.01 mm (a pocket's depth to ``cad.depth_step``, 0.05 mm by default) and
checking it, and picking the best of checked designs.

No solver's success flag is trusted: every answer is rounded to the reported 0.01 mm grid and
judged again with the numeric model (``result.evaluation.evaluate``); what is reported is what
was checked (docs/model.md §5).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np

from designer import model
from designer.errors import InputError
from designer.model import tolerance
from designer.result.evaluation import ROUNDING, Design, Evaluation, channelled, evaluate
from designer.search.problem import MM, pocket_as_needed


# Steps of its own grid (cad.depth_step, 0.05 mm by default) that a wider box reaches in the depth
# at most: a step of it is about five of the 0.01 mm grid.
DEPTH_REACH = 2
# IPOPT relaxes every bound it is given by this much (its bound_relax_factor, by default) before
# it solves, so a converged answer may sit over a limit by up to it: still the optimum that
# bounds every design near it (``outranked_before_rounding``).
ANSWER_TOLERANCE = 1e-8


def only_targets_missed(ev: Evaluation, epigraph: bool) -> bool:
    """Under the error objective (``epigraph``), whether the accuracy targets are all that ``ev``
    misses: a verdict on the spec (the least error it reaches), not a failure of the solve."""
    return epigraph and all(v.name in model.TARGET_LIMITS for v in ev.violations)


def round_and_check(design: Design, spec, reach: int = 0, lowest: bool = False) -> Evaluation | None:
    """Round to 0.01 mm (a pocket's or flat's depth to ``spec.cad.depth_step``); if rounding broke
    a limit, try the neighbouring grid points. A stock section (``design.stock``) is not rounded:
    only its feature and stations are.

    Every length is rounded down or up (inner stations to the nearest); all combinations are
    checked at once with the numeric model over numpy arrays, the best is chosen as ``pick``
    chooses, and that one design is evaluated again on its own and returned. None when no
    combination can be evaluated at all. ``reach`` adds that many grid steps below the rounded-down
    and above the rounded-up value of each section size and the feature's depth or hole. With
    ``lowest``, the combination with the lowest objective that meets every limit is chosen instead
    of the tie rule's.
    """
    box = GridBox.around(design, spec, reach)
    return None if box is None else box.choose(lowest)


class GridBox:
    """The grid points around a design (``round_and_check``), judged at once with the numeric model."""

    def __init__(self, design: Design, spec, trial, named: dict, st, viol, objective, deflection, mass, valid,
                 keys: tuple):
        self.design, self.spec, self.trial, self.named, self.st = design, spec, trial, named, st
        self.viol, self.objective, self.deflection, self.mass, self.valid = viol, objective, deflection, mass, valid
        # each point's worst of the geometry's own rules (nominal; the rules themselves, for
        # ``broken``), of the duty's other limits (nominal and at the corners) and of the targets
        self.rules, self._own, self.bearing, self.targets = keys

    @classmethod
    def around(cls, design: Design, spec, reach: int = 0) -> "GridBox | None":
        """The box of ``round_and_check``; None when no point of it can be evaluated."""
        g = design.geometry
        fields_ = [f for f in ("width", "height", "diameter", "wall") if getattr(g, f) is not None]
        if g.axes == 2 and g.section == "rectangle":
            fields_.remove("height")  # a biaxial rectangle is square
        if design.stock is not None:
            fields_ = []  # a stock section is what the table says it is
        fields_ += {"pocket": ["depth"], "hole": ["hole"]}.get(g.feature, [])
        stations = [float(s) for s in g.stations]
        if not all(math.isfinite(v) for v in [*(float(getattr(g, f)) for f in fields_), *stations]):
            return None  # a solver's non-finite answer (nlopt's SLSQP can end on NaN): nothing to round
        choices = [floor_ceil(float(getattr(g, f)), min(reach, DEPTH_REACH), spec.cad.depth_step) if f == "depth"
                   else floor_ceil(float(getattr(g, f)), reach) for f in fields_]
        station_choices = [floor_ceil(s) for s in stations]
        for i in range(1, len(stations) - 1):  # linear limits with slack: nearest is enough
            station_choices[i] = (round(stations[i] / ROUNDING) * ROUNDING,)
        combos = np.array(list(itertools.product(*choices, *station_choices)))
        named = {f: combos[:, i] for i, f in enumerate(fields_)}
        if g.axes == 2 and g.section == "rectangle" and "width" in named:
            named["height"] = named["width"]
        st = combos[:, len(fields_):]
        # the wire channels' depth follows the rounded pocket's, as the CAD cuts them; a searched
        # pocket is as long as the rounded section needs (``pocket_as_needed``), on the grid
        trial = channelled(replace(g, stations=tuple(st[:, i] for i in range(st.shape[1])),
                                   length=round(float(g.length) / ROUNDING) * ROUNDING, **named), spec.cad)
        if g.feature == "pocket":
            length = pocket_as_needed(trial, spec.pocket_size()[0], ROUNDING).pocket_length
            named["pocket_length"] = np.broadcast_to(length, (len(combos),))
            trial = replace(trial, pocket_length=named["pocket_length"])
        params = design.material_params(spec)
        with np.errstate(all="ignore"):
            a = model.analyse(trial, params, spec, adjust=design.adjustment)
            lims = model.limits(trial, a, params, spec)
            # the closest design's keys (``closest.closeness``): the geometry's rules (how many are
            # broken, a size limit among them), the duty's limits but the targets (the corners' with
            # them), the targets; every limit is in one of them
            own = [lim for lim in lims if lim.name not in model.DUTY_LIMITS]
            rules = model.worst_normalised(own, len(combos))
            bearing = np.maximum(model.worst_normalised([lim for lim in lims if lim.name in model.DUTY_LIMITS
                                                         and lim.name not in model.TARGET_LIMITS], len(combos)),
                                 tolerance.worst(trial, params, spec, design.adjustment))
            targets = model.worst_normalised([lim for lim in lims if lim.name in model.TARGET_LIMITS], len(combos))
            viol = np.maximum(np.maximum(rules, bearing), targets)
            objective = np.broadcast_to(np.asarray(model.objective(a, spec), dtype=float), (len(combos),))
            deflection = np.broadcast_to(np.asarray(a.deflection, dtype=float), (len(combos),))
            mass = np.broadcast_to(np.asarray(a.mass, dtype=float), (len(combos),))
        valid = np.isfinite(viol) & np.isfinite(objective) & np.all(np.diff(st, axis=1) > 0, axis=1)
        if not valid.any():
            return None
        return cls(design, spec, trial, named, st, viol, objective, deflection, mass, valid,
                   (rules, own, bearing, targets))

    def broken(self) -> tuple[np.ndarray, np.ndarray]:
        """Each point's (whether it breaks a size limit, how many of the geometry's rules it breaks)."""
        n = len(self.viol)
        over = {lim.name: np.broadcast_to(np.asarray(lim.normalised, dtype=float) > model.FEASIBILITY_TOLERANCE, (n,))
                for lim in self._own}
        outside = np.zeros(n, dtype=bool)
        for name in set(over) & set(model.SIZE_LIMITS):
            outside |= over[name]
        return outside, sum((o.astype(int) for o in over.values()), np.zeros(n, dtype=int))

    def choose(self, lowest: bool = False, closest: bool = False) -> Evaluation | None:
        """The box's best point, evaluated on its own (``round_and_check``'s choice). With
        ``closest``, when no point meets every limit, the closest by ``closest.closeness``'s order:
        within the size limits, then the fewest of the geometry's own rules broken, then the least
        violation of the duty's other limits, then of the targets."""
        objective, valid = self.objective, self.valid
        feasible = valid & (self.viol <= model.FEASIBILITY_TOLERANCE)
        if feasible.any():
            lead = objective[feasible].min()
            band = feasible & (objective == lead if lowest else model.ties(objective, lead))
            idx = np.flatnonzero(band)
            best = idx[np.lexsort((objective[idx], self.mass[idx], self.deflection[idx]))[0]]
        elif closest:
            idx = np.flatnonzero(valid)
            keys = [np.maximum(worst[idx], model.FEASIBILITY_TOLERANCE) for worst in (self.targets, self.bearing)]
            outside, broken = self.broken()
            best = idx[np.lexsort((*keys, broken[idx], outside[idx]))[0]]
        else:
            # the least worst violation among the points that keep the geometry's own rules, when
            # any does (``closest.closeness``' order puts them first): a station 0.01 mm into its
            # clearance had been kept for a target missed by 1e-3 less; else among them all
            kept = valid & (self.rules <= model.FEASIBILITY_TOLERANCE)
            best = int(np.argmin(np.where(kept if kept.any() else valid, self.viol, np.inf)))
        design = self.design
        chosen = channelled(replace(design.geometry, stations=tuple(float(v) for v in self.st[best]),
                                    length=float(self.trial.length),
                                    **{f: float(v[best]) for f, v in self.named.items()}), self.spec.cad)
        try:
            return evaluate(Design(design.material, chosen, design.adjustment, design.stock), self.spec)
        except InputError:
            return None


def pick(evaluations: list) -> Evaluation | None:
    """The best of several checked designs: the first by ``rank`` among the feasible ones,
    else the least violating. Ties are anchored on the best objective, never chained."""
    feasible = [ev for ev in evaluations if ev.feasible]
    if feasible:
        return model.rank(feasible)[0]
    return min(evaluations, key=lambda ev: (not buildable(ev), ev.worst_violation), default=None)


def buildable(ev: Evaluation) -> bool:
    """Whether the design is a beam at all (``model.unbuildable``): a least-infeasible design that
    is not could not be plotted, exported or simulated from its design.json."""
    return model.unbuildable(ev.design.geometry) is None


def broken_rules(ev: Evaluation) -> set[str]:
    """The geometry's own rules (every limit but its duty's) that ``ev`` breaks, at its nominal
    sizes or a tolerance corner."""
    tol = model.FEASIBILITY_TOLERANCE
    return {lim.name for lim in ev.judged if lim.name not in model.DUTY_LIMITS and float(lim.normalised) > tol}


def floor_ceil(v: float, reach: int = 0, step: float = ROUNDING) -> tuple:
    """The values of the grid of ``step`` (0.01 mm unless given) just below and above ``v`` (m);
    one when ``v`` is on the grid; with ``reach``, that many more grid steps each side (none at or
    below zero)."""
    lo = math.floor(v / step + 1e-9)
    hi = math.ceil(v / step - 1e-9)
    return tuple(round(k * step, 8) for k in range(max(lo - reach, 1) if reach else lo, hi + reach + 1))


def depths_held(problem, x) -> list[dict]:
    """``{index: value}`` (NLP units) holding the pocket's depth at each value of its grid
    (``cad.depth_step``) around ``x``'s, the nearer first; none for a family without a pocket. A
    grid value outside the depth's bounds is no pocket the spec allows (a depth of 0 under the
    least depth: its notch's square root has no derivative there, IPOPT's Invalid_Number_Detected)."""
    if "depth" not in problem.names:
        return []
    i, (lo, hi) = problem.names.index("depth"), problem.bounds()
    depths = [d / MM for d in floor_ceil(float(x[i]) * MM, step=problem.spec.cad.depth_step)]
    return [{i: d} for d in sorted(depths, key=lambda d: abs(d - x[i])) if lo[i] <= d <= hi[i]]


def outranked_before_rounding(problem, material, s, cap: float | None, within: float = ANSWER_TOLERANCE
                              ) -> Evaluation | None:
    """The evaluation of IPOPT's answer ``s`` before rounding when it meets every limit there to
    ``within`` (IPOPT's tolerance unless given; or misses only the accuracy targets, under the
    error objective) and its objective is above ``cap`` (rounding to the grid only loses); None
    otherwise."""
    if cap is None or not s.success:
        return None
    try:
        ev = evaluate(problem.design(s.x, material), problem.spec)
    except InputError:
        return None
    met = all(float(v.normalised) <= within or (problem.epigraph and v.name in model.TARGET_LIMITS)
              for v in ev.violations)
    return ev if met and ev.objective > cap else None


def what_broke(problem, material, s, rounded: Evaluation) -> str:
    """Why a run that reported success gave no design that meets every limit: its answer itself
    breaks a limit (the check's verdict, not the solver's), or the answer meets every limit and
    none of its neighbours on the manufacturing grid (0.01 mm, a depth's step) does, ``rounded``
    being the one ``round_and_check`` chose."""
    def broken(ev: Evaluation) -> str:   # each limit and how far it is missed: a share of its bound
        misses = [(v.name, v.record()) for v in ev.violations]
        return ", ".join(f"{name} (by {-100 * r['margin']:.2g} % of its bound)" if r["limit"] else
                         f"{name} (by {-r['margin']:.3g} {r['unit']})" for name, r in misses)

    try:
        answer = evaluate(problem.design(s.x, material), problem.spec)
    except InputError:   # the model gives no number at the answer itself (as outranked_before_rounding)
        return (f"reported success, at an answer the model cannot judge; rounding it to the manufacturing grid "
                f"breaks {broken(rounded)} at the best neighbouring grid point")
    if not answer.feasible:
        return f"reported success but its answer violates {broken(answer)}"
    return (f"its answer meets every limit, but rounding it to the manufacturing grid breaks {broken(rounded)} "
            "at the best neighbouring grid point")
