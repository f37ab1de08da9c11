"""An exhaustive reference search, independent of casadi and nlopt.

A dense grid over every variable of a family (the section, the feature and the first and
last station) is evaluated at once with the numeric model; the best grid points are then
polished by scipy's SLSQP with finite differences, rounded and checked (the best one polished
again with a pocket's depth held at its grid values); with tolerances, every
limit is judged at the corners throughout (``model.tolerance``). A family whose sections come from
stock (tubes always) is searched so with its section held at each row in turn. It is slow and
thorough: the yardstick the optimiser's answers are measured against (tests, ``bench``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from designer import model
from designer.model import MaterialParams, tolerance
from designer.result.evaluation import Evaluation
from designer.search.problem import MM, Family, FamilyVariables, families, in_nlp_units
from designer.search.rounding import floor_ceil, pick, round_and_check
from designer.search.stock import on_stock, stock_rows, stock_system

POLISH_STARTS = 6


def reference_search(spec, family: Family, material, levels: int = 9) -> Evaluation | None:
    """Best verified design of one material and family by grid + polish (None if none evaluates).
    A family on stock (``stock.stock_system``: tubes always) is gridded and polished row by row,
    its section held at each row's sizes."""
    problem = FamilyVariables.of(spec, family)  # variables and bounds only: no casadi graph
    mat = MaterialParams.of(material, spec.limits)
    if stock_system(spec, family) == "none":
        rows, held = [None], [problem]
    else:
        rows, _ = stock_rows(problem, material)
        held = [_held(problem, mm) for _, mm, _ in rows]
    grids = [_grid(p, levels) for p in held]
    x = np.concatenate(grids) if grids else np.empty((0, len(problem.names)))
    if not len(x):      # a family on stock without a row of this material
        return None
    which = np.repeat(np.arange(len(grids)), [len(g) for g in grids])
    f, viol = _evaluate(problem, mat, x)
    # the best grid points: those that meet every limit by objective, then the least violating
    # (a start at the lowest objective of a grid that meets nothing is its most infeasible corner)
    order = np.lexsort((np.where(viol > 0, viol, f), viol > 0))[:POLISH_STARTS]
    checked, polished = [], []

    def check(candidate, k):
        design = problem.design(candidate, material)
        if rows[k] is not None:
            design = on_stock(design, rows[k][0], rows[k][2])
        ev = round_and_check(design, spec)
        if ev is not None:
            checked.append(ev)

    for x0, k in zip(x[order], which[order]):
        check(x0, k)
        x1 = _polish(held[k], mat, x0)
        check(x1, k)
        polished.append((x1, k))
    # the depth is drawn on its own, coarser grid (cad.depth_step): rounding it alone can cost
    # more than a size step makes up, so the best polished answer is polished again with its
    # depth held at each of its two grid values (as the optimiser's rounding does, search.ongrid)
    if "depth" in problem.names and polished:
        f, viol = _evaluate(problem, mat, np.array([x1 for x1, _ in polished]))
        x1, k = polished[int(np.lexsort((f, viol > model.FEASIBILITY_TOLERANCE))[0])]
        i = problem.names.index("depth")
        for depth in floor_ceil(float(x1[i]) * MM, step=spec.cad.depth_step):
            start = x1.copy()
            start[i] = depth / MM
            check(_polish(_held(held[k], {i: depth / MM}), mat, start), k)
    return pick(checked)


def _held(problem: FamilyVariables, sizes: dict) -> FamilyVariables:
    """``problem`` with the variables of ``sizes`` (mm by variable index) held at those values."""
    lower, upper = problem.lower.copy(), problem.upper.copy()
    for i, v in sizes.items():
        lower[i] = upper[i] = v
    return replace(problem, lower=lower, upper=upper)


def _grid(problem: FamilyVariables, levels: int) -> np.ndarray:
    """Every variable on ``levels`` points (one where it is held); inner stations evenly between
    the first and last."""
    names = problem.names
    n_st = problem.spec.stations
    free = [i for i, n in enumerate(names) if not n.startswith("station_") or n in ("station_1", f"station_{n_st}")]
    axes = [np.linspace(problem.lower[i], problem.upper[i], levels if problem.upper[i] > problem.lower[i] else 1)
            for i in free]
    mesh = np.meshgrid(*axes, indexing="ij")
    x = np.empty((mesh[0].size, len(names)))
    for j, i in enumerate(free):
        x[:, i] = mesh[j].ravel()
    first, last = names.index("station_1"), names.index(f"station_{n_st}")
    for k in range(2, n_st):
        t = (k - 1) / (n_st - 1)
        x[:, names.index(f"station_{k}")] = x[:, first] + t * (x[:, last] - x[:, first])
    return x[x[:, last] > x[:, first]]


def _evaluate(problem: FamilyVariables, mat: MaterialParams, x: np.ndarray):
    """Objective and worst normalised violation of each row of ``x`` (mm), with the numeric model."""
    spec = problem.spec
    g = problem.geometry([x[:, i] * MM for i in range(x.shape[1])])
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        a = model.analyse(g, mat, spec)
        lims = model.limits(g, a, mat, spec, include_targets=not problem.epigraph)
        viol = np.maximum(model.worst_normalised(lims, len(x)), tolerance.worst(g, mat, spec))
        f = in_nlp_units(model.objective(a, spec), spec.objective)
    f = np.broadcast_to(np.asarray(f, dtype=float), (len(x),))
    bad = ~np.isfinite(viol) | ~np.isfinite(f)
    return np.where(bad, np.inf, f), np.where(bad, np.inf, np.maximum(viol, 0.0))


def _polish(problem: FamilyVariables, mat: MaterialParams, x0: np.ndarray) -> np.ndarray:
    """scipy SLSQP from a grid point, on the numeric model (finite differences)."""
    from scipy.optimize import minimize

    spec = problem.spec

    def parts(v):
        g = problem.geometry([float(t) * MM for t in v])
        with np.errstate(all="ignore"):
            a = model.analyse(g, mat, spec)
            lims = model.limits(g, a, mat, spec, include_targets=not problem.epigraph)
            corners = tolerance.worst_each(g, mat, spec)
        return a, np.concatenate([[float(lim.normalised) for lim in lims], corners])

    def objective(v):
        a, _ = parts(v)
        return float(in_nlp_units(model.objective(a, spec), spec.objective))

    def constraints(v):
        g = -parts(v)[1]
        return np.nan_to_num(g, nan=-1e6, posinf=1e6, neginf=-1e6)

    bounds = list(zip(problem.lower, problem.upper))
    try:
        res = minimize(lambda v: np.nan_to_num(objective(v), nan=1e6), x0, method="SLSQP", bounds=bounds,
                       constraints=[{"type": "ineq", "fun": constraints}], options={"maxiter": 300, "ftol": 1e-12})
    except (ValueError, ArithmeticError):
        return x0
    return np.clip(res.x, problem.lower, problem.upper)


def reference_best(spec, materials=None, levels: int = 9) -> Evaluation | None:
    """The best verified design over materials x families, ranked as the optimiser ranks."""
    from designer.spec import catalogue

    found = [reference_search(spec, fam, catalogue.material(name), levels)
             for fam in families(spec) for name in materials or spec.search.materials]
    return pick([ev for ev in found if ev is not None])
