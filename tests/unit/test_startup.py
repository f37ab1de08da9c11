"""`fpdesign --help` starts fast: building the command line loads no numerical library."""

import subprocess
import sys


def test_the_command_line_is_built_without_numerical_libraries():
    code = ("import sys; from designer.cli import build_parser; build_parser().format_help(); "
            "print(sorted(m for m in ('numpy', 'scipy', 'casadi', 'matplotlib', 'cadquery', 'pint', 'yaml', 'rich') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"


def test_the_search_loads_no_scipy_optimize():
    # scipy.optimize takes a quarter of a second to import (python -X importtime) and the search
    # needs none of it: IPOPT is casadi's, the other methods nlopt's; the reference search and
    # the 3-D studies import their scipy solvers where they use them.
    code = ("import sys; from designer.search import optimize; from designer.search.tradeoff import fronts; "
            "from designer.result.pipeline import design; print('scipy.optimize' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "False"
