"""STEP and STL files of the solid, written so that nothing half-written is left behind,
and reading a STEP file back (its solid, its product names, faces found by position).

cadquery and OCP are imported only inside the functions that need them.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from designer.errors import FpdError
from designer.outputs.files import move_into_place, temporary_sibling
from designer.outputs.part import ascii_text

# STL tessellation: 0.01 mm chordal deviation, 0.1 rad angular deviation.
STL_TOLERANCE_MM = 0.01
STL_ANGULAR_TOLERANCE = 0.1


def step_name(name: str) -> str:
    """The product name as written into STEP: plain ASCII without quotes."""
    return ascii_text(name).replace("'", "") or "design"


def write_step(solid, path: str | os.PathLike, name: str) -> Path:
    """Write ``solid`` (mm) as STEP AP214 in millimetres with one product named ``name``."""
    path = Path(path)
    with temporary_sibling(path) as tmp:
        step_file(solid, tmp, name)
        move_into_place(tmp, path)
    return path


def write_stl(solid, path: str | os.PathLike) -> Path:
    """Write ``solid`` (mm) as binary STL, 0.01 mm chordal tolerance."""
    path = Path(path)
    with temporary_sibling(path) as tmp:
        stl_file(solid, tmp)
        move_into_place(tmp, path)
    return path


def step_file(solid, path: Path, name: str) -> None:
    """Write the STEP file straight to ``path`` (callers write to a temporary file and move it)."""
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer
    from OCP.StepBasic import StepBasic_Product
    from OCP.TCollection import TCollection_HAsciiString

    writer = STEPControl_Writer()
    # The writer's unit settings are global to OCCT; cadquery's own exporter sets them the same way.
    Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    writer.Transfer(solid.wrapped, STEPControl_StepModelType.STEPControl_AsIs)
    model = writer.Model()
    label = step_name(name)
    for i in range(1, model.NbEntities() + 1):
        entity = model.Value(i)
        if isinstance(entity, StepBasic_Product):
            entity.SetName(TCollection_HAsciiString(label))
            entity.SetId(TCollection_HAsciiString(label))
    status = writer.Write(str(path))
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise FpdError(f"{path}: the STEP file could not be written ({status})")


def stl_file(solid, path: Path) -> None:
    """Write the STL file straight to ``path`` (callers write to a temporary file and move it)."""
    ok = solid.exportStl(str(path), tolerance=STL_TOLERANCE_MM, angularTolerance=STL_ANGULAR_TOLERANCE,
                         ascii=False, relative=False)
    if not ok:
        raise FpdError(f"{path}: the STL file could not be written")


def read_step(path: str | os.PathLike):
    """The single solid of a STEP file (mm), read back from disk."""
    import cadquery as cq

    try:
        shapes = cq.importers.importStep(str(path)).solids().vals()
    except ValueError as exc:
        raise FpdError(f"{path}: not a readable STEP file ({exc})") from exc
    if len(shapes) != 1:
        raise FpdError(f"{path}: holds {len(shapes)} solids, expected one")
    return shapes[0]


def step_product_names(path: str | os.PathLike) -> list[str]:
    """The names of the PRODUCT entities of a STEP file."""
    text = Path(path).read_text(encoding="ascii", errors="replace")
    return re.findall(r"PRODUCT\('((?:[^']|'')*)'", text)


def planar_faces(solid, axis: str, level_mm: float, tol_mm: float = 1e-4) -> list[tuple]:
    """Centres (mm) of the planar faces normal to ``axis`` ('x', 'y', 'z') at ``axis = level_mm``."""
    i = "xyz".index(axis)
    out = []
    for face in solid.Faces():
        if face.geomType() != "PLANE":
            continue
        normal = face.normalAt().toTuple()
        if abs(abs(normal[i]) - 1.0) > 1e-9:
            continue
        centre = face.Center().toTuple()
        if abs(centre[i] - level_mm) <= tol_mm:
            out.append(centre)
    return sorted(out)


def cylinders(solid, axis: str, radius_mm: float, tol_mm: float = 1e-4) -> list[tuple]:
    """A point on the axis (mm) of each cylindrical face along ``axis`` with radius ``radius_mm``."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface

    i = "xyz".index(axis)
    out = []
    for face in solid.Faces():
        if face.geomType() != "CYLINDER":
            continue
        cyl = BRepAdaptor_Surface(face.wrapped).Cylinder()   # (a trimmed surface's too)
        direction = cyl.Axis().Direction()
        d = (direction.X(), direction.Y(), direction.Z())
        if abs(abs(d[i]) - 1.0) > 1e-9 or abs(cyl.Radius() - radius_mm) > tol_mm:
            continue
        loc = cyl.Location()
        out.append((loc.X(), loc.Y(), loc.Z()))
    return sorted(out)
