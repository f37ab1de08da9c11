"""The search: materials x section families, each solved as a smooth NLP and checked.

``problem`` (a family's variables and its casadi NLP) -> ``nlopt_adapter``/``grid`` (the other
methods behind the same interface) -> ``rounding`` (0.01 mm, checked again) -> ``run``
(``optimize``: every candidate, ties, the verdict) and ``diagnosis``; ``reference`` (an
exhaustive search sharing no code with casadi) and ``tradeoff`` (fronts) build on them.
"""

from designer.search.problem import (METHODS, MM, Family, FamilyProblem, FamilyVariables, Solve, families,
                                     in_nlp_units, material_params)
from designer.search.rounding import buildable, pick, round_and_check
from designer.search.run import Candidate, SearchResult, optimize, solve_candidate

__all__ = ["METHODS", "MM", "Candidate", "Family", "FamilyProblem", "FamilyVariables", "SearchResult", "Solve",
           "buildable", "families", "in_nlp_units", "material_params", "optimize", "pick", "round_and_check",
           "solve_candidate"]
