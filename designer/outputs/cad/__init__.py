"""The CAD model of a designed beam: a machinable CadQuery solid, STEP and STL files.

``beam`` resolves a design.json record into the part to build (``resolve``: checks and CAD
defaults), ``solid`` builds it (``build_solid``), ``step`` writes and reads STEP and STL,
``mesh`` tessellates the solid for the 3-D picture and ``writer`` writes every CAD output of a
design together (``export``, ``write_cad_outputs``). The part itself (``BeamCad``) is described
in ``designer.outputs.part``, shared with the drawing. cadquery is imported only inside the
functions that need it.
"""

from designer.outputs.cad.kernel import defer_extras, defer_vtk

defer_vtk()      # before anything imports cadquery (kernel.py: libraries it loads and fpdesign never uses)
defer_extras()

from designer.outputs.cad.beam import bolt_clearance, resolve  # noqa: E402
from designer.outputs.cad.mesh import clipped, model_meshes, tessellate
from designer.outputs.cad.solid import build_solid
from designer.outputs.cad.step import (cylinders, planar_faces, read_step, step_name, step_product_names, write_step,
                                       write_stl)
from designer.outputs.cad.writer import export, write_cad_outputs
from designer.outputs.part import MM, BeamCad, Channels, Clamp, Grooves, fmt_mm

__all__ = ["BeamCad", "Channels", "Clamp", "Grooves", "MM", "bolt_clearance", "build_solid", "clipped", "cylinders",
           "export", "fmt_mm", "model_meshes", "planar_faces", "read_step", "resolve", "step_name",
           "step_product_names", "tessellate", "write_cad_outputs", "write_step", "write_stl"]
