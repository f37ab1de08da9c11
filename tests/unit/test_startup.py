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


def test_the_cad_kernel_starts_without_dxf_vtk_and_solver_libraries_which_still_work(tmp_path):
    # cadquery's own modules import ezdxf (DXF), the VTK modules of its viewers and exporters, casadi
    # (assembly constraints) and nlopt (sketch constraints): a quarter of its start beyond OCCT
    # (python -X importtime), none used by fpdesign. designer.outputs.cad makes cadquery's first
    # import see stand-ins whose names import the real module on first use (kernel.defer_extras).
    # None is loaded with cadquery; afterwards each is a real module again, and the cadquery
    # features that use them work: a DXF export (ezdxf, with its default units), a constrained
    # sketch (nlopt) and a constrained assembly (casadi).
    code = f"""
import sys
import designer.outputs.cad, cadquery as cq
extras = ('ezdxf', 'casadi', 'nlopt', 'vtkmodules.vtkRenderingCore', 'vtkmodules.vtkIOExport')
print(sorted(m for m in extras if m in sys.modules))
cq.exporters.export(cq.Workplane().box(1, 2, 3).section(), {str(tmp_path / 'part.dxf')!r})
sketch = (cq.Sketch().segment((0, 0), (1, 0), 's1').segment((1, 0), (1, 1), 's2')
          .constrain('s1', 'Fixed', None).constrain('s1', 's2', 'Coincident', None)
          .constrain('s2', 'Length', 2.0).solve())
assy = (cq.Assembly().add(cq.Workplane().box(1, 1, 1), name='a').add(cq.Workplane().box(1, 1, 1), name='b')
        .constrain('a@faces@>Z', 'b@faces@<Z', 'Plane').constrain('a', 'Fixed').solve())
import ezdxf, casadi, nlopt
print(all(getattr(m, '__file__', None) for m in (ezdxf, casadi, nlopt)))
print(round(sketch._edges[1].Length(), 6), round(assy.loc.toTuple()[0][2], 6),
      round(assy.objects['b'].loc.toTuple()[0][2], 6))
"""
    done = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    out = done.stdout.split("\n")
    assert out[0] == "[]"
    assert out[1] == "True"
    # the sketch's second segment solved to its constrained length; box b stacked on a (1 mm boxes)
    assert out[2].split() == ["2.0", "0.0", "1.0"]
    assert (tmp_path / "part.dxf").read_text(encoding="utf-8").lstrip().startswith("0")
