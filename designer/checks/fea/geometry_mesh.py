"""What the 3-D check meshes: the problem's numbers from a design, and gmsh's quarter model.

The design's STEP solid is cut at the clamp face ``X = 0`` and a few section sizes past the last
gauge station, ``X = x_cut``; only the quarter ``Y >= 0, Z >= 0`` is meshed (the design is
symmetric about ``XZ`` and, under a load along ``Z``, antisymmetric about ``XY``). Element sizes
follow the section, thin walls and features (the named settings below). gmsh is imported only
inside ``mesh_quarter``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designer.errors import DesignFileError, SolverError

# Mesh levels: a refinement factor on the base element sizes below; each step is 1.5 x finer.
MESH_LEVELS = {"coarse": 1.0, "normal": 1.5, "fine": 2.25}
# The convergence check repeats the run with every size this many times larger.
CONVERGENCE_COARSENING = 1.5
# Base sizes (refinement 1): elements across the section size in the load direction ...
ELEMENTS_PER_DEPTH = 2.0
# A wide plate (Prototype A) may have elements up to this fraction of its width across, and
# this many times its depth: quadratic elements stay accurate at that aspect ratio.
PLATE_ELEMENTS_ACROSS = 8.0
PLATE_ASPECT = 2.0
# ... across a thin wall (hole ligament, material under a pocket floor) ...
ELEMENTS_PER_WALL = 1.5
# ... across a feature's smallest plan dimension (pocket width, hole diameter) ...
ELEMENTS_PER_FEATURE = 4.0
# ... and around a full circle (round and tube sections, holes, corner radii): the facets of a
# 32-gon leave a round section's second moment about 1 % short, the strain about 0.5 % high.
ELEMENTS_PER_CIRCLE = 32
# Gmsh never makes elements smaller than this fraction of the feature size.
MIN_SIZE_FRACTION = 0.25
# The mesh is cut this many section sizes (the larger of width and depth) past the last
# feature: Saint-Venant end effects of the cut-face load decay over about one section size.
CUT_MARGIN = 2.0
# Refined boxes reach this many feature sizes beyond each feature (and its gauge grid).
REFINE_MARGIN = 0.5
# Geometric tolerance relative to the section size (nodes on symmetry planes, cut faces).
PLANE_TOLERANCE = 1e-7


@dataclass(frozen=True)
class Problem:
    """Everything the solver needs, SI."""

    E: float
    poisson: float
    force: float            # F, acting along -Z
    position: float         # x of the load
    free_length: float
    cut: float
    EI: float               # plain section beyond the cut
    depth: float            # section size along Z
    size: float             # larger of width and depth
    stations: tuple
    feature: str
    feature_length: float
    spans: tuple            # where the reduced section acts: the beam model's Geometry.reduced_spans
    gauge_z: float          # the gauge face's Z (pocket floor or surface)
    grid_length: float
    grid_width: float
    global_size: float      # base sizes at refinement 1
    detail_size: float


def build_problem(record: dict, beam, analysis, spec, material, geometry) -> Problem:
    """The problem of a design.json ``record``: its CAD ``beam`` (``outputs.cad.resolve``), the beam
    model's ``analysis``, ``spec``, ``material`` and model ``geometry``. DesignFileError names a
    gauge without its grid size."""
    g = record["design"]["gauge"]
    try:
        grid_length, grid_width = float(g["grid_length"]), float(g["grid_width"])
    except (KeyError, TypeError, ValueError) as exc:
        raise DesignFileError(f"design.gauge: {g!r} needs grid_length and grid_width (m) to place the gauge grid") \
            from exc
    sp = analysis.props
    depth = beam.height
    size = max(beam.width, beam.height)
    l_f = beam.feature_length
    x_max, f_max = spec.load.position_max, spec.load.force_max
    reach = beam.stations[-1] + max(l_f, grid_length) / 2
    cut = min(x_max, reach + CUT_MARGIN * size)

    # base element size: one element through the half depth (quadratic elements carry the
    # linear bending strain exactly); a wide plate may have flatter elements, a tube's wall one
    global_size = max(depth, min(beam.width / PLATE_ELEMENTS_ACROSS, PLATE_ASPECT * depth)) / ELEMENTS_PER_DEPTH
    if beam.section == "tube":
        global_size = min(global_size, beam.wall)
    detail_size = global_size          # a plain gauge site needs no refinement
    if beam.feature == "pocket":
        under = beam.wall - beam.pocket_depth if beam.section == "tube" else depth / 2 - beam.pocket_depth
        detail_size = min(global_size, under / ELEMENTS_PER_WALL,
                          min(beam.pocket_width, beam.pocket_length) / ELEMENTS_PER_FEATURE)
    elif beam.feature == "hole":
        detail_size = min(global_size, (depth - beam.hole_diameter) / 2 / ELEMENTS_PER_WALL,
                          beam.hole_diameter / ELEMENTS_PER_FEATURE)
    gauge_z = float(sp.y_g)
    spans = tuple((float(a), float(b)) for a, b in geometry.reduced_spans)
    return Problem(E=material.E, poisson=material.poisson, force=f_max, position=x_max,
                   free_length=beam.length, cut=cut, EI=material.E * float(sp.I), depth=depth, size=size,
                   stations=tuple(beam.stations), feature=beam.feature, feature_length=l_f, spans=spans,
                   gauge_z=gauge_z, grid_length=grid_length, grid_width=grid_width, global_size=global_size,
                   detail_size=detail_size)


def mesh_quarter(step_path: Path, pb: Problem, refinement: float):
    """gmsh: the quarter ``0 <= X <= x_cut, Y >= 0, Z >= 0`` of the STEP solid, linear tets."""
    import gmsh

    s_g = pb.global_size / refinement
    s_d = pb.detail_size / refinement
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setString("Geometry.OCCTargetUnit", "M")
        try:
            entities = gmsh.model.occ.importShapes(str(step_path))
        except Exception as exc:  # gmsh raises plain Exception
            raise SolverError(f"{step_path}: gmsh could not read the STEP model ({exc})") from exc
        big = 10 * pb.size
        box = gmsh.model.occ.addBox(0.0, 0.0, 0.0, pb.cut, big, big)
        volumes, _ = gmsh.model.occ.intersect(entities, [(3, box)])
        gmsh.model.occ.synchronize()
        if len(volumes) != 1:
            raise SolverError(f"cutting the STEP model at X = 0 and X = {pb.cut * 1e3:.2f} mm gave "
                              f"{len(volumes)} volumes, expected one; please report this design")

        f = gmsh.model.mesh.field
        boxes = []
        half = max(pb.feature_length, pb.grid_length) / 2 + REFINE_MARGIN * max(pb.feature_length, pb.depth)
        for d in pb.stations:
            b = f.add("Box")
            f.setNumber(b, "VIn", s_d)
            f.setNumber(b, "VOut", s_g)
            f.setNumber(b, "XMin", max(d - half, 0.0))
            f.setNumber(b, "XMax", d + half)
            f.setNumber(b, "YMin", -big)
            f.setNumber(b, "YMax", big)
            f.setNumber(b, "ZMin", -big)
            f.setNumber(b, "ZMax", big)
            f.setNumber(b, "Thickness", 2 * s_g)
            boxes.append(b)
        least = f.add("Min")
        f.setNumbers(least, "FieldsList", boxes)
        f.setAsBackgroundMesh(least)
        gmsh.option.setNumber("Mesh.MeshSizeMax", s_g)
        gmsh.option.setNumber("Mesh.MeshSizeMin", MIN_SIZE_FRACTION * s_d)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", ELEMENTS_PER_CIRCLE * refinement)
        gmsh.option.setNumber("Mesh.ElementOrder", 1)
        try:
            gmsh.model.mesh.generate(3)
        except Exception as exc:
            raise SolverError(f"gmsh could not mesh the beam ({exc})") from exc
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, tet_nodes = gmsh.model.mesh.getElementsByType(4)
    finally:
        gmsh.finalize()
    if len(tet_nodes) == 0:
        raise SolverError("gmsh made no tetrahedra for the beam; please report this design")
    index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    t = index[tet_nodes.astype(np.int64)].reshape(-1, 4).T
    used, t = np.unique(t, return_inverse=True)
    points = coords.reshape(-1, 3).T[:, used]
    return np.ascontiguousarray(points), np.ascontiguousarray(t.reshape(4, -1))
