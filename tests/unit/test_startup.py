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


def test_the_cad_kernel_starts_without_the_whole_of_vtk_and_vtk_still_works():
    # cadquery's VTK bridge imports the `vtk` module, every VTK module (0.3-0.5 s of cadquery's
    # start, python -X importtime); designer.outputs.cad puts a `vtk` there that imports the real
    # one on first use (outputs/cad/kernel.py): vtkIOCGNSReader, which only the whole `vtk` loads,
    # is not loaded with the CAD package and cadquery, and the first name asked of `vtk` is the
    # real one (every CAD test builds, writes and reads parts with it in place).
    code = ("import sys; import designer.outputs.cad; import cadquery; "
            "print('vtkmodules.vtkIOCGNSReader' in sys.modules); "
            "import vtk; from vtkmodules.vtkCommonDataModel import vtkPolyData; print(vtk.vtkPolyData is vtkPolyData); "
            "print('vtkmodules.vtkIOCGNSReader' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.split() == ["False", "True", "True"]
