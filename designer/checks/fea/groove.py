"""The load grooves' K_t in 3-D (docs/model.md §4): a submodel of one groove in pure bending.

A straight segment of the bar, HALF_LENGTH section sizes long either side of one groove, built in
gmsh's OpenCASCADE kernel with the groove the model assumes and the CAD cuts (0.5 mm wide, ``t``
deep, its walls ending in a semicircular root of radius ``r = 0.25 mm``: a ring on a round bar or
tube; on a rectangle one such groove across each face, the top and side grooves crossing at the
section's edges). Only the eighth ``x, y, z >= 0`` is meshed: the groove's mid-plane ``x = 0``
and the bending plane ``y = 0`` are planes of symmetry, the neutral plane ``z = 0`` one of
antisymmetry (``u_x = u_y = 0``), one vertex on it holds ``u_z``. The end face ``x = L`` carries
the pure bending traction ``sigma = M z / I`` (``I`` that of the meshed face, so that the
resultant is ``M``); for a prismatic bar that is the exact solution, so the groove's own
disturbance is all the segment holds. Quadratic tetrahedra, assembled and solved with the 3-D
check's stiffness and two-level conjugate gradients (``solve``); elements of ``r / n`` within
FINE_REACH r of the groove's faces, growing from there at GRADING per unit distance.

The 3-D ``K_t``: the largest axial stress at a vertex of the groove's faces (the stress tensor
averaged over the elements at the vertex) over the net section's ``M c / I`` as
``grooves.groove_stress`` defines it. benchmarks/groove_kt_check.py converges it (root meshes to
r/24, within 0.2 %) against Roark's chart, which the model's ``grooves.FACTOR_3D`` is fitted to;
``verify`` solves it at the groove nearest the clamp of the design it checks (``groove_kt``).
Lengths in mm, stresses in MPa, moments in N mm.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from designer.errors import SolverError
from designer.model import grooves

ROOT_RADIUS = grooves.ROOT_RADIUS * 1e3    # mm
E_MPA, POISSON = 71.7e3, 0.33   # K_t does not depend on the modulus; verify gives the design's Poisson's ratio
MOMENT = 1000.0             # N mm
HALF_LENGTH = 2.5           # section sizes either side of the groove
FAR_ELEMENTS = 8.0          # elements across the section's smaller size, far from the groove
FINE_REACH = 0.4            # the root's element size holds within this share of r of the groove's faces ...
GRADING = 0.3               # ... and grows from there by this much per unit distance
CG_TOLERANCE = 1e-9
# Root elements r / n of verify's mesh levels: at r/6 every groove of the converged study reads
# within 1.2 % of its converged K_t (benchmarks/groove_kt_check.md), at r/4 within 1.9 %
ROOT_DIVISIONS = {"coarse": 4.0, "normal": 6.0, "fine": 9.0}


@dataclass(frozen=True)
class GrooveKt:
    """The 3-D ``K_t`` of a groove (averaged stress at the root's vertices over the net section's
    nominal), the largest single element's value over the same nominal, where the peak is (mm,
    the groove's mid-plane x = 0), the mesh's root divisions and size, and the seconds taken."""

    kt: float
    kt_element: float
    at: tuple
    divisions: float
    tetrahedra: int
    seconds: float


def _profile(occ, plane, surface: float, t: float, profile: str) -> int:
    """A groove's cutting profile, a plane face over ``x`` in ``[-r, r]``: ``plane(x, s)`` is the
    point at depth coordinate ``s`` (the bar's surface at ``s = surface``). A U: walls down to
    ``surface - t + r``, then the semicircle; a square slot: walls down to a flat floor at ``t``."""
    r = ROOT_RADIUS
    top = surface + 1.0
    if profile == "u":
        sc = surface - t + r
        pts = [occ.addPoint(*plane(x, s)) for x, s in ((-r, sc), (-r, top), (r, top), (r, sc), (0.0, sc - r))]
        centre = occ.addPoint(*plane(0.0, sc))
        curves = [occ.addLine(pts[0], pts[1]), occ.addLine(pts[1], pts[2]), occ.addLine(pts[2], pts[3]),
                  occ.addCircleArc(pts[3], centre, pts[4]), occ.addCircleArc(pts[4], centre, pts[0])]
    else:
        floor = surface - t
        pts = [occ.addPoint(*plane(x, s)) for x, s in ((-r, floor), (-r, top), (r, top), (r, floor))]
        curves = [occ.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
    return occ.addPlaneSurface([occ.addCurveLoop(curves)])


def segment(kind: str, dims: dict, t: float, profile, n: float) -> tuple:
    """gmsh's eighth of the segment, meshed with elements ``r / n`` at the groove's faces: points
    (3, N) and tetrahedra (4, E) in mm, the vertices on the groove's faces (for the plain segment,
    on its top surface within the groove's width) and the segment's half length."""
    import gmsh

    r, h = ROOT_RADIUS, ROOT_RADIUS / n
    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 2)
        gmsh.model.add("groove")
        occ = gmsh.model.occ
        cutters = []
        if kind == "rectangle":
            W, H = dims["width"], dims["height"]
            L, top = HALF_LENGTH * max(W, H), H / 2
            bar = [(3, occ.addBox(0, 0, 0, L, W / 2, H / 2))]
            if profile:
                face = _profile(occ, lambda x, s: (x, -1.0, s), H / 2, t, profile)
                cutters += occ.extrude([(2, face)], 0, W / 2 + 2, 0)
                face = _profile(occ, lambda x, s: (x, s, -1.0), W / 2, t, profile)
                cutters += occ.extrude([(2, face)], 0, 0, H / 2 + 2)
            far = min(W, H) / FAR_ELEMENTS
        else:
            D = dims["diameter"]
            R = D / 2
            L, top = HALF_LENGTH * D, R
            cylinder, box = occ.addCylinder(0, 0, 0, L, 0, 0, R), occ.addBox(0, 0, 0, L, R + 1, R + 1)
            bar, _ = occ.intersect([(3, cylinder)], [(3, box)])
            if kind == "tube":
                cutters.append((3, occ.addCylinder(-1, 0, 0, L + 2, 0, 0, R - dims["wall"])))
            if profile:
                face = _profile(occ, lambda x, s: (x, 0.0, s), R, t, profile)
                cutters += occ.revolve([(2, face)], 0, 0, 0, 1, 0, 0, 2 * math.pi)
            far = (D if kind == "round" else min(D, 4 * dims["wall"])) / FAR_ELEMENTS
        cutters = [c for c in cutters if c[0] == 3]
        if cutters:
            bar, _ = occ.cut(bar, cutters)
        occ.synchronize()
        if len(gmsh.model.getEntities(3)) != 1:
            raise SolverError("the groove submodel's segment is not one solid")
        # the groove's faces: all within x <= r, off the mid-plane
        groove = [tag for _, tag in gmsh.model.getEntities(2)
                  if 1e-6 < gmsh.model.getBoundingBox(2, tag)[3] <= r + 1e-4]
        fields = gmsh.model.mesh.field
        distance = fields.add("Distance")
        if groove:
            reach = 2 * math.pi * (max(dims.get("width", 0), dims.get("height", 0)) or dims["diameter"]) / 4
            fields.setNumbers(distance, "SurfacesList", groove)
            fields.setNumber(distance, "Sampling", int(min(1500, max(100, 3 * reach / h))))
            root = distance
        else:
            # the plain segment: the same sizes about where the groove's root would be (free curves
            # at x = 0, the root's centre line, r below the sizes' reach)
            if kind == "rectangle":
                zc, yc = H / 2 - t + r, W / 2 - t + r
                a, b, c = occ.addPoint(0, 0, zc), occ.addPoint(0, yc, zc), occ.addPoint(0, yc, 0)
                curves = [occ.addLine(a, b), occ.addLine(b, c)]
            else:
                rc = R - t + r
                o, a, b = occ.addPoint(0, 0, 0), occ.addPoint(0, 0, rc), occ.addPoint(0, rc, 0)
                curves = [occ.addCircleArc(a, o, b)]
            occ.synchronize()
            fields.setNumbers(distance, "CurvesList", curves)
            fields.setNumber(distance, "Sampling", 2000)
            root = fields.add("MathEval")
            fields.setString(root, "F", f"F{distance} - {r}")
        threshold = fields.add("Threshold")
        fields.setNumber(threshold, "InField", root)
        fields.setNumber(threshold, "SizeMin", h)
        fields.setNumber(threshold, "SizeMax", far)
        fields.setNumber(threshold, "DistMin", FINE_REACH * r)
        fields.setNumber(threshold, "DistMax", FINE_REACH * r + (far - h) / GRADING)
        fields.setAsBackgroundMesh(threshold)
        for name, value in (("Mesh.MeshSizeFromPoints", 0), ("Mesh.MeshSizeFromCurvature", 0),
                            ("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeMax", far),
                            ("Mesh.Algorithm3D", 10), ("Mesh.Optimize", 1)):
            gmsh.option.setNumber(name, value)
        gmsh.model.mesh.generate(3)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
        index[tags.astype(np.int64)] = np.arange(len(tags))
        points = coords.reshape(-1, 3).T.copy()
        types, _, nodes = gmsh.model.mesh.getElements(3)
        if list(types) != [4]:
            raise SolverError(f"the groove submodel: gmsh made elements of types {list(types)}, not only "
                              "linear tetrahedra")
        tets = index[nodes[0].astype(np.int64)].reshape(-1, 4).T
        on_groove = np.zeros(points.shape[1], dtype=bool)
        for tag in groove:
            on_groove[index[gmsh.model.mesh.getNodes(2, tag, includeBoundary=True)[0].astype(np.int64)]] = True
    finally:
        gmsh.finalize()
    used = np.unique(tets)            # drop the free curves' nodes
    remap = np.full(points.shape[1], -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points, tets, on_groove = points[:, used], remap[tets], on_groove[used]
    if not groove:
        on_groove = (points[0] <= r + 1e-9) & (points[2] >= top - 1e-6)
    return points, tets, np.flatnonzero(on_groove), L


def solve_bending(points: np.ndarray, tets: np.ndarray, L: float, poisson: float = POISSON) -> tuple:
    """The eighth in pure bending: ``u_x = 0`` on ``x = 0``, ``u_y = 0`` on ``y = 0``,
    ``u_x = u_y = 0`` on ``z = 0``, one vertex's ``u_z`` held, ``sigma = M z / I`` on ``x = L``.
    Returns the mesh, its P2 dofs, the displacements (3, N) and the CG iterations."""
    from skfem import ElementTetP2, FacetBasis, Functional, LinearForm, MeshTet, asm
    from skfem.assembly import Dofs

    from designer.checks.fea.solve import sliver_dofs, stiffness, two_level_cg

    mesh = MeshTet(np.ascontiguousarray(points), np.ascontiguousarray(tets))
    dofs = Dofs(mesh, ElementTetP2())
    n_nodes = dofs.N
    tol = 1e-7 * L

    def held(xyz):
        x0, y0, z0 = (np.abs(xyz[i]) < tol for i in range(3))
        return np.array([x0 | z0, y0 | z0, np.zeros_like(x0)]).T

    on_neutral = np.flatnonzero(np.abs(mesh.p[2]) < tol)
    anchor = on_neutral[np.argmax(mesh.p[0, on_neutral])]
    fixed = held(np.hstack([mesh.p, mesh.p[:, mesh.edges].mean(axis=1)]))      # vertex dofs, then edge dofs
    fixed[anchor, 2] = True
    fixed_v = held(mesh.p)
    fixed_v[anchor, 2] = True
    end = FacetBasis(mesh, ElementTetP2(), facets=mesh.facets_satisfying(lambda x: np.abs(x[0] - L) < tol,
                                                                          boundaries_only=True))
    inertia = 4 * asm(Functional(lambda w: w.x[2] ** 2), end)
    f = np.zeros(3 * n_nodes)
    f[0::3] = asm(LinearForm(lambda v, w: MOMENT * w.x[2] / inertia * v), end)
    f[fixed.ravel()] = 0.0
    K = stiffness(mesh, dofs.element_dofs, n_nodes, E_MPA, poisson, fixed)
    slivers = sliver_dofs(mesh.p, mesh.t, dofs.element_dofs, fixed)
    u, iterations = two_level_cg(K, f, mesh, n_nodes, fixed, ~fixed_v.ravel(), slivers, CG_TOLERANCE)
    residual = np.linalg.norm(f - K @ u) / np.linalg.norm(f)
    if not residual < 10 * CG_TOLERANCE:    # the solution against the system itself, not the solver's word
        raise SolverError(f"the groove submodel's solve left a relative residual of {residual:.1e}")
    return mesh, dofs, u.reshape(-1, 3).T, iterations


def corner_stress(mesh, dofs, u: np.ndarray, elements: np.ndarray, poisson: float = POISSON) -> np.ndarray:
    """``sigma_xx`` (E, 4) at the four corners of ``elements``, each element's own value."""
    from designer.checks.fea.solve import _EDGES, lame

    x = mesh.p[:, mesh.t[:, elements]]
    inv = np.linalg.inv((x[:, 1:] - x[:, :1]).transpose(2, 0, 1))
    g = np.empty((len(elements), 4, 3))                        # barycentric gradients
    g[:, 1:] = inv
    g[:, 0] = -inv.sum(axis=1)
    G = np.zeros((len(elements), 4, 10, 3))                    # element, corner, shape function, d/dx
    for k in range(4):
        for i in range(4):                                     # vertex i: (4 lambda_i - 1) grad lambda_i
            G[:, k, i] = (3.0 if i == k else -1.0) * g[:, i]
        for e, (i, j) in enumerate(_EDGES):                    # edge ij: 4 (lambda_i grad lambda_j + ...)
            if k in (i, j):
                G[:, k, 4 + e] = 4 * g[:, j if k == i else i]
    grad = np.einsum("aie,ekic->ekac", u[:, dofs.element_dofs[:, elements]], G)
    lam, mu = lame(E_MPA, poisson)
    return 2 * mu * grad[:, :, 0, 0] + lam * np.einsum("ekaa->ek", grad)


def root_peak(mesh, dofs, u: np.ndarray, nodes: np.ndarray, poisson: float = POISSON) -> dict:
    """The largest ``sigma_xx`` over ``nodes``: averaged over the elements at each vertex, and the
    largest single element's; where each is; and (for the rectangle's middle of the top face) the
    averaged largest on ``y = 0``."""
    touched = np.zeros(mesh.p.shape[1], dtype=bool)
    touched[nodes] = True
    elements = np.flatnonzero(touched[mesh.t].any(axis=0))
    s = corner_stress(mesh, dofs, u, elements, poisson)
    corners = mesh.t[:, elements].T
    n = mesh.p.shape[1]
    total, count, largest = np.zeros(n), np.zeros(n), np.full(n, -np.inf)
    for k in range(4):
        np.add.at(total, corners[:, k], s[:, k])
        np.add.at(count, corners[:, k], 1.0)
        np.maximum.at(largest, corners[:, k], s[:, k])
    averaged = total[nodes] / count[nodes]
    i, j = int(np.argmax(averaged)), int(np.argmax(largest[nodes]))
    mid = np.abs(mesh.p[1, nodes]) < 1e-9
    return {"averaged": float(averaged[i]), "raw": float(largest[nodes][j]), "at": mesh.p[:, nodes[i]],
            "raw_at": mesh.p[:, nodes[j]], "mid": float(np.max(averaged[mid])) if mid.any() else float("nan")}


def reference(kind: str, dims: dict, t: float, grooved: bool) -> tuple:
    """``(nominal stress (MPa) under MOMENT, Roark's K_t)``: ``grooves.groove_stress``'s net-section
    ``M c / I`` and ``grooves.stress_concentration`` (without FACTOR_3D), in SI and back; for the
    plain segment the gross section's ``M c / I``."""
    m = 1e-3
    g = SimpleNamespace(section=kind, width=dims.get("width", 0.0) * m, height=dims.get("height", 0.0) * m,
                        diameter=dims.get("diameter", 0.0) * m, wall=dims.get("wall", 0.0) * m)
    g.size = g.height if kind == "rectangle" else g.diameter
    kt = float(grooves.stress_concentration(kind, t * m, g.size))
    if not grooved:
        if kind == "rectangle":
            return MOMENT * (dims["height"] / 2) / (dims["width"] * dims["height"] ** 3 / 12), kt
        bore = dims["diameter"] - 2 * dims["wall"] if kind == "tube" else 0.0
        return MOMENT * (dims["diameter"] / 2) / (math.pi * (dims["diameter"] ** 4 - bore ** 4) / 64), kt
    # the groove 1 m from the load: M = F_max x 1 m = MOMENT N mm
    spec = SimpleNamespace(cad=SimpleNamespace(load_grooves=True, groove_positions=[0.0], groove_depth=t * m),
                           load=SimpleNamespace(position_max=1.0, force_max=MOMENT * m))
    nominal, _ = grooves.groove_stress(g, spec)
    return float(nominal) / 1e6, kt


def groove_kt(kind: str, dims: dict, t: float, n: float, profile: str | None = "u",
              poisson: float = POISSON) -> GrooveKt:
    """The 3-D ``K_t`` of a groove ``t`` mm deep on a section ``kind`` of ``dims`` (mm: ``width``
    and ``height``, or ``diameter`` and a tube's ``wall``), its root meshed at ``r / n``, of a
    material of ``poisson``; of the plain segment (``profile`` None) the gross section's
    ``M c / I`` ratio, 1 by beam theory."""
    t0 = time.perf_counter()
    nominal, _ = reference(kind, dims, t, profile is not None)
    points, tets, nodes, L = segment(kind, dims, t, profile, n)
    mesh, dofs, u, _ = solve_bending(points, tets, L, poisson)
    out = root_peak(mesh, dofs, u, nodes, poisson)
    return GrooveKt(kt=out["averaged"] / nominal, kt_element=out["raw"] / nominal,
                    at=tuple(float(v) for v in out["at"]), divisions=n, tetrahedra=int(tets.shape[1]),
                    seconds=time.perf_counter() - t0)
