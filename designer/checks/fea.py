"""A 3-D finite-element check of a design against the beam model (MODEL.md sections 2-4).

The beam model is Euler-Bernoulli theory with closed-form sections. Features that disturb
the strain field (pockets, flats and above all transverse holes) and the clamp are where it
stops being exact; this module measures by how much for one design.

How the check is made:

- The design's CAD solid (``designer.cad``) is written as STEP and read back by gmsh, which
  cuts it at the clamp face ``X = 0`` (the clamp block is not meshed: the clamp face is held
  fixed) and a few section sizes past the last gauge station, ``X = x_cut``. Every design is
  symmetric about the ``XZ`` plane and, under a load along ``Z``, antisymmetric about the
  ``XY`` plane, so only the quarter ``Y >= 0, Z >= 0`` is meshed, with ``u_y = 0`` on
  ``Y = 0`` and ``u_x = u_y = 0`` on ``Z = 0``.
- Linear elasticity with quadratic tetrahedra (scikit-fem's ``ElementTetP2``), assembled here
  in vectorised form and solved by conjugate gradients preconditioned with a two-level
  (quadratic / linear) cycle.
- The load ``F_max`` at ``x_max`` enters at the cut face as its resultant (Saint-Venant): a
  uniform shear ``tau = -F/A`` and a bending stress ``sigma = M z / I`` with
  ``M = F (x_max - x_cut)``; ``A`` and ``I`` are integrated over the meshed cut face.
- The free-end deflection is the cut face's mean deflection ``w_c`` and slope ``w'_c`` (least
  squares of ``u_x = -z w'``) carried to the free end with Euler-Bernoulli over the plain rest:
  ``w(l) = w_c + w'_c (l - x_cut) + F a^3/(3EI) + F a^2/(2EI) (l - x_max)``, ``a = x_max - x_cut``.
- A gauge reads the mean of ``eps_xx`` over its grid's footprint (``grid_length x grid_width``
  centred on the station, on the gauge face: the pocket floor, or the beam's surface). Along
  each line of the grid that mean is exactly ``(u_x(end) - u_x(start)) / grid_length``; the
  lines are combined with Gauss-Legendre weights across the grid's width.
- The peak stress is the von Mises stress averaged at the mesh vertices, away from the
  clamp face, whose idealised full fixity is singular at its edges; the root stress stays
  the beam model's.
- Every run is repeated on a mesh one step coarser, and the change is reported as the
  mesh-convergence check.

``verify_design(record, mesh, out_dir)`` returns a complete ``VerifyResult``; gmsh, scikit-fem,
cadquery and matplotlib are imported only inside the functions that need them.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from designer.errors import DesignFileError, InputError, SolverError, describe_allowed

# ----------------------------------------------------------------- named settings

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
# Stress is not taken closer to the clamp face or the cut face than this many section depths:
# the idealised clamp (every node fixed) is singular at the edges of the clamp face; nor closer
# than this many elements, over which the singular peak spreads.
STRESS_EXCLUSION = 0.5
STRESS_EXCLUSION_ELEMENTS = 2.0
# Gauss-Legendre lines across half a gauge grid's width (the other half is the mirror image).
GAUGE_LINES = 4
# Points along the surface-strain profile, from this fraction of an element off the clamp face.
PROFILE_POINTS = 400
PROFILE_START = 0.25
# The strain plot's axis reaches this many times the largest beam-model strain; peaks at sharp
# corners beyond it are named in a note instead.
PLOT_HEADROOM = 1.6
# Conjugate gradients: relative residual, iteration cap; damping of the Jacobi smoother as a
# fraction of 2 / lambda_max(D^-1 K) (1.5 / lambda_max: inside the convergent range).
CG_TOLERANCE = 1e-10
CG_MAX_ITERATIONS = 3000
SMOOTHER_DAMPING = 1.5
# Convergence: relative change between the two meshes that counts as converged. For a
# second-order rate the finer mesh's error is at most 0.8 x the change (1 / (1.5^2 - 1)) and in
# practice far less (Prototype B: 1.8 % coarse to normal, then 0.2 % normal to fine).
CONVERGED_STRAIN = 0.02
CONVERGED_DEFLECTION = 0.01
CONVERGED_STRESS = 0.05
# A gauge-strain ratio further than this from 1 is worth a sentence in the report.
RATIO_NOTE = 0.03
# Geometric tolerance relative to the section size (nodes on symmetry planes, cut faces).
PLANE_TOLERANCE = 1e-7
# Upward surface facets: outward normal's Z component at least this.
UP_FACING = 0.2
# Candidate facets searched for each surface point.
FACET_CANDIDATES = 64

MPA = 1e6
MICRO = 1e-6


# ----------------------------------------------------------------- results

@dataclass(frozen=True)
class GaugeCheck:
    station: float          # d_i, m
    fea_strain: float       # mean eps_xx over the grid footprint under F_max at x_max
    model_strain: float     # MODEL.md eq. 3
    coarse_strain: float    # the same on the convergence mesh

    @property
    def ratio(self) -> float:
        return self.fea_strain / self.model_strain

    @property
    def mesh_change(self) -> float:
        return abs(self.fea_strain - self.coarse_strain) / abs(self.fea_strain)


LIMIT_TOLERANCE = 1e-9  # as evaluation.Evaluation.violations


@dataclass(frozen=True)
class LimitCheck:
    """A limit of MODEL.md section 4 with the beam model's value and the value the 3-D check gives."""

    name: str
    model_value: float
    fea_value: float
    limit: float
    upper: bool
    source: str             # how fea_value was obtained
    unit: str = ""
    scale: float | None = None  # as model.Limit: the normalising scale (None: the limit itself)

    def _holds(self, value: float) -> bool:
        """The model's rule: the normalised violation at most 1e-9 (model.Limit, evaluation)."""
        gap = value - self.limit if self.upper else self.limit - value
        scale = self.scale if self.scale is not None else abs(self.limit)
        return gap / (scale or 1.0) <= LIMIT_TOLERANCE

    @property
    def satisfied(self) -> bool:
        return self._holds(self.fea_value)

    @property
    def model_satisfied(self) -> bool:
        return self._holds(self.model_value)


@dataclass(frozen=True)
class MeshRun:
    level: str
    refinement: float
    global_size: float      # m
    detail_size: float      # m
    elements: int
    vertices: int
    dofs: int
    cg_iterations: int
    seconds: float


@dataclass(frozen=True)
class StressPeak:
    value: float            # von Mises, Pa
    location: tuple         # (X, Y, Z), m
    where: str              # "pocket corner", "hole edge", ...


@dataclass(frozen=True)
class VerifyResult:
    """The 3-D check of one design under ``force`` at ``position`` (F_max at x_max), SI."""

    name: str
    mesh: str
    force: float
    position: float
    free_length: float
    cut: float                      # x_cut, m
    gauges: tuple                   # GaugeCheck per station
    deflection_fea: float           # free end, m (downward positive)
    deflection_model: float
    deflection_coarse: float
    stress_peak: StressPeak         # FEA, away from the clamp face
    stress_peak_coarse: float
    stress_feature_fea: float       # FEA peak within the feature zones
    stress_model: float             # the beam model's largest stress
    stress_root_model: float
    stress_allowable: float
    limits: tuple                   # LimitCheck
    runs: tuple                     # MeshRun: the requested mesh, then the convergence mesh
    profile_x: tuple                # surface strain along the top centre line, m
    profile_fea: tuple
    profile_model: tuple
    gauge_grid: tuple               # (grid_length, grid_width), m
    feature_length: float
    messages: tuple
    seconds: float

    @property
    def ratios(self) -> tuple:
        return tuple(g.ratio for g in self.gauges)

    @property
    def converged(self) -> bool:
        return (max(g.mesh_change for g in self.gauges) <= CONVERGED_STRAIN
                and self.deflection_change <= CONVERGED_DEFLECTION)

    @property
    def deflection_change(self) -> float:
        return abs(self.deflection_fea - self.deflection_coarse) / abs(self.deflection_fea)

    @property
    def stress_change(self) -> float:
        return abs(self.stress_peak.value - self.stress_peak_coarse) / self.stress_peak.value

    @property
    def passed(self) -> bool:
        return all(c.satisfied for c in self.limits)

    def as_dict(self) -> dict:
        """Every figure as plain JSON types (verify.json, design.json's ``verification``)."""
        return {
            "name": self.name, "mesh": self.mesh, "passed": self.passed, "converged": self.converged,
            "load": {"force": self.force, "position": self.position}, "free_length": self.free_length,
            "cut": self.cut,
            "gauges": [{"station": g.station, "fea_strain": g.fea_strain, "model_strain": g.model_strain,
                        "ratio": g.ratio, "coarse_strain": g.coarse_strain, "mesh_change": g.mesh_change}
                       for g in self.gauges],
            "deflection": {"fea": self.deflection_fea, "model": self.deflection_model,
                           "ratio": self.deflection_fea / self.deflection_model,
                           "coarse": self.deflection_coarse, "mesh_change": self.deflection_change},
            "stress": {"fea_peak": self.stress_peak.value, "location": list(self.stress_peak.location),
                       "where": self.stress_peak.where, "fea_feature": self.stress_feature_fea,
                       "coarse_peak": self.stress_peak_coarse, "mesh_change": self.stress_change,
                       "model_max": self.stress_model, "model_root": self.stress_root_model,
                       "allowable": self.stress_allowable},
            "limits": [{"name": c.name, "model": c.model_value, "fea": c.fea_value, "limit": c.limit,
                        "sense": "<=" if c.upper else ">=", "satisfied": c.satisfied,
                        "model_satisfied": c.model_satisfied, "source": c.source, "unit": c.unit}
                       for c in self.limits],
            "meshes": [asdict(r) for r in self.runs],
            "profile": {"x": list(self.profile_x), "fea": list(self.profile_fea), "model": list(self.profile_model)},
            "messages": list(self.messages), "seconds": self.seconds,
        }

    def plot(self, ax=None):
        return plot_surface_strain(self, ax=ax)


# ----------------------------------------------------------------- what is meshed

@dataclass(frozen=True)
class _Problem:
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
    gauge_z: float          # the gauge face's Z (pocket floor or surface)
    grid_length: float
    grid_width: float
    global_size: float      # base sizes at refinement 1
    detail_size: float


def _problem(record: dict, beam, analysis, spec, material) -> _Problem:
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
    return _Problem(E=material.E, poisson=material.poisson, force=f_max, position=x_max,
                    free_length=beam.length, cut=cut, EI=material.E * float(sp.I), depth=depth, size=size,
                    stations=tuple(beam.stations), feature=beam.feature, feature_length=l_f, gauge_z=gauge_z,
                    grid_length=grid_length, grid_width=grid_width, global_size=global_size,
                    detail_size=detail_size)


def _mesh_quarter(step_path: Path, pb: _Problem, refinement: float):
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


# ----------------------------------------------------------------- the solver

@dataclass(frozen=True)
class _Solution:
    mesh: object
    basis: object            # scalar P2 basis
    u: np.ndarray            # (3, N) displacement at the P2 nodes
    iterations: int


def _lame(E: float, nu: float) -> tuple[float, float]:
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _stiffness(basis, E: float, nu: float):
    """The P2 elasticity stiffness, vector dofs interleaved (3 n + component)."""
    import scipy.sparse as sp

    lam, mu = _lame(E, nu)
    n_fun = basis.Nbfun
    G = np.array([basis.basis[i][0].grad for i in range(n_fun)])    # (i, a, e, q)
    Gw = G * basis.dx[None, None]
    K = lam * np.einsum("iaeq,jbeq->eiajb", Gw, G, optimize=True)
    K += mu * np.einsum("ibeq,jaeq->eiajb", Gw, G, optimize=True)
    diag = mu * np.einsum("iceq,jceq->eij", Gw, G, optimize=True)
    for a in range(3):
        K[:, :, a, :, a] += diag
    dofs = (3 * basis.element_dofs[:, :, None] + np.arange(3)).transpose(1, 0, 2).reshape(-1, 3 * n_fun)
    rows = np.repeat(dofs, 3 * n_fun, axis=1).ravel()
    cols = np.tile(dofs, (1, 3 * n_fun)).ravel()
    n = 3 * basis.N
    return sp.csr_matrix((K.ravel(), (rows, cols)), shape=(n, n))


def _prolongation(basis, mesh):
    """Linear (P1 on the vertices) to quadratic interpolation, scalar."""
    import scipy.sparse as sp

    nv = mesh.p.shape[1]
    vertex = basis.nodal_dofs[0]
    edge = basis.edge_dofs[0]
    rows = np.concatenate([vertex, edge, edge])
    cols = np.concatenate([np.arange(nv), mesh.edges[0], mesh.edges[1]])
    vals = np.concatenate([np.ones(nv), 0.5 * np.ones(2 * len(edge))])
    return sp.csr_matrix((vals, (rows, cols)), shape=(basis.N, nv))


def _constrained(xyz: np.ndarray, pb: _Problem) -> np.ndarray:
    """(3, n) mask of fixed components at points ``xyz``: clamp, symmetry and antisymmetry."""
    tol = PLANE_TOLERANCE * pb.size
    clamp = np.abs(xyz[0]) < tol
    y0 = np.abs(xyz[1]) < tol
    z0 = np.abs(xyz[2]) < tol
    return np.array([clamp | z0, clamp | y0 | z0, clamp])


def _solve(points, tets, pb: _Problem) -> _Solution:
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla
    from skfem import Basis, ElementTetP2, FacetBasis, Functional, LinearForm, MeshTet, asm

    mesh = MeshTet(points, tets)
    basis = Basis(mesh, ElementTetP2(), intorder=2)
    K = _stiffness(basis, pb.E, pb.poisson)

    # the cut face: the load's resultant as beam-theory tractions
    tol = PLANE_TOLERANCE * pb.size
    cut_facets = mesh.facets_satisfying(lambda x: np.abs(x[0] - pb.cut) < tol, boundaries_only=True)
    if len(cut_facets) == 0:
        raise SolverError("the mesh has no face at the cut; please report this design")
    fb = FacetBasis(mesh, ElementTetP2(), facets=cut_facets)
    area_q = asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), fb)
    inertia_q = asm(Functional(lambda w: w.x[2] ** 2), fb)
    area, inertia = 4 * area_q, 4 * inertia_q           # the whole section
    moment = pb.force * (pb.position - pb.cut)
    fx = asm(LinearForm(lambda v, w: moment * w.x[2] / inertia * v), fb)
    fz = asm(LinearForm(lambda v, w: -pb.force / area * v), fb)
    f = np.zeros(3 * basis.N)
    f[0::3], f[2::3] = fx, fz

    fixed = _constrained(basis.doflocs, pb).T.ravel()
    free = ~fixed
    Kf = K[free][:, free].tocsr()
    ff = f[free]

    # two-level preconditioner: damped Jacobi on P2, exact solve of the Galerkin P1 problem
    P = sp.kron(_prolongation(basis, mesh), sp.eye(3), format="csr")
    fixed_v = _constrained(mesh.p, pb).T.ravel()
    P = P[free][:, ~fixed_v].tocsc()
    coarse = (P.T @ Kf @ P).tocsc()
    try:
        lu = spla.splu(coarse, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
    except RuntimeError as exc:
        raise SolverError(f"the coarse finite-element system is singular ({exc}); the beam is not held") from exc
    dinv = 1.0 / Kf.diagonal()
    scaled = sp.diags(np.sqrt(dinv)) @ Kf @ sp.diags(np.sqrt(dinv))
    lam_max = spla.eigsh(scaled, k=1, which="LA", tol=1e-2, return_eigenvectors=False)[0]
    omega = SMOOTHER_DAMPING / lam_max

    def cycle(r):
        x = omega * dinv * r
        x = x + P @ lu.solve(P.T @ (r - Kf @ x))
        return x + omega * dinv * (r - Kf @ x)

    count = [0]

    def tick(_):
        count[0] += 1

    x, info = spla.cg(Kf, ff, M=spla.LinearOperator(Kf.shape, cycle), rtol=CG_TOLERANCE,
                      maxiter=CG_MAX_ITERATIONS, callback=tick)
    if info != 0:
        raise SolverError(f"the finite-element solve did not converge in {CG_MAX_ITERATIONS} iterations")
    u = np.zeros(3 * basis.N)
    u[free] = x
    return _Solution(mesh, basis, u.reshape(-1, 3).T, count[0])


# ----------------------------------------------------------------- reading the solution

def _probe_matrix(basis, points: np.ndarray, cells: np.ndarray, derivative: int | None = None):
    """Values (or the derivative along axis ``derivative``) at ``points`` (3, n) lying in or on
    the given ``cells``, as a sparse matrix acting on a scalar P2 field."""
    from scipy.sparse import coo_matrix

    local = basis.mapping.invF(points[:, :, None], tind=cells)
    local = np.clip(local, 0.0, 1.0)
    fields = [basis.elem.gbasis(basis.mapping, local, k, tind=cells)[0] for k in range(basis.Nbfun)]
    phis = np.array([np.asarray(f) if derivative is None else f.grad[derivative] for f in fields]).reshape(basis.Nbfun, -1)
    n = points.shape[1]
    rows = np.tile(np.arange(n), basis.Nbfun)
    cols = basis.element_dofs[:, cells].ravel()
    return coo_matrix((phis.ravel(), (rows, cols)), shape=(n, basis.N)).tocsr()


def _up_facets(mesh):
    """Boundary facets whose outward normal points up (+Z), with their triangles."""
    facets = mesh.boundary_facets()
    tri = mesh.p[:, mesh.facets[:, facets]]                    # (3 coords, 3 nodes, n)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], axis=0)
    normal /= np.linalg.norm(normal, axis=0)
    cell = mesh.f2t[0, facets]
    outward = tri.mean(axis=1) - mesh.p[:, mesh.t[:, cell]].mean(axis=1)
    normal *= np.sign(np.sum(normal * outward, axis=0))
    up = normal[2] > UP_FACING
    return tri[:, :, up], cell[up]


def _surface_points(mesh, xy: np.ndarray, below: float | None = None):
    """The top surface of the mesh above each ``(x, y)``: points (3, n) and their cells.

    ``below``: only surface at or below this Z (skips walls' tops over a pocket floor).
    """
    from scipy.spatial import cKDTree

    tri, cell = _up_facets(mesh)
    tree = cKDTree(tri[:2].mean(axis=1).T)
    k = min(FACET_CANDIDATES, tri.shape[2])
    _, cand = tree.query(xy.T, k=k)
    cand = cand.reshape(xy.shape[1], k)
    a, b, c = tri[:, 0][:, cand], tri[:, 1][:, cand], tri[:, 2][:, cand]   # (3, n, k)
    px, py = xy[0][:, None], xy[1][:, None]
    det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
    l1 = ((px - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (py - a[1])) / det
    l2 = ((b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1])) / det
    l0 = 1 - l1 - l2
    eps = 1e-9
    inside = (l0 >= -eps) & (l1 >= -eps) & (l2 >= -eps)
    z = l0 * a[2] + l1 * b[2] + l2 * c[2]
    if below is not None:
        inside &= z <= below
    z = np.where(inside, z, -np.inf)
    best = np.argmax(z, axis=1)
    rows = np.arange(xy.shape[1])
    if not np.all(np.isfinite(z[rows, best])):
        missing = xy[:, ~np.isfinite(z[rows, best])][:, 0]
        raise SolverError(f"no beam surface found above X = {missing[0] * 1e3:.2f} mm, "
                          f"Y = {missing[1] * 1e3:.2f} mm; please report this design")
    points = np.vstack([xy, z[rows, best]])
    return points, cell[cand[rows, best]]


def _axial_displacement(sol: _Solution, points, cells):
    return _probe_matrix(sol.basis, points, cells) @ sol.u[0]


def _gauge_strains(sol: _Solution, pb: _Problem) -> list[float]:
    """Mean eps_xx over each gauge grid's footprint on the gauge face."""
    t, w = np.polynomial.legendre.leggauss(GAUGE_LINES)
    ys = (t + 1) / 2 * pb.grid_width / 2
    out = []
    for d in pb.stations:
        x1, x2 = d - pb.grid_length / 2, d + pb.grid_length / 2
        xy = np.array([np.r_[np.full(GAUGE_LINES, x1), np.full(GAUGE_LINES, x2)], np.r_[ys, ys]])
        points, cells = _surface_points(sol.mesh, xy, below=pb.gauge_z + PLANE_TOLERANCE * pb.size)
        ux = _axial_displacement(sol, points, cells)
        strain = (ux[GAUGE_LINES:] - ux[:GAUGE_LINES]) / pb.grid_length
        out.append(float(np.sum(w * strain) / np.sum(w)))
    return out


def _profile(sol: _Solution, pb: _Problem, start: float):
    """eps_xx at the surface along the top centre line (the element's own value at each point)."""
    x = np.linspace(start, pb.cut - start, PROFILE_POINTS)
    xy = np.array([x, np.full_like(x, PLANE_TOLERANCE * 1e3 * pb.size)])
    points, cells = _surface_points(sol.mesh, xy)
    return x, points[2], _probe_matrix(sol.basis, points, cells, derivative=0) @ sol.u[0]


def _cut_face_motion(sol: _Solution, pb: _Problem) -> tuple[float, float]:
    """Mean deflection ``w_c`` and slope ``w'_c`` of the cut face (least squares of u_x = -z w')."""
    from skfem import FacetBasis, Functional, asm

    tol = PLANE_TOLERANCE * pb.size
    facets = sol.mesh.facets_satisfying(lambda x: np.abs(x[0] - pb.cut) < tol, boundaries_only=True)
    fb = FacetBasis(sol.mesh, sol.basis.elem, facets=facets)
    ux, uz = fb.interpolate(sol.u[0]), fb.interpolate(sol.u[2])
    area = asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), fb)
    zz = asm(Functional(lambda w: w.x[2] ** 2), fb)
    w_c = asm(Functional(lambda w: w["uz"]), fb, uz=uz) / area
    slope = -asm(Functional(lambda w: w["ux"] * w.x[2]), fb, ux=ux) / zz
    return float(w_c), float(slope)


def _free_end_deflection(sol: _Solution, pb: _Problem) -> float:
    """Downward deflection of the free end: the cut's motion carried on by beam theory."""
    w_c, slope = _cut_face_motion(sol, pb)
    a = pb.position - pb.cut
    beyond = pb.force * a ** 3 / (3 * pb.EI) + pb.force * a ** 2 / (2 * pb.EI) * (pb.free_length - pb.position)
    return -(w_c + slope * (pb.free_length - pb.cut)) + beyond


def _vertex_von_mises(sol: _Solution, pb: _Problem) -> np.ndarray:
    """Von Mises stress at the mesh vertices, the stress tensor averaged over the elements at each."""
    from skfem import Basis

    corners = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    vb = Basis(sol.mesh, sol.basis.elem, quadrature=(corners, np.ones(4) / 24))
    G = np.array([vb.basis[i][0].grad for i in range(vb.Nbfun)])      # (i, a, e, q)
    ue = sol.u[:, vb.element_dofs]                                     # (c, i, e)
    grad = np.einsum("cie,iaeq->caeq", ue, G)
    strain = (grad + grad.transpose(1, 0, 2, 3)) / 2
    lam, mu = _lame(pb.E, pb.poisson)
    trace = np.einsum("cceq->eq", strain)
    stress = 2 * mu * strain
    for a in range(3):
        stress[a, a] += lam * trace
    nv = sol.mesh.p.shape[1]
    total = np.zeros((3, 3, nv))
    count = np.zeros(nv)
    for q in range(4):
        np.add.at(total.transpose(2, 0, 1), sol.mesh.t[q], stress[:, :, :, q].transpose(2, 0, 1))
        np.add.at(count, sol.mesh.t[q], 1.0)
    s = total / count
    return np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - s[2, 2]) ** 2 + (s[2, 2] - s[0, 0]) ** 2)
                   + 3 * (s[0, 1] ** 2 + s[1, 2] ** 2 + s[0, 2] ** 2))


@dataclass(frozen=True)
class _Figures:
    gauges: tuple
    deflection: float
    peak: StressPeak
    feature_peak: float
    profile: tuple
    run: MeshRun


def _feature_zone(x: np.ndarray, pb: _Problem) -> np.ndarray:
    half = pb.feature_length / 2 + pb.depth / 2
    return np.any([np.abs(x - d) <= half for d in pb.stations], axis=0)


def _where(point: np.ndarray, pb: _Problem) -> str:
    x = point[0]
    for i, d in enumerate(pb.stations):
        if abs(x - d) <= pb.feature_length / 2 + pb.depth / 4:
            kind = {"pocket": "pocket", "hole": "hole", "none": "gauge"}[pb.feature]
            return f"{kind} at station {i + 1} ({d * 1e3:.1f} mm)"
    if x < pb.stations[0]:
        return "between the clamp and the first station"
    return "plain beam"


def _run(step_path: Path, pb: _Problem, level: str, refinement: float) -> _Figures:
    start = time.perf_counter()
    points, tets = _mesh_quarter(step_path, pb, refinement)
    sol = _solve(points, tets, pb)
    gauges = tuple(_gauge_strains(sol, pb))
    deflection = _free_end_deflection(sol, pb)
    vm = _vertex_von_mises(sol, pb)
    x = sol.mesh.p[0]
    margin = max(STRESS_EXCLUSION * pb.depth, STRESS_EXCLUSION_ELEMENTS * pb.global_size / refinement)
    keep = (x >= margin) & (x <= pb.cut - margin)
    i_peak = np.flatnonzero(keep)[np.argmax(vm[keep])]
    location = tuple(float(v) for v in sol.mesh.p[:, i_peak])
    peak = StressPeak(float(vm[i_peak]), location, _where(sol.mesh.p[:, i_peak], pb))
    zone = keep & _feature_zone(x, pb)
    feature_peak = float(vm[zone].max()) if zone.any() else float(vm[keep].max())
    profile = _profile(sol, pb, PROFILE_START * pb.global_size / refinement)
    run = MeshRun(level=level, refinement=refinement, global_size=pb.global_size / refinement,
                  detail_size=pb.detail_size / refinement, elements=int(tets.shape[1]),
                  vertices=int(points.shape[1]), dofs=int(3 * sol.basis.N), cg_iterations=sol.iterations,
                  seconds=time.perf_counter() - start)
    return _Figures(gauges, deflection, peak, feature_peak, profile, run)


# ----------------------------------------------------------------- the check

def _model_profile(x: np.ndarray, z: np.ndarray, pb: _Problem, props) -> np.ndarray:
    """Beam-model strain ``M z / (E I)`` at the same surface points, ``I_s`` over each feature."""
    inertia = np.where(_feature_zone_exact(x, pb), float(props.I_s), float(props.I))
    return pb.force * (pb.position - x) * z / (pb.E * inertia)


def _feature_zone_exact(x: np.ndarray, pb: _Problem) -> np.ndarray:
    return np.any([np.abs(x - d) <= pb.feature_length / 2 for d in pb.stations], axis=0)


def verify_design(design: dict, mesh: str = "normal", out_dir: Path | None = None) -> VerifyResult:
    """Check a design.json record in 3-D (see the module's description); write outputs to ``out_dir``.

    Raises DesignFileError for a record that cannot be built, InputError for an unknown mesh
    level, SolverError when meshing or solving fails.
    """
    from designer.outputs import cad
    from designer.result.designfile import rebuild, validate
    from designer.result.evaluation import evaluate

    if mesh not in MESH_LEVELS:
        raise InputError(f"mesh: {mesh!r} is not allowed; must be {describe_allowed(MESH_LEVELS)}")
    start = time.perf_counter()
    validate(design)
    spec, model_design = rebuild(design)
    ev = evaluate(model_design, spec)
    beam = cad.resolve(design)
    pb = _problem(design, beam, ev.analysis, spec, model_design.material)

    refinement = MESH_LEVELS[mesh]
    with tempfile.TemporaryDirectory(prefix="fpdesign-verify-") as tmp:
        step_path = Path(tmp) / f"{beam.file_stem}.step"
        cad.write_step(cad.build_solid(beam), step_path, beam.name)
        main = _run(step_path, pb, mesh, refinement)
        partner = _run(step_path, pb, f"{mesh} / {CONVERGENCE_COARSENING:g}", refinement / CONVERGENCE_COARSENING)

    a = ev.analysis
    gauges = tuple(GaugeCheck(d, fea, float(m), coarse)
                   for d, fea, m, coarse in zip(pb.stations, main.gauges, a.gauge_strain, partner.gauges))
    allowable = float(ev.limits[0].limit)
    limits = _recheck(ev, spec, gauges, main, a)
    x, z, eps = main.profile
    result = VerifyResult(
        name=beam.name, mesh=mesh, force=pb.force, position=pb.position, free_length=pb.free_length, cut=pb.cut,
        gauges=gauges, deflection_fea=main.deflection, deflection_model=float(a.deflection),
        deflection_coarse=partner.deflection, stress_peak=main.peak, stress_peak_coarse=partner.peak.value,
        stress_feature_fea=main.feature_peak, stress_model=float(a.max_stress),
        stress_root_model=float(a.stress_root), stress_allowable=allowable, limits=limits,
        runs=(main.run, partner.run), profile_x=tuple(float(v) for v in x),
        profile_fea=tuple(float(v) for v in eps),
        profile_model=tuple(float(v) for v in _model_profile(x, z, pb, a.props)),
        gauge_grid=(pb.grid_length, pb.grid_width), feature_length=pb.feature_length, messages=(),
        seconds=0.0)
    result = _with_messages(result, spec, pb, time.perf_counter() - start)
    if out_dir is not None:
        write_outputs(result, out_dir)
    return result


def _recheck(ev, spec, gauges, main: _Figures, a) -> tuple:
    """Every limit of the beam model again, with the 3-D figures where the check gives them."""
    from designer.model.estimator import sigma_force, sigma_position

    k = [float(a.sensitivity) * g.ratio for g in gauges]
    d = [g.station for g in gauges]
    load = spec.load
    sigma_v = float(a.sigma_v)
    fea = {
        "stress_feature": (main.feature_peak, "3-D peak von Mises stress at the features"),
        "gauge_strain": (gauges[0].fea_strain, "3-D gauge strain, station 1"),
        "min_signal_snr": (float(a.min_signal_snr) * gauges[-1].ratio, "model x 3-D strain ratio of the last gauge"),
        "deflection": (main.deflection, "3-D free-end deflection"),
        "force_error": (float(sigma_force(k, d, sigma_v)) / load.force_min, "model with 3-D sensitivities"),
        "position_error": (float(sigma_position(k, d, sigma_v, load.force_min, load.position_max)),
                           "model with 3-D sensitivities"),
        "stress_root": (float(a.stress_root), "beam model: the idealised clamp is singular in 3-D"),
    }
    out = []
    for lim in ev.limits:
        value, source = fea.get(lim.name, (float(lim.value), "geometry: as the model"))
        scale = None if lim.scale is None else float(lim.scale)
        out.append(LimitCheck(lim.name, float(lim.value), value, float(lim.limit), lim.upper, source, lim.unit,
                              scale))
    out.append(LimitCheck("stress_peak", float(a.max_stress), main.peak.value, float(ev.limits[0].limit), True,
                          f"3-D peak von Mises stress ({main.peak.where})", "Pa"))
    return tuple(out)


def _with_messages(r: VerifyResult, spec, pb: _Problem, seconds: float) -> VerifyResult:
    from dataclasses import replace

    msgs = []
    for i, g in enumerate(r.gauges):
        line = (f"gauge {i + 1} at {g.station * 1e3:.1f} mm: 3-D {g.fea_strain / MICRO:.0f} µε, beam model "
                f"{g.model_strain / MICRO:.0f} µε, ratio {g.ratio:.3f}")
        if abs(g.ratio - 1) > RATIO_NOTE:
            more = "over" if g.ratio < 1 else "under"
            line += (f": the beam model {more}-predicts this gauge's strain by {abs(1 / g.ratio - 1):.0%}; "
                     f"its sensitivity k is {g.ratio:.2f} x the model's (calibration measures the real k, "
                     f"but the predicted errors and signal scale by {1 / g.ratio:.2f})")
        msgs.append(line)
    by_name = {c.name: c for c in r.limits}
    strain = by_name.get("gauge_strain")
    if strain is not None:
        msgs.append(f"gauge strain at station 1: {strain.fea_value / MICRO:.0f} µε against the gauge's "
                    f"{strain.limit / MICRO:.0f} µε limit: {'within' if strain.satisfied else 'OVER'} the limit")
    peak = r.stress_peak
    kind = "fatigue and yield" if spec.limits.fatigue else "yield"
    msgs.append(f"peak stress {peak.value / MPA:.1f} MPa at X = {peak.location[0] * 1e3:.1f} mm ({peak.where}) "
                f"against the {kind} allowable {r.stress_allowable / MPA:.1f} MPa "
                f"(beam model's largest {r.stress_model / MPA:.1f} MPa): "
                f"{'within' if peak.value <= r.stress_allowable else 'OVER'} the allowable")
    if pb.feature == "pocket" and r.stress_change > CONVERGED_STRESS:
        msgs.append(f"the peak stress changed {r.stress_change:.0%} between the two meshes: it sits at a sharp "
                    "inside corner (pocket floor meeting its wall), where linear elasticity has no finite "
                    "peak; a floor radius bounds it, and fatigue life there needs a measured notch factor")
    elif r.stress_change > CONVERGED_STRESS:
        msgs.append(f"the peak stress changed {r.stress_change:.0%} between the two meshes: not converged; "
                    "try --mesh fine")
    msgs.append(f"free-end deflection: 3-D {r.deflection_fea * 1e3:.3f} mm, beam model "
                f"{r.deflection_model * 1e3:.3f} mm (ratio {r.deflection_fea / r.deflection_model:.3f})")
    worst = max(g.mesh_change for g in r.gauges)
    if r.converged:
        msgs.append(f"mesh convergence: the gauge strains moved at most {worst:.2%} and the deflection "
                    f"{r.deflection_change:.2%} on a mesh {CONVERGENCE_COARSENING:g} x coarser: converged")
    else:
        msgs.append(f"mesh convergence: NOT converged (gauge strains moved up to {worst:.2%}, deflection "
                    f"{r.deflection_change:.2%} on a mesh {CONVERGENCE_COARSENING:g} x coarser); "
                    "rerun with --mesh fine")
    failed = [c.name for c in r.limits if not c.satisfied]
    if failed:
        msgs.append("FAILS with the 3-D figures: " + ", ".join(failed))
    else:
        msgs.append("every limit holds with the 3-D figures")
    return replace(r, messages=tuple(msgs), seconds=seconds)


# ----------------------------------------------------------------- outputs

def plot_surface_strain(result: VerifyResult, ax=None):
    """Surface strain along the top centre line: 3-D check against the beam model."""
    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(8, 4.2), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    x = np.asarray(result.profile_x) * 1e3
    ax.plot(x, np.asarray(result.profile_model) / MICRO, color="0.35", lw=1.4, ls="--",
            label="beam model, M z / (E I) at the same points")
    ax.plot(x, np.asarray(result.profile_fea) / MICRO, color="C0", lw=1.2, label="3-D FEA, top centre line")
    gl, gw = result.gauge_grid
    for i, g in enumerate(result.gauges):
        ax.axvspan((g.station - result.feature_length / 2) * 1e3, (g.station + result.feature_length / 2) * 1e3,
                   color="C1", alpha=0.12, lw=0, label="feature" if i == 0 else None)
        ax.errorbar([g.station * 1e3], [g.fea_strain / MICRO], xerr=[[gl * 1e3 / 2], [gl * 1e3 / 2]], fmt="o",
                    color="C3", ms=5, capsize=3, label="3-D gauge (grid mean)" if i == 0 else None)
        ax.plot([g.station * 1e3], [g.model_strain / MICRO], "s", mfc="none", color="k", ms=6,
                label="beam-model gauge" if i == 0 else None)
        ax.annotate(f"{g.ratio:.2f}", (g.station * 1e3, g.fea_strain / MICRO), textcoords="offset points",
                    xytext=(6, 6), fontsize=8, color="C3")
    ax.set_xlabel("distance from the clamp face X (mm)")
    ax.set_ylabel("axial surface strain (µε)")
    ax.set_title(f"{result.name}: surface strain under {result.force:.3g} N at {result.position * 1e3:.0f} mm "
                 f"(mesh {result.mesh}; labels: 3-D / model)", fontsize=9)
    ax.set_xlim(0, result.cut * 1e3)
    reach = PLOT_HEADROOM * max(max(np.abs(result.profile_model)), max(abs(g.fea_strain) for g in result.gauges)) / MICRO
    fea_um = np.asarray(result.profile_fea) / MICRO
    ax.set_ylim(min(0.0, float(fea_um.min())) if fea_um.min() > -reach else -0.25 * reach, reach)
    if fea_um.max() > reach or fea_um.min() < -0.25 * reach:
        ax.text(0.01, 0.02, f"off scale: sharp-corner peaks from {fea_um.min():.0f} to {fea_um.max():.0f} µε",
                transform=ax.transAxes, fontsize=8, color="C0")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return fig


def report_markdown(r: VerifyResult) -> str:
    """The verify report as Markdown."""
    um = 1 / MICRO
    lines = [f"# 3-D check of {r.name}", "",
             f"Load {r.force:.4g} N at {r.position * 1e3:.1f} mm (F_max at x_max). "
             f"Quadratic tetrahedra on the quarter beam from the clamp face to X = {r.cut * 1e3:.1f} mm; "
             "the load beyond enters as its shear and moment on the cut face. "
             f"Verdict: **{'every limit holds' if r.passed else 'FAILS'}** with the 3-D figures; "
             f"mesh {'converged' if r.converged else 'NOT converged'}.", "",
             "## Gauge strains", "",
             "| station (mm) | 3-D (µε) | beam model (µε) | 3-D / model | coarser mesh (µε) | change |",
             "|---:|---:|---:|---:|---:|---:|"]
    for g in r.gauges:
        lines.append(f"| {g.station * 1e3:.1f} | {g.fea_strain * um:.1f} | {g.model_strain * um:.1f} | "
                     f"{g.ratio:.3f} | {g.coarse_strain * um:.1f} | {g.mesh_change:.2%} |")
    lines += ["", "## Deflection and stress", "",
              "| quantity | 3-D | beam model | limit |", "|---|---:|---:|---:|",
              f"| free-end deflection (mm) | {r.deflection_fea * 1e3:.3f} | {r.deflection_model * 1e3:.3f} | |",
              f"| peak stress (MPa), {r.stress_peak.where} | {r.stress_peak.value / MPA:.1f} | "
              f"{r.stress_model / MPA:.1f} | {r.stress_allowable / MPA:.1f} |",
              f"| stress at the features (MPa) | {r.stress_feature_fea / MPA:.1f} | | {r.stress_allowable / MPA:.1f} |",
              f"| root stress (MPa), beam model kept | | {r.stress_root_model / MPA:.1f} | "
              f"{r.stress_allowable / MPA:.1f} |", "",
              "## Limits re-checked", "",
              "| limit | beam model | 3-D | limit | holds | 3-D value from |", "|---|---:|---:|---:|:-:|---|"]
    for c in r.limits:
        lines.append(f"| {c.name} | {_fmt(c.model_value, c.unit)} | {_fmt(c.fea_value, c.unit)} | "
                     f"{'≤' if c.upper else '≥'} {_fmt(c.limit, c.unit)} | {'yes' if c.satisfied else '**no**'} | "
                     f"{c.source} |")
    lines += ["", "## Meshes", "",
              "| mesh | element size (mm) | detail size (mm) | elements | unknowns | CG iterations | seconds |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for m in r.runs:
        lines.append(f"| {m.level} | {m.global_size * 1e3:.2f} | {m.detail_size * 1e3:.2f} | {m.elements} | "
                     f"{m.dofs} | {m.cg_iterations} | {m.seconds:.1f} |")
    lines += ["", "## What it means", ""] + [f"- {m}" for m in r.messages]
    lines += ["", "![surface strain](surface-strain.png)", ""]
    return "\n".join(lines)


def _fmt(value: float, unit: str) -> str:
    if unit == "Pa":
        return f"{value / MPA:.1f} MPa"
    if unit == "strain":
        return f"{value / MICRO:.0f} µε"
    if unit == "m":
        return f"{value * 1e3:.3f} mm"
    if unit == "Hz":
        return f"{value:.2f} Hz"
    return f"{value:.4g}"


def write_outputs(result: VerifyResult, out_dir: Path) -> dict[str, Path]:
    """``verify.md``, ``verify.json`` and ``surface-strain.png`` in ``out_dir``, all or nothing."""
    from designer.outputs.files import atomic_write_json, atomic_write_text, staged_directory

    out_dir = Path(out_dir)
    names = {"report": "verify.md", "json": "verify.json", "plot": "surface-strain.png"}
    with staged_directory(out_dir) as scratch:
        atomic_write_text(scratch / names["report"], report_markdown(result))
        atomic_write_json(scratch / names["json"], result.as_dict())
        fig = plot_surface_strain(result)
        fig.savefig(scratch / names["plot"], dpi=130)
    return {k: out_dir / v for k, v in names.items()}
