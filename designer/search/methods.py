"""Every search method behind one call: IPOPT on the casadi graph, nlopt's methods, the grid."""

from __future__ import annotations

from designer.search.grid import grid_solve
from designer.search.nlopt_adapter import nlopt_solve
from designer.search.problem import FamilyProblem, Solve


def solve(problem: FamilyProblem, method: str, params, x0, margin: float = 0.0) -> Solve:
    """One run of ``method`` on ``problem`` from ``x0`` with the material ``params``; IPOPT keeps
    every constraint ``margin`` inside its limit (``g <= -margin``), the other methods ignore it."""
    if method == "ipopt":
        return problem.solve_ipopt(params, x0, margin=margin)
    if method == "grid":
        return grid_solve(problem, params)
    return nlopt_solve(problem, method, params, x0)
