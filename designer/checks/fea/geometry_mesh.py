"""What the 3-D check meshes: the problem's numbers from a design, and gmsh's quarter model.

The design's STEP solid is cut at the clamp face ``X = 0`` and a few section sizes past the last
gauge station, ``X = x_cut``; only the quarter ``Y >= 0, Z >= 0`` is meshed (the design is
symmetric about ``XZ`` and, under a load along ``Z``, antisymmetric about ``XY``). Element sizes
follow the section, thin walls and features (the named settings below): the detail size fills
the material within a thin wall's thickness of the features' faces (pocket floor, walls and
corners, hole bore) and grows from there at ``GRADING`` to the section's size, so plain lengths
and the far side of a thick section stay coarse. gmsh is imported only inside the functions that
mesh.

A mesh that gmsh cannot make, or that holds tetrahedra of no volume, comes from flat triangles
on a floor radius's narrow faces (FLAT_TRIANGLE): it is made once more with those faces meshed
by gmsh's MeshAdapt, and the check's convergence mesh is then made the same way. Every other
mesh is gmsh's first.

The STEP solid is built by cadquery in a child process (``write_step_apart``): the CAD kernel
alone holds about 0.5 GB, which is then free for the solve.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designer.errors import DesignFileError, SolverError
from designer.model.sections import shear_stiffness

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
# A thick tube's bore, holding less than this share (r_i / r_o)^4 of the section's second moment,
# takes elements as long as the outer surface's (ELEMENTS_PER_CIRCLE around the outside), not
# ELEMENTS_PER_CIRCLE around itself: its facets' share of the error in the second moment is then
# (r_i / r_o)^2 of the outer facets', while its small bore would otherwise fill the whole length
# with elements finer than the features' detail (two thirds of the gripper finger's mesh). A
# thin tube's bore (Prototype C: 30 %) keeps the full count.
BORE_SHARE = 0.05
# Gmsh never makes elements smaller than this fraction of the feature size ...
MIN_SIZE_FRACTION = 0.25
# ... except at a pocket's or flat's floor radius (the end mill's corner radius, where the floor
# meets the feature's end walls and the peak stress sits): there the elements are this share of
# the radius at refinement 1 (so that even the convergence mesh of a coarse check stays within the
# report's RESOLVED_RADIUS_SHARE = 0.5), fill the material within RADIUS_REACH radii of the
# fillet and grow at GRADING beyond. The optimised gripper finger's R0.2 flats (normal mesh):
# edges of 0.04 mm read 198.7 MPa and its convergence mesh 195.1 MPa (1.8 %); a mesh of 0.033 mm
# edges over twice the reach reads 201.4 MPa. Without this refinement (0.11 mm edges) the two
# meshes read 172 and 136 MPa.
RADIUS_SIZE = 0.3
RADIUS_REACH = 0.5
# The whole fillet is refined, across the beam: a band of three radii about the mid-plane (where a
# deep flat's peak sits) read a R0.1 flat on a Ø12 mm bar 7 % low next to the unrefined rest of
# the fillet (a peak at a vertex off the band, on 0.67 mm edges), and the optimised prototype B's
# slot, whose peak sits off the mid-plane, 7 % low (213 MPa; 229 MPa with the whole fillet, 221.5
# on the mesh 1.5 x coarser). The whole fillets cost the gripper finger's normal mesh 59 600
# elements against 18 800.
HXT = 10                 # gmsh's Mesh.Algorithm3D code of its parallel Delaunay, HXT
# gmsh's surface mesher (Frontal-Delaunay) can leave flat triangles (three corners in a line, or
# nearly) on a floor radius's faces, strips a quarter circle wide running across the beam: the
# R0.01 and R0.02 radii of 1 to 1.6 mm slots, the R0.2 radii of 8.4 mm flats on a 28 mm round. HXT
# then either stops ("a vertex lies in a segment": a boundary node on such a triangle's edge) or
# fills the triangle with tetrahedra of no volume, on which the stiffness is singular and
# conjugate gradients do not converge. Such a mesh is made again with the faces that carry a
# triangle flatter than FLAT_TRIANGLE (its area over an equilateral's on its longest edge; those
# faces' worst are 0 to 0.005) meshed by gmsh's MeshAdapt, which gives them sound triangles
# (0.2 and better). A mesh that meshes and has no tetrahedron flatter than FLAT_TETRAHEDRON (its
# volume over a regular one's on its longest edge; tetrahedra of no volume read 1e-16 and less,
# the worst of the meshes the examples and the bench suite solve 1e-5) is kept as it is.
MESH_ADAPT = 1           # gmsh's Mesh.Algorithm code of its MeshAdapt surface mesher
FLAT_TRIANGLE = 0.01
FLAT_TETRAHEDRON = 1e-9
# The mesh is cut this many section sizes (the larger of width and depth) past the last
# feature: Saint-Venant end effects of the cut-face load decay over about one section size.
CUT_MARGIN = 2.0
# The detail size fills the material within this many thin-wall thicknesses of a feature's
# faces (and at least ``DETAIL_ELEMENTS`` detail elements); beyond, the element size grows by
# GRADING per unit distance (0.4: each element at most about 1.4 x its neighbour) up to the
# section's size.
DETAIL_REACH = 1.0
DETAIL_ELEMENTS = 2.0
GRADING = 0.4
# A gauge grid short for its section (a 3 mm grid on a 60 mm bar, or a tube's wall-sized
# elements) reads its strain from the few elements it spans: on the normal mesh a Ø60 round bar's
# plain gauge moved 1-3 % between the check's two meshes. Elements of at most this share of the
# grid's length (at refinement 1) fill a box round each grid, one grid length deep, and grow at
# GRADING beyond it; a grid already finer-meshed than that is left as it is.
GRID_ELEMENTS = 3.0
# ... where the grid spans fewer elements than this (a 3 mm grid on a Ø20 mm bar spans 2.3 of
# its surface's elements on the normal mesh and moves 0.3 % at most between the two meshes; on a
# Ø60 mm bar 0.8 of one)
GRID_SPANS = 2.0
# Geometric tolerance relative to the section size (nodes on symmetry planes, cut faces).
PLANE_TOLERANCE = 1e-7
# ... and for a face's bounding box lying within a feature's span.
FACE_TOLERANCE = 1e-3


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
    detail_reach: float     # the detail size fills this distance from the features' faces (thin wall)
    bore: float             # a tube's bore radius (0: none)
    radius: float           # a round or tube section's outer radius (0: rectangle)
    floor_radius: float     # the pockets' floor radius (the end mill's corner radius; 0: none)
    plate: bool             # a thin wide plate: elements flatter than the depth across its width
    shear_stiffness: float = float("inf")   # kappa G A of the plain section beyond the cut (Cowper)
    grooves: tuple = ()     # the load grooves' spans (x0, x1), which a submodel checks (``groove``)
    biaxial: bool = False   # features on all four faces: the side (+Y) ones' floor radii refined too
    lateral: bool = False   # F along -Y instead of -Z (a biaxial design's other axis, ``solve``)


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
    plate = beam.section == "rectangle" and beam.width / PLATE_ELEMENTS_ACROSS > depth
    if beam.section == "tube":
        global_size = min(global_size, beam.wall)
    detail_size = global_size          # a plain gauge site needs no refinement
    wall = 0.0                         # the thin wall at a feature
    if beam.feature == "pocket":
        wall = beam.wall - beam.pocket_depth if beam.section == "tube" else depth / 2 - beam.pocket_depth
        detail_size = min(global_size, wall / ELEMENTS_PER_WALL,
                          min(beam.pocket_width, beam.pocket_length) / ELEMENTS_PER_FEATURE)
    elif beam.feature == "hole":
        wall = (depth - beam.hole_diameter) / 2
        detail_size = min(global_size, wall / ELEMENTS_PER_WALL, beam.hole_diameter / ELEMENTS_PER_FEATURE)
    detail_reach = DETAIL_REACH * wall
    gauge_z = float(sp.y_g)
    spans = tuple((float(a), float(b)) for a, b in geometry.reduced_spans)
    return Problem(E=material.E, poisson=material.poisson, force=f_max, position=x_max,
                   free_length=beam.length, cut=cut, EI=material.E * float(sp.I), depth=depth, size=size,
                   stations=tuple(beam.stations), feature=beam.feature, feature_length=l_f, spans=spans,
                   gauge_z=gauge_z, grid_length=grid_length, grid_width=grid_width, global_size=global_size,
                   detail_size=detail_size, detail_reach=detail_reach,
                   bore=beam.radius - beam.wall if beam.section == "tube" else 0.0,
                   radius=beam.radius if beam.section != "rectangle" else 0.0,
                   floor_radius=beam.floor_radius if beam.feature == "pocket" else 0.0, plate=plate,
                   shear_stiffness=float(shear_stiffness(geometry, sp, material.E, material.poisson)),
                   grooves=() if beam.grooves is None else tuple(
                       (x - beam.grooves.width / 2, x + beam.grooves.width / 2) for x in beam.grooves.positions),
                   biaxial=beam.axes == 2 and beam.feature == "pocket")


def write_step_apart(record: dict, path: Path) -> None:
    """The design's CAD solid as STEP at ``path``, built in a child Python so that the CAD kernel's
    memory is returned before the mesh and the solve. SolverError if the child fails. Where the
    kernel is loaded in this process already (a caller that exported CAD), a child would only
    load it again: the solid is then built here."""
    import json
    import os
    import subprocess
    import sys

    import designer

    if "cadquery" in sys.modules:
        from designer.outputs import cad

        beam = cad.resolve(record)
        cad.write_step(cad.build_solid(beam), path, beam.name)
        return

    root = str(Path(designer.__file__).resolve().parent.parent)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([root] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    code = ("import json, sys; from designer.outputs import cad; record = json.load(sys.stdin); "
            "beam = cad.resolve(record); cad.write_step(cad.build_solid(beam), sys.argv[1], beam.name)")
    done = subprocess.run([sys.executable, "-c", code, str(path)], input=json.dumps(record), text=True,
                          capture_output=True, env=env)
    if done.returncode != 0 or not Path(path).is_file():
        lines = [line for line in done.stderr.strip().splitlines() if line.strip()]
        raise SolverError("building the CAD solid failed" + (f": {lines[-1]}" if lines else "")
                          + "; please report this design")


def _feature_faces(pb: Problem) -> list:
    """gmsh's surfaces that the detail size grows from: a pocket's floor (with its edges, where
    the floor meets the walls), or every face of a hole (its bore); faces lying within a reduced
    span. A deep flat's tall end walls stay out: only their foot, within reach of the floor, is
    refined."""
    import gmsh

    tol = FACE_TOLERANCE * pb.size         # OCC's bounding boxes carry its tolerance
    faces, floors = [], []
    for dim, tag in gmsh.model.getEntities(2):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(dim, tag)
        if any(a - tol <= x0 and x1 <= b + tol for a, b in pb.spans):
            faces.append(tag)
            level = [abs(lo - pb.gauge_z) < tol and abs(hi - pb.gauge_z) < tol for lo, hi in ((z0, z1), (y0, y1))]
            if any(level):
                floors.append(tag)
    return floors if pb.feature == "pocket" and floors else faces


def _floor_radius_boxes(pb: Problem) -> list:
    """Bounding boxes ``(low, high)`` of the floor-radius faces at the clamp-side end of every
    pocket or flat, where the bending moment over each feature is largest and so its peak stress
    sits: the faces that rise from the floor (on the loaded face, +Z) by the floor radius within
    the radius of that end, across the whole beam. The first feature's carries the most moment,
    but a feature further from the clamp has the higher K_t (the clamp no longer stiffens its
    surroundings) and may carry the peak (docs/model.md §4). The far ends carry less moment; were
    a peak found there, the report's RESOLVED_RADIUS_SHARE test would say that the mesh does not
    resolve it."""
    import gmsh

    r = pb.floor_radius
    tol = FACE_TOLERANCE * pb.size
    rise = max(tol, 0.25 * r)            # OCC's boxes of curved faces may overshoot a little
    out = []
    for dim, tag in gmsh.model.getEntities(2):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(dim, tag)
        at_end = any(a - tol <= x0 <= a + r + tol and x1 <= b + tol for a, b in pb.spans)
        rises = abs(z0 - pb.gauge_z) < tol and tol < z1 - pb.gauge_z <= r + rise
        if pb.biaxial:   # a side feature's radius rises from its floor along +Y
            rises = rises or (abs(y0 - pb.gauge_z) < tol and tol < y1 - pb.gauge_z <= r + rise)
        if at_end and rises:
            out.append((np.array([x0, y0, z0]), np.array([x1, y1, z1])))
    return out


def mesh_quarter(step_path: Path, pb: Problem, refinement: float, mesh_adapt: bool = False):
    """gmsh: the quarter ``0 <= X <= x_cut, Y >= 0, Z >= 0`` of the STEP solid, linear tets
    ``(points (3, n), tets (4, E))``, and whether faces were meshed by MeshAdapt. A mesh that
    fails, or holds a tetrahedron of no volume, is made once more with MeshAdapt on the faces that
    carry flat triangles (see FLAT_TRIANGLE); gmsh is started afresh for it, as after a failed mesh
    it refuses to mesh again. ``mesh_adapt``: go straight to MeshAdapt on such faces (the
    convergence mesh of a check whose main mesh needed it, so that both are made alike).
    SolverError when the last mesh fails too."""
    import gmsh

    from designer import interrupt

    failure = None
    for again in (True,) if mesh_adapt else (False, True):
        gmsh.initialize(interruptible=False)
        interrupt.reinstall()   # gmsh has put SIGTERM back to its default action
        try:
            _set_up(step_path, pb, refinement)
            faces = _mesh_adapt_flat_faces() if again else []
            if again and not faces and not mesh_adapt:
                break                       # nothing to mesh otherwise: the same failure again
            try:
                with _c_output_dropped():
                    gmsh.model.mesh.generate(3)
                points, tets = _tetrahedra()
                problem = "it left tetrahedra of no volume" if _flat_tetrahedra(points, tets) else None
            except Exception as exc:  # gmsh raises plain Exception
                problem = str(exc)
            if problem is None:
                return points, tets, bool(faces)
            attempt = f"with MeshAdapt on {len(faces)} faces: {problem}"
            failure = f"{failure}; again {attempt}" if failure else (attempt if faces else problem)
        finally:
            gmsh.finalize()
    raise SolverError(f"gmsh could not mesh the beam ({failure})")


@contextmanager
def _c_output_dropped():
    """The process's standard output (file descriptor 1) sent to the null device for the block:
    gmsh's 3-D mesher prints some messages from C past ``General.Terminal`` (TetGen's
    "PLC Error: A vertex lies in a segment" while it recovers the boundary of a mesh that then
    succeeds), which would stand above the check's report as if it had failed. A mesh that does
    fail says so through gmsh's exception."""
    import ctypes
    import os
    import sys

    try:
        fflush = ctypes.CDLL(None).fflush
    except (OSError, TypeError, AttributeError):    # no C library by that name (Windows)
        fflush = None
    sys.stdout.flush()
    saved = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        try:
            yield
        finally:
            if fflush is not None:
                fflush(None)        # C's buffered output goes to the null device, not after it
            os.dup2(saved, 1)
    finally:
        os.close(null)
        os.close(saved)


def _mesh_adapt_flat_faces() -> list:
    """The surfaces whose Frontal-Delaunay mesh has flat triangles, set to be meshed by MeshAdapt
    (the surface mesh made to find them is cleared)."""
    import gmsh

    gmsh.model.mesh.generate(2)
    faces = _flat_faces()
    for tag in faces:
        gmsh.model.mesh.setAlgorithm(2, tag, MESH_ADAPT)
    gmsh.model.mesh.clear()
    return faces


def _plain_boxes(boxes) -> list:
    """``(low, high)`` corner arrays as tuples of floats, for ``_box_distance``."""
    return [(tuple(float(v) for v in lo), tuple(float(v) for v in hi)) for lo, hi in boxes]


def _box_distance(boxes, x: float, y: float, z: float) -> float:
    """The distance from ``(x, y, z)`` to the nearest of ``boxes``. Plain float arithmetic: gmsh
    asks the size callback once per point, hundreds of thousands of times, where numpy's
    per-call overhead on three-element arrays took 8 s of a 57 s check."""
    best = math.inf
    for (x0, y0, z0), (x1, y1, z1) in boxes:
        dx = max(x0 - x, x - x1, 0.0)
        dy = max(y0 - y, y - y1, 0.0)
        dz = max(z0 - z, z - z1, 0.0)
        best = min(best, dx * dx + dy * dy + dz * dz)
    return math.sqrt(best)


def _grid_size(pb: Problem, refinement: float) -> float:
    """The element size at the gauge grids before their own refinement: the features' detail
    size, or the section's, or a round surface's facets (ELEMENTS_PER_CIRCLE)."""
    size = (pb.detail_size if pb.feature != "none" else pb.global_size) / refinement
    if pb.radius > 0:
        size = min(size, 2 * np.pi * pb.radius / (ELEMENTS_PER_CIRCLE * refinement))
    return size


def _gauge_boxes(pb: Problem) -> list:
    """Each gauge grid's footprint on the gauge face (the quarter model's half width), one grid
    length deep: ``(low corner, high corner)`` float tuples, for ``_box_distance``."""
    half, z = pb.grid_length / 2, float(pb.gauge_z)
    return [((float(d) - half, 0.0, z - pb.grid_length), (float(d) + half, pb.grid_width / 2, z)) for d in pb.stations]


def _set_up(step_path: Path, pb: Problem, refinement: float) -> None:
    """gmsh (started): the quarter model cut from the STEP solid, its element sizes and options."""
    import gmsh

    s_g = pb.global_size / refinement
    s_d = pb.detail_size / refinement
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

    faces = _feature_faces(pb) if s_d < s_g else []
    if faces:
        # the detail size within detail_reach of the features' faces, then graded to s_g
        f = gmsh.model.mesh.field
        distance = f.add("Distance")
        f.setNumbers(distance, "SurfacesList", faces)
        f.setNumber(distance, "Sampling", int(min(200, np.ceil(pb.feature_length / s_d) + 2)))
        reach = max(pb.detail_reach, DETAIL_ELEMENTS * s_d)
        ramp = f.add("Threshold")
        f.setNumber(ramp, "InField", distance)
        f.setNumber(ramp, "SizeMin", s_d)
        f.setNumber(ramp, "SizeMax", s_g)
        f.setNumber(ramp, "DistMin", reach)
        f.setNumber(ramp, "DistMax", reach + (s_g - s_d) / GRADING)
        f.setAsBackgroundMesh(ramp)
    gmsh.option.setNumber("Mesh.MeshSizeMax", s_g)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", ELEMENTS_PER_CIRCLE * refinement)
    gmsh.option.setNumber("Mesh.ElementOrder", 1)
    sizers = []
    if 0 < pb.bore and (pb.bore / pb.radius) ** 4 < BORE_SHARE:
        # the bore's elements as long as the outer surface's (never longer than the section's)
        # and no longer than the detail size's ramp along X near the features (a flat's floor
        # may lie a thin wall above the bore)
        bore_size = min(s_g, 2 * np.pi * pb.radius / (ELEMENTS_PER_CIRCLE * refinement))
        near = FACE_TOLERANCE * pb.size
        reach = max(pb.detail_reach, DETAIL_ELEMENTS * s_d) if s_d < s_g else 0.0

        def bore(dim, x, y, z, lc):
            if dim == 3 or abs(np.hypot(y, z) - pb.bore) > near:
                return lc
            beyond = min(max(a - reach - x, x - b - reach, 0.0) for a, b in pb.spans)
            return max(lc, min(bore_size, s_d + GRADING * beyond))

        sizers.append(bore)
    boxes = _floor_radius_boxes(pb) if pb.floor_radius > 0 else []
    if boxes:
        # gmsh's minimum drops to the floor radius's size; everywhere else the old minimum
        # still holds (the callback lifts gmsh's size to it), so that curved faces far from
        # the radius (a slot's plan corners, a tube's bore) keep the sizes they had
        s_r = min(RADIUS_SIZE * pb.floor_radius / refinement, s_d)
        r_reach = RADIUS_REACH * pb.floor_radius
        radius_boxes = _plain_boxes(boxes)
        old_min = MIN_SIZE_FRACTION * s_d
        min_size = s_r

        def radius(dim, x, y, z, lc):
            d = _box_distance(radius_boxes, x, y, z)
            return min(max(lc, old_min), s_r + GRADING * max(d - r_reach, 0.0))

        sizers.append(radius)
        # gmsh's default 3-D Delaunay stalls for minutes on a radius this much finer than the
        # section (a R0.25 flat on a 30 mm tube: over 300 s); HXT meshes it in seconds
        gmsh.option.setNumber("Mesh.Algorithm3D", HXT)
    else:
        min_size = MIN_SIZE_FRACTION * s_d
    s_grid = pb.grid_length / (GRID_ELEMENTS * refinement)
    if _grid_size(pb, refinement) > pb.grid_length / GRID_SPANS:
        grid_boxes = _gauge_boxes(pb)

        def grid(dim, x, y, z, lc):
            return min(lc, s_grid + GRADING * _box_distance(grid_boxes, x, y, z))

        sizers.append(grid)    # last: the floor radius's sizer lifts sizes to its minimum
        min_size = min(min_size, s_grid)
    gmsh.option.setNumber("Mesh.MeshSizeMin", min_size)
    if sizers:
        def size(dim, tag, x, y, z, lc):
            for sizer in sizers:
                lc = sizer(dim, x, y, z, lc)
            return lc

        gmsh.model.mesh.setSizeCallback(size)


def _tetrahedra():
    """gmsh's tetrahedra as ``(points (3, n), tets (4, E))``, only the vertices they use."""
    import gmsh

    tags, coords, _ = gmsh.model.mesh.getNodes()
    _, tet_nodes = gmsh.model.mesh.getElementsByType(4)
    if len(tet_nodes) == 0:
        raise SolverError("gmsh made no tetrahedra for the beam; please report this design")
    index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    t = index[tet_nodes.astype(np.int64)].reshape(-1, 4).T
    used, t = np.unique(t, return_inverse=True)
    points = coords.reshape(-1, 3).T[:, used]
    return np.ascontiguousarray(points), np.ascontiguousarray(t.reshape(4, -1))


def tetrahedron_shapes(points: np.ndarray, tets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The squared lengths of the six edges (6, E) and the volumes (E,) of the tetrahedra ``tets``
    (4, E); a regular tetrahedron on edge ``L`` has ``L^3 / (6 sqrt 2)``."""
    x = points[:, tets]                                                   # (3, 4, E)
    edges = x[:, [1, 2, 3, 2, 3, 3]] - x[:, [0, 0, 0, 1, 1, 2]]           # (3, 6, E)
    volume = np.abs(np.einsum("ie,ie->e", edges[:, 0], np.cross(edges[:, 1], edges[:, 2], axis=0))) / 6
    return np.sum(edges ** 2, axis=0), volume


def _flat_tetrahedra(points: np.ndarray, tets: np.ndarray) -> bool:
    """Whether a tetrahedron's volume is below FLAT_TETRAHEDRON of a regular one's on its longest edge."""
    squared, volume = tetrahedron_shapes(points, tets)
    longest = np.sqrt(np.max(squared, axis=0))
    return bool(np.any(volume < FLAT_TETRAHEDRON * longest ** 3 / (6 * np.sqrt(2))))


def _flat_faces() -> list:
    """The surfaces whose triangles include one of area below FLAT_TRIANGLE of an equilateral's on
    its longest edge."""
    import gmsh

    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    xyz = coords.reshape(-1, 3)
    out = []
    for _, tag in gmsh.model.getEntities(2):
        _, nodes = gmsh.model.mesh.getElementsByType(2, tag)
        if len(nodes) == 0:
            continue
        a, b, c = xyz[index[nodes.astype(np.int64)].reshape(-1, 3).T]
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        longest = np.max([np.sum((b - a) ** 2, axis=1), np.sum((c - b) ** 2, axis=1), np.sum((a - c) ** 2, axis=1)],
                         axis=0)
        if np.any(area < FLAT_TRIANGLE * np.sqrt(3) / 4 * longest):
            out.append(tag)
    return out
