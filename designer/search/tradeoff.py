"""Trade-off fronts: the best achievable error as one limit is swept (issue 5's plots).

Each point is a solved, verified design: the spec re-solved for the ``error`` objective with
``limits.max_deflection`` (or ``limits.min_frequency``) set to a level (``x``), for the leading
materials of the search and every section family, with the design's own deflection (or
frequency) as ``value``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from designer.search.run import optimize

LEVELS = 9
MATERIALS = 4     # the best distinct materials of the search take part in the fronts
SPAN = 10.0       # levels from value/SPAN**0.5 to value*SPAN**0.5 around the chosen design


def _levels(centre: float) -> np.ndarray:
    return np.geomspace(centre / SPAN ** 0.5, centre * SPAN ** 0.5, LEVELS)


def fronts(spec, outcome, materials: int = MATERIALS, progress=None) -> dict:
    """``{"max_deflection": [points], "min_frequency": [points]}`` for ``plots.write_design_plots``;
    ``progress(done, total)``, if given, hears of each level solved."""
    leading = list(dict.fromkeys(c.material for c in outcome.candidates))[:materials]
    chosen = outcome.best.analysis
    base = replace(spec, objective="error")
    out = {}
    sweeps = (("max_deflection", float(chosen.deflection), spec.limits.max_deflection),
              ("min_frequency", float(chosen.natural_frequency), spec.limits.min_frequency))
    achieved = {"max_deflection": "deflection", "min_frequency": "natural_frequency"}
    done = 0
    for key, value, given in sweeps:
        points = []
        for level in _levels(given or value):
            variant = replace(base, limits=replace(base.limits, **{key: float(level)}))
            result = optimize(variant, materials=leading, tie_break=False)
            done += 1
            if progress is not None:
                progress(done, len(sweeps) * LEVELS)
            for cand in result.candidates:
                ev = cand.evaluation
                # x: the limit the design was solved under; value: its own deflection or
                # frequency, which the deflection limit's room (docs/model.md §4) keeps below x
                points.append({"material": cand.material, "section": cand.family.label, "x": float(level),
                               "value": None if ev is None else float(getattr(ev.analysis, achieved[key])),
                               "objective": None if ev is None else float(ev.error_ratio),
                               "feasible": bool(ev is not None and ev.feasible)})
        out[key] = points
    return out
