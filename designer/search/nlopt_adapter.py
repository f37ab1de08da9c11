"""The nlopt methods behind the search's solver interface (``FamilyProblem.solve``)."""

from __future__ import annotations

import numpy as np

from designer import interrupt
from designer.search import watchdog
from designer.search.problem import Solve

NLOPT_XTOL = 1e-8
# Evaluation budgets per nlopt run: deterministic, unlike a wall-clock limit (CCSAQ's inner
# solves make each of its evaluations about 10x dearer, hence its smaller budget).
NLOPT_MAX_EVAL = {"slsqp": 500, "mma": 1000, "ccsaq": 200, "cobyla": 2000, "isres": 4000, "direct": 2000}
NAN_PENALTY = 1e6
# MMA/CCSAQ inner iterations per outer step, and evaluations of their dual subproblem: both are
# unbounded by default, and the dual solve alone can spin for seconds on these problems.
CCSA_INNER_MAX_EVAL = 50
CCSA_DUAL_MAX_EVAL = 100
NLOPT_SAFETY_SECONDS = 5.0    # a stalled run must not stall the search; budgets end runs first
# A run is watched in a forked child (``watchdog``) and killed at this age: nlopt's own loops can
# ignore both budgets. Above two runs' safety time (MMA's and CCSAQ's restart is a second run).
NLOPT_KILL_SECONDS = 3 * NLOPT_SAFETY_SECONDS
ISRES_SEED = 12345            # nlopt's random generator is global: seeded before each ISRES run
CCSA_RESTART_OVER = 1e-6      # a constraint over this at MMA's or CCSAQ's stop starts them once more


_NLOPT_ALGORITHMS = {"slsqp": "LD_SLSQP", "mma": "LD_MMA", "ccsaq": "LD_CCSAQ", "cobyla": "LN_COBYLA",
                     "isres": "GN_ISRES", "direct": "GN_DIRECT_L"}


def nlopt_solve(problem, method: str, params, x0) -> Solve:
    """One nlopt run behind the same interface, watched in a child process where the platform
    forks: a run that has not returned after ``NLOPT_KILL_SECONDS`` is killed and recorded as
    failed, at its start point."""
    if not watchdog.can_watch():
        return _nlopt_run(problem, method, params, x0)
    try:
        return watchdog.run_watched(lambda: _nlopt_run(problem, method, params, x0), NLOPT_KILL_SECONDS)
    except watchdog.Lost as lost:
        return Solve(_start_point(problem, x0), False, f"nlopt {method}: {lost}", 0, method)


def _box(problem):
    """The bounds nlopt runs in: the problem's, with a finite top for the epigraph's error ratio
    (global methods sample the whole box; the ratio stays below 1e3)."""
    lo, hi = problem.bounds()
    if problem.epigraph:
        hi = hi.copy()
        hi[-1] = 1e3
    return lo, hi


def _start_point(problem, x0):
    """Where a run starts (and where a failed run is recorded): ``x0`` clipped into ``_box``."""
    return np.clip(np.asarray(x0, dtype=float), *_box(problem))


def _nlopt_run(problem, method: str, params, x0) -> Solve:
    """One nlopt run; DIRECT, which takes no constraints, runs in AUGLAG."""
    import nlopt

    lo, hi = _box(problem)
    n = problem.size
    fn = problem.functions
    counter = {"n": 0}

    # Global methods sample impossible points of the box (a flat deeper than the radius, two
    # stations at one place): the model gives NaN or inf there, passed on as a large penalty.
    def objective(x, grad):
        counter["n"] += 1
        f, df, _, _ = fn(x, params)
        if grad.size > 0:
            grad[:] = np.nan_to_num(np.asarray(df).ravel(), nan=0.0)
        return float(_finite(f).item())  # a 1x1 DM: float() of a 2-D array fails on numpy >= 2.4

    def constraints(result, x, grad):
        _, _, g, dg = fn(x, params)
        result[:] = _finite(np.asarray(g).ravel())
        if grad.size > 0:
            grad[:, :] = np.nan_to_num(np.asarray(dg), nan=0.0)

    algorithm = getattr(nlopt, _NLOPT_ALGORITHMS[method])
    if method == "direct":
        opt = nlopt.opt(nlopt.AUGLAG, n)
        local = nlopt.opt(algorithm, n)
        local.set_maxeval(NLOPT_MAX_EVAL[method] // 10)
        local.set_xtol_rel(1e-6)
        opt.set_local_optimizer(local)
    else:
        opt = nlopt.opt(algorithm, n)
    opt.set_lower_bounds(lo)
    opt.set_upper_bounds(hi)
    opt.set_min_objective(objective)
    opt.add_inequality_mconstraint(constraints, np.full(problem.n_constraints, 1e-10))
    opt.set_xtol_rel(NLOPT_XTOL)
    opt.set_maxeval(NLOPT_MAX_EVAL[method])
    opt.set_maxtime(NLOPT_SAFETY_SECONDS)
    if method in ("mma", "ccsaq"):
        opt.set_param("inner_maxeval", CCSA_INNER_MAX_EVAL)
        opt.set_param("dual_maxeval", CCSA_DUAL_MAX_EVAL)
    if method == "isres":
        opt.set_population(20 * (n + 1))
        nlopt.srand(ISRES_SEED)
    x_start = _start_point(problem, x0)
    try:
        x = opt.optimize(x_start)
        code = opt.last_optimize_result()
        # MMA and CCSAQ may stop on their step tolerance at a point over a limit, their moving
        # asymptotes closed in on a stalled path: once more from there, with fresh asymptotes, they
        # go on (the gripper finger's round 7075-T6 bar: 1.8 % above IPOPT's optimum, then at it)
        if method in ("mma", "ccsaq") and code == 4 and _worst(fn, x, params) > CCSA_RESTART_OVER:
            x = opt.optimize(np.asarray(x))
            code = opt.last_optimize_result()
        x = np.asarray(x, dtype=float)
        if not np.all(np.isfinite(x)):  # SLSQP can end on NaN and call it success (nlopt issue #28)
            return Solve(x_start, False, f"{_nlopt_message(code)} at a non-finite point", counter["n"], method)
        return Solve(x, code > 0, _nlopt_message(code), counter["n"], method)
    except Exception as exc:  # nlopt's own exception types do not derive from RuntimeError
        # RoundoffLimited, forced stops and failures: the run is recorded as failed, never raised,
        # unless it stopped for a signal.
        interrupt.check()
        return Solve(x_start, False, f"nlopt {type(exc).__name__}: {exc}", counter["n"], method)


def _worst(fn, x, params) -> float:
    """The largest constraint value at ``x`` (over its limit where positive)."""
    return float(np.max(_finite(np.asarray(fn(x, params)[2]).ravel())))


def _finite(values):
    return np.nan_to_num(np.asarray(values, dtype=float), nan=NAN_PENALTY, posinf=NAN_PENALTY, neginf=-NAN_PENALTY)


def _nlopt_message(code: int) -> str:
    return {1: "success", 2: "stopval reached", 3: "ftol reached", 4: "xtol reached", 5: "maxeval reached",
            6: "maxtime reached"}.get(code, f"nlopt result {code}")
