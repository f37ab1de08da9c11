"""The plain grid method: every section variable on a grid, stations spread, vectorised."""

from __future__ import annotations

import numpy as np

from designer import model
from designer.model import MaterialParams, grooves
from designer.search.problem import MM, Solve, in_nlp_units

GRID_LEVELS = 9               # points per section variable in the grid method


def grid_solve(problem, params) -> Solve:
    """A plain grid over the section variables with stations at their extremes, vectorised."""
    names = problem.names
    axes = []
    station_idx = [i for i, nme in enumerate(names) if nme.startswith("station_")]
    for i, nme in enumerate(names):
        if i in station_idx:
            axes.append(None)
        else:
            axes.append(np.linspace(problem.lower[i], problem.upper[i], GRID_LEVELS))
    section_axes = [a for a in axes if a is not None]
    mesh = [m.ravel() for m in np.meshgrid(*section_axes, indexing="ij")]
    x = np.empty((len(mesh[0]), len(names)))
    j = 0
    for i in range(len(names)):
        if i not in station_idx:
            x[:, i] = mesh[j]
            j += 1
    x[:, station_idx] = _spread_stations(problem, x)
    material = MaterialParams.from_scaled(params)
    g = problem.geometry([x[:, i] * MM for i in range(len(names))])
    with np.errstate(invalid="ignore", divide="ignore"):  # impossible grid points give NaN: infeasible
        a = model.analyse(g, material, problem.spec, adjust=problem.adjustment)
        lims = model.limits(g, a, material, problem.spec, include_targets=not problem.epigraph)
        viol = model.worst_normalised(lims, len(x))
    viol = np.where(np.isnan(viol), np.inf, viol)
    f = in_nlp_units(model.objective(a, problem.spec), problem.spec.objective)
    f = np.nan_to_num(np.broadcast_to(np.asarray(f, dtype=float), (len(x),)), nan=np.inf)
    feasible = viol <= 0
    if feasible.any():
        best = int(np.argmin(np.where(feasible, f, np.inf)))
    else:  # the least violating of the points that are beams at all, if any are
        with np.errstate(invalid="ignore", divide="ignore"):
            beam = model.worst_normalised(model.section_limits(g, problem.spec), len(x)) <= 0
        best = int(np.argmin(np.where(beam, viol, np.inf) if beam.any() else viol))
    xb = x[best]
    if problem.epigraph:
        xb = np.append(xb, f[best])
    return Solve(xb, bool(feasible.any()), f"grid of {len(x)} designs", len(x), "grid")


def _spread_stations(problem, x):
    """Stations from the clamp-side limit to the load-side limit, evenly (vectorised)."""
    spec, lim = problem.spec, problem.spec.limits
    named = {n: x[:, i] for i, n in enumerate(problem.names)}
    lf = np.broadcast_to(model.feature_length(problem.family.feature, spec.pocket_size()[0] / MM, named.get("hole"),
                                              spec.gauge.length / MM), (len(x),))
    first = lim.clamp_clearance / MM + lf / 2
    last = grooves.stations_end(spec) / MM - lf / 2
    t = np.linspace(0, 1, spec.stations)
    return first[:, None] + (last - first)[:, None] * t[None, :]
