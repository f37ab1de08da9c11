"""Trade-off fronts: the best achievable error as one limit is swept (issue 5's plots).

Each point is a solved, verified design: the spec re-solved for the ``error`` objective with
``limits.max_deflection`` (or ``limits.min_frequency``) set to a level (``x``), for the leading
materials of the search and every section family, with the design's own deflection (or
frequency) as ``value``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from designer.errors import InputError
from designer.result.evaluation import evaluate
from designer.search.problem import SWEPT_LIMIT, FamilyProblem, families
from designer.search.run import Candidate, optimize
from designer.search.stock import stock_rows, stock_system
from designer.spec import catalogue

LEVELS = 9
MATERIALS = 4     # the best distinct materials of the search take part in the fronts
SPAN = 10.0       # levels from value/SPAN**0.5 to value*SPAN**0.5 around the chosen design
# A candidate whose answer before rounding keeps this much room (normalised, at every corner) in
# the swept limit at the tighter of two neighbouring levels is not bound by it at either: its
# design at the neighbouring level is its design at this one, judged again under this level.
UNBOUND_ROOM = 1e-2


def _levels(centre: float) -> np.ndarray:
    levels = np.geomspace(centre / SPAN ** 0.5, centre * SPAN ** 0.5, LEVELS)
    levels[LEVELS // 2] = centre   # exactly (a spec's own limit, whose designs the search has)
    return levels


def fronts(spec, outcome, materials: int = MATERIALS, progress=None) -> dict:
    """``{"max_deflection": [points], "min_frequency": [points]}`` for ``plots.write_design_plots``;
    ``progress(done, total)``, if given, hears of each level solved.

    Each sweep builds one graph per family with its limit as a parameter (``FamilyProblem``'s
    ``swept``) and solves the levels from the chosen design's outwards, every material x family
    starting from its own checked design at the neighbouring level (at the first level, from the
    search's answer): a continuation, before the usual starts. At the spec's own limit (a
    sweep's middle level, when the spec gives that limit) the search's designs are taken as they
    are, so the chosen design is the front's point there.
    """
    leading = list(dict.fromkeys(c.material for c in outcome.candidates))[:materials]
    chosen = outcome.best.analysis
    base = replace(spec, objective="error")
    out = {}
    sweeps = (("max_deflection", float(chosen.deflection), spec.limits.max_deflection),
              ("min_frequency", float(chosen.natural_frequency), spec.limits.min_frequency))
    done = 0
    for key, value, given in sweeps:
        graphs = {fam: FamilyProblem(base, fam, swept=key) for fam in families(base)}
        # a family on stock with no row of the material inside the size bounds has no design at
        # any level (the swept limit moves no bound): its point is empty, unsolved
        rowless = {(m, fam) for m in leading for fam, g in graphs.items()
                   if stock_system(base, fam) != "none" and not stock_rows(g, catalogue.material(m))[0]}
        levels = _levels(given or value)
        centre = len(levels) // 2
        # from the centre up, then from the centre down: each level's neighbour is solved before it
        order = list(range(centre, len(levels))) + list(range(centre - 1, -1, -1))
        found = {}
        for i in order:
            level = float(levels[i])
            variant = replace(base, limits=replace(base.limits, **{key: level}))
            j = i - 1 if i > centre else i + 1
            near = found.get(j, outcome.candidates)
            # designs the swept limit binds at neither this level nor the search's own (or the
            # neighbour's) are taken as they are, the search's first
            same, sources = {}, [(outcome.candidates, given)] + ([(near, float(levels[j]))] if j in found else [])
            if i == centre and level == given and spec.objective == "error":
                # the spec's own limit: the search's designs are this level's (its outranked
                # candidates, which have none, are solved), and nothing else is taken as it is
                same = {(c.material, c.family): c for c in outcome.candidates
                        if c.evaluation is not None and c.evaluation.feasible and c.material in leading
                        and c.family in graphs}
                sources = []
            for source, other in sources:
                tight = level if other is None else (min if key == "max_deflection" else max)(level, other)
                at = {fam: g.at(replace(base, limits=replace(base.limits, **{key: tight})), tight)
                      for fam, g in graphs.items()}
                for c in source:
                    if ((c.material, c.family) not in same and c.family in graphs and c.material in leading
                            and stock_system(base, c.family) == "none"   # (stock rows are not an answer's grid)
                            and (u := _unbound(at[c.family], key, c, variant)) is not None):
                        same[(c.material, c.family)] = u
            warm = {(c.material, c.family): c for c in near
                    if c.evaluation is not None and c.evaluation.feasible and c.family in graphs}
            # the limit tightens as the deflection's level falls or the frequency's rises: a
            # candidate with no feasible design at the looser neighbouring level has none here
            tighter = i <= centre if key == "max_deflection" else i >= centre
            # (one outranked by the main search had a design: it is solved, not skipped)
            ranked_out = {(c.material, c.family) for c in near if c.unrounded}
            skip = ({(m, fam) for m in leading for fam in graphs if (m, fam) not in warm and (m, fam) not in ranked_out}
                    if tighter else set()) | rowless
            skip -= set(same)
            if len(skip) + len(same) == len(leading) * len(graphs):
                found[i] = [same.get((m, fam), Candidate(m, fam, None)) for m in leading for fam in graphs]
            else:
                result = optimize(variant, materials=leading, tie_break=False, skip=skip, warm=warm, known=same,
                                  outrank=False, closest=False,
                                  problems={fam: g.at(variant, level) for fam, g in graphs.items()})
                found[i] = result.candidates
            done += 1
            if progress is not None:
                progress(done, len(sweeps) * LEVELS)
        points = []
        for i, level in enumerate(levels):
            for c in found[i]:
                material, fam, ev = c.material, c.family, c.evaluation
                # x: the limit the design was solved under; value: its own deflection or
                # frequency, which the deflection limit's room (docs/model.md §4) keeps below x
                points.append({"material": material, "section": fam.label, "x": float(level),
                               "value": None if ev is None else float(getattr(ev.analysis, SWEPT_LIMIT[key])),
                               "objective": None if ev is None else float(ev.error_ratio),
                               "feasible": bool(ev is not None and ev.feasible)})
        out[key] = points
    return out


def _unbound(problem: FamilyProblem, key: str, cand: Candidate, variant) -> Candidate | None:
    """``cand`` (a neighbouring level's, or the search's) judged under ``variant`` when the swept
    limit does not bind its answer before rounding: UNBOUND_ROOM inside its level in ``problem``
    (the swept problem at the tighter of the two levels) at every corner. The answer is then a
    solution at both levels, and its design on the grid the same. None when it does bind, or
    ``cand`` has no such answer or its design fails here."""
    s = cand.solution
    if cand.evaluation is None or not cand.evaluation.feasible or s is None or not s.success:
        return None
    g = np.asarray(problem.functions(s.x, problem.params(catalogue.material(cand.material)))[2]).ravel()
    rows = [k for k, name in enumerate(problem.limit_names) if name == SWEPT_LIMIT[key]]
    if not rows or g[rows].max() > -UNBOUND_ROOM:
        return None
    try:
        ev = evaluate(cand.evaluation.design, variant)
    except InputError:
        return None
    return replace(cand, evaluation=ev) if ev.feasible else None
