"""Reading the 3-D solution: gauge strains, the surface strain profile, the free-end
deflection and the peak stresses.

- A gauge reads the mean of ``eps_xx`` over its grid's footprint (``grid_length x grid_width``
  centred on the station, on the gauge face: the pocket floor, or the beam's surface). Along
  each line of the grid that mean is exactly ``(u_x(end) - u_x(start)) / grid_length`` at one
  height (a round surface's facets put the ends a little apart in height: the change of u_x
  over it, by the section's rotation, is taken out); the lines are combined with
  Gauss-Legendre weights across the grid's width.
- The free-end deflection is the cut face's mean deflection ``w_c`` and slope ``w'_c`` (least
  squares of ``u_x = -z w'``) carried to the free end with Euler-Bernoulli over the plain rest:
  ``w(l) = w_c + w'_c (l - x_cut) + F a^3/(3EI) + F a^2/(2EI) (l - x_max)``, ``a = x_max - x_cut``.
- The peak stress is the von Mises stress averaged at the mesh vertices, away from the clamp
  face, whose idealised full fixity is singular at its edges. Its convergence is judged where
  it sits: the coarser mesh's largest stress within a few of its elements of the finer mesh's
  peak (``stress_near``), so that a peak which moves to another floor radius, or out of the
  region kept clear of the clamp, is not mistaken for a change.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.checks.fea.geometry_mesh import PLANE_TOLERANCE, Problem
from designer.checks.fea.solve import Solution, lame
from designer.errors import SolverError

# Stress is not taken closer to the clamp face or the cut face than this many section depths:
# the idealised clamp (every node fixed) is singular at the edges of the clamp face; nor closer
# than this many elements, over which the singular peak spreads.
STRESS_EXCLUSION = 0.5
STRESS_EXCLUSION_ELEMENTS = 2.0
# The coarser mesh's stress at the finer mesh's peak: its largest within this many of its own
# detail elements of the peak's position.
STRESS_NEAR_ELEMENTS = 2.0
# Gauss-Legendre lines across half a gauge grid's width (the other half is the mirror image).
GAUGE_LINES = 4
# Points along the surface-strain profile, from this fraction of an element off the clamp face.
PROFILE_POINTS = 400
PROFILE_START = 0.25
# A point within this many floor radii of a pocket's end and of its floor's level is on the
# radius (the fillet spans one radius each way; the rest allows for the mesh's vertices).
FLOOR_RADIUS_REACH = 1.5
# Upward surface facets: outward normal's Z component at least this.
UP_FACING = 0.2
# A biaxial design's load directions are swept in this step (degrees).
DIRECTION_STEP = 2.5
# Candidate facets searched for each surface point.
FACET_CANDIDATES = 64


@dataclass(frozen=True)
class StressPeak:
    """The largest von Mises stress of a run and where it sits."""

    value: float            # von Mises, Pa
    location: tuple         # (X, Y, Z), m
    where: str              # "pocket corner", "hole edge", ...
    element_size: float = 0.0   # mean length of the mesh edges meeting at the peak, m
    on_floor_radius: bool = False   # on a pocket's floor radius at one of its ends

    @property
    def at_feature(self) -> bool:
        """Whether the peak lies at a pocket or a hole (in a feature's zone of ``_where``)."""
        return self.where.split(" ", 1)[0] in (ZONE_WORDS["pocket"], ZONE_WORDS["hole"])


# ``_where``'s first word for a station's zone, by the design's feature.
ZONE_WORDS = {"pocket": "pocket", "hole": "hole", "none": "gauge"}


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


def _surface_points(mesh, xy: np.ndarray, below: float | None = None, required: bool = True):
    """The top surface of the mesh above each ``(x, y)``: points (3, n) and their cells.

    ``below``: only surface at or below this Z (skips walls' tops over a pocket floor).
    ``required=False``: points with no up-facing surface above them (the steep part of a floor
    radius, where the surface faces along X) are left out instead of raising SolverError.
    """
    from scipy.spatial import cKDTree

    tri, cell = _up_facets(mesh)
    tree = cKDTree(tri[:2].mean(axis=1).T)
    n = xy.shape[1]
    z_best, cell_best = np.full(n, -np.inf), np.zeros(n, dtype=int)
    todo = np.arange(n)
    k = min(FACET_CANDIDATES, tri.shape[2])
    # Where fine facets (a floor radius) crowd the nearest centroids next to coarse ones (the
    # plain surface beyond it), the facet above a point may not be among the first candidates:
    # those points are searched again with four times as many, up to every facet.
    while todo.size:
        z, facet = _highest_facet(tri, xy[:, todo], tree, k, below)
        found = np.isfinite(z)
        z_best[todo[found]], cell_best[todo[found]] = z[found], cell[facet[found]]
        todo = todo[~found]
        if k == tri.shape[2]:
            break
        k = min(4 * k, tri.shape[2])
    if todo.size and not required:
        keep = np.setdiff1d(np.arange(n), todo)
        return np.vstack([xy[:, keep], z_best[keep]]), cell_best[keep]
    if todo.size:
        missing = xy[:, todo[0]]
        raise SolverError(f"no beam surface found above X = {missing[0] * 1e3:.2f} mm, "
                          f"Y = {missing[1] * 1e3:.2f} mm; please report this design")
    return np.vstack([xy, z_best]), cell_best


def _highest_facet(tri, xy, tree, k: int, below):
    """The highest of the ``k`` facets nearest each point (x, y) that lie above it: their Z
    there (-inf where none does) and their index."""
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
    return z[rows, best], cand[rows, best]


def _axial_displacement(sol: Solution, points, cells):
    return _probe_matrix(sol.basis, points, cells) @ sol.u[0]


def gauge_strains(sol: Solution, pb: Problem) -> list[float]:
    """Mean eps_xx over each gauge grid's footprint on the gauge face."""
    t, w = np.polynomial.legendre.leggauss(GAUGE_LINES)
    ys = (t + 1) / 2 * pb.grid_width / 2
    out = []
    for d in pb.stations:
        x1, x2 = d - pb.grid_length / 2, d + pb.grid_length / 2
        xy = np.array([np.r_[np.full(GAUGE_LINES, x1), np.full(GAUGE_LINES, x2)], np.r_[ys, ys]])
        points, cells = _surface_points(sol.mesh, xy, below=pb.gauge_z + PLANE_TOLERANCE * pb.size)
        ux = _axial_displacement(sol, points, cells)
        # a round surface's facets put a line's two ends at heights a little apart, over which u_x
        # changes by the section's rotation (du_x/dz = -w'): the line is read at one height, midway
        rise = points[2, GAUGE_LINES:] - points[2, :GAUGE_LINES]
        turn = _probe_matrix(sol.basis, points, cells, derivative=2) @ sol.u[0]
        ux_rise = (turn[GAUGE_LINES:] + turn[:GAUGE_LINES]) / 2 * rise
        strain = (ux[GAUGE_LINES:] - ux[:GAUGE_LINES] - ux_rise) / pb.grid_length
        out.append(float(np.sum(w * strain) / np.sum(w)))
    return out


def surface_profile(sol: Solution, pb: Problem, refinement: float):
    """eps_xx at the surface along the top centre line (the element's own value at each point),
    from PROFILE_START of an element off either end; points over the steep part of a floor radius,
    which no up-facing surface covers, are left out."""
    start = PROFILE_START * pb.global_size / refinement
    x = np.linspace(start, pb.cut - start, PROFILE_POINTS)
    xy = np.array([x, np.full_like(x, PLANE_TOLERANCE * 1e3 * pb.size)])
    points, cells = _surface_points(sol.mesh, xy, required=False)
    return points[0], points[2], _probe_matrix(sol.basis, points, cells, derivative=0) @ sol.u[0]


def _cut_face_motion(sol: Solution, pb: Problem) -> tuple[float, float]:
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


def free_end_deflection(sol: Solution, pb: Problem) -> float:
    """Downward deflection of the free end: the cut's motion carried on by Timoshenko's beam
    theory over the plain rest (its shear ``F a / (kappa G A)`` between the cut and the load; the
    cut's slope is the section's rotation, the least squares of ``u_x = -z w'``)."""
    w_c, slope = _cut_face_motion(sol, pb)
    a = pb.position - pb.cut
    beyond = (pb.force * a ** 3 / (3 * pb.EI) + pb.force * a ** 2 / (2 * pb.EI) * (pb.free_length - pb.position)
              + pb.force * a / pb.shear_stiffness)
    return -(w_c + slope * (pb.free_length - pb.cut)) + beyond


def vertex_von_mises(sol: Solution, pb: Problem) -> np.ndarray:
    """Von Mises stress at the mesh vertices, the stress tensor averaged over the elements at each."""
    return von_mises(vertex_stress(sol, pb))


def von_mises(s: np.ndarray) -> np.ndarray:
    """Von Mises stress of stress tensors ``s`` (3, 3, n)."""
    return np.sqrt(0.5 * ((s[0, 0] - s[1, 1]) ** 2 + (s[1, 1] - s[2, 2]) ** 2 + (s[2, 2] - s[0, 0]) ** 2)
                   + 3 * (s[0, 1] ** 2 + s[1, 2] ** 2 + s[0, 2] ** 2))


def vertex_stress(sol: Solution, pb: Problem) -> np.ndarray:
    """The stress tensor (3, 3, n) at the mesh vertices, averaged over the elements at each."""
    from skfem import Basis

    corners = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    vb = Basis(sol.mesh, sol.basis.elem, quadrature=(corners, np.ones(4) / 24))
    G = np.array([vb.basis[i][0].grad for i in range(vb.Nbfun)])      # (i, a, e, q)
    ue = sol.u[:, vb.element_dofs]                                     # (c, i, e)
    grad = np.einsum("cie,iaeq->caeq", ue, G)
    strain = (grad + grad.transpose(1, 0, 2, 3)) / 2
    lam, mu = lame(pb.E, pb.poisson)
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
    return total / count


def worst_direction(along_z: Solution, along_y: Solution, pb: Problem, refinement: float) -> tuple[float, float]:
    """A biaxial design's features' peak at the worst load direction, and that direction (degrees
    off the Z axis): the two solutions of one mesh, under F along -Z and along -Y, superposed as
    ``cos(a) S_Z + sin(a) S_Y`` at every vertex of the feature zones, ``a`` from 0 to 90 degrees in
    DIRECTION_STEP; ``cos(a) S_Z - sin(a) S_Y`` is the stress at the vertex's mirror image in Y = 0
    (and in Z = 0), so that every direction of the whole section is seen."""
    x = along_z.mesh.p[0]
    zone = _kept(along_z, pb, refinement) & _stress_zone(x, pb)
    if not zone.any():
        zone = _kept(along_z, pb, refinement)
    s_z, s_y = vertex_stress(along_z, pb)[:, :, zone], vertex_stress(along_y, pb)[:, :, zone]
    best = (0.0, 0.0)
    for degrees in np.arange(0.0, 90.0 + DIRECTION_STEP / 2, DIRECTION_STEP):
        c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
        peak = max(float(von_mises(c * s_z + s * s_y).max()), float(von_mises(c * s_z - s * s_y).max()))
        if peak > best[0]:
            best = (peak, float(degrees))
    return best


def _stress_zone(x: np.ndarray, pb: Problem) -> np.ndarray:
    """Where the features' stress is sought: each reduced span widened by half a section depth."""
    margin = pb.depth / 2
    return np.any([(x >= a - margin) & (x <= b + margin) for a, b in pb.spans], axis=0)


def _where(point: np.ndarray, pb: Problem) -> str:
    """Words for where ``point`` lies: at a feature (its reduced span and a quarter depth on
    either side), between the clamp and the first station, or on the plain beam."""
    x = point[0]
    margin = pb.depth / 4
    for i, (d, (a, b)) in enumerate(zip(pb.stations, pb.spans)):
        if a - margin <= x <= b + margin:
            return f"{ZONE_WORDS[pb.feature]} at station {i + 1} ({d * 1e3:.1f} mm)"
    if x < pb.stations[0]:
        return "between the clamp and the first station"
    return "plain beam"


def _on_floor_radius(point: np.ndarray, pb: Problem) -> bool:
    """Whether ``point`` lies on a pocket's floor radius (``_floor_radius_mask``)."""
    return bool(_floor_radius_mask(np.asarray(point, float).reshape(3, 1), pb)[0])


def _floor_radius_mask(points: np.ndarray, pb: Problem) -> np.ndarray:
    """Which of ``points`` (3, n) lie on a pocket's floor radius: within FLOOR_RADIUS_REACH radii
    of a pocket's end along the beam and of its floor's level (+Z: the loaded face), where the end
    mill's corner radius joins floor and end wall. A peak elsewhere in a pocket (a slot's side
    wall, a wire channel's edge) is not the radius's."""
    r = pb.floor_radius
    if r <= 0:
        return np.zeros(points.shape[1], dtype=bool)
    x, z = points[0], points[2]
    reach = FLOOR_RADIUS_REACH * r
    near_end = np.any([np.minimum(abs(x - a), abs(x - b)) <= reach for a, b in pb.spans], axis=0)
    return near_end & (z - pb.gauge_z >= -PLANE_TOLERANCE * pb.size) & (z - pb.gauge_z <= reach)


def _element_size_at(mesh, vertex: int) -> float:
    """The mean length of the mesh edges that meet at ``vertex``."""
    others = np.unique(mesh.t[:, np.any(mesh.t == vertex, axis=0)])
    others = others[others != vertex]
    return float(np.mean(np.linalg.norm(mesh.p[:, others] - mesh.p[:, [vertex]], axis=0)))


def _kept(sol: Solution, pb: Problem, refinement: float) -> np.ndarray:
    """The vertices whose stress counts: STRESS_EXCLUSION away from the clamp and cut faces, and
    also nearer the clamp inside a feature's span (its floor radius at the clamp-side end carries
    the largest moment of the features, and a pocket may start closer to the clamp than half a
    depth) except in the elements that touch the clamp face, over which its singular peak spreads;
    and not within STRESS_EXCLUSION_ELEMENTS elements of a load groove, whose 0.25 mm root this
    mesh does not resolve (a submodel checks it: ``groove``)."""
    x = sol.mesh.p[0]
    elements = STRESS_EXCLUSION_ELEMENTS * pb.global_size / refinement
    margin = max(STRESS_EXCLUSION * pb.depth, elements)
    tol = PLANE_TOLERANCE * pb.size
    touching = np.any(x[sol.mesh.t] <= tol, axis=0)
    at_clamp = np.zeros(x.shape, dtype=bool)
    at_clamp[np.unique(sol.mesh.t[:, touching])] = True
    in_span = np.any([(x >= a - tol) & (x <= b + tol) for a, b in pb.spans], axis=0)
    kept = ((x >= margin) | (in_span & ~at_clamp)) & (x <= pb.cut - margin)
    for a, b in pb.grooves:
        kept &= (x < a - elements) | (x > b + elements)
    return kept


def stress_peaks(sol: Solution, pb: Problem, refinement: float) -> tuple[StressPeak, float, tuple, tuple]:
    """The peak von Mises stress away from the clamp and cut faces (``_kept``), the largest within
    the feature zones (the whole kept beam when no vertex lies in one), the largest within each
    station's zone (its reduced span widened by half a section depth; 0 where none is kept), and
    each station's zone's two places a pocket's peak may sit: ``(floor radius, outer face)``, the
    largest on its floor radius (``_floor_radius_mask``) and on the loaded outer face (Z = half
    the depth: a slot's rim and the top of its side walls), 0 where the zone has none."""
    vm = vertex_von_mises(sol, pb)
    x = sol.mesh.p[0]
    keep = _kept(sol, pb, refinement)
    if not keep.any():  # a beam shorter than the zones kept out at its two ends: all but the clamp face
        keep = x > PLANE_TOLERANCE * pb.size
    i_peak = np.flatnonzero(keep)[np.argmax(vm[keep])]
    location = tuple(float(v) for v in sol.mesh.p[:, i_peak])
    peak = StressPeak(float(vm[i_peak]), location, _where(sol.mesh.p[:, i_peak], pb),
                      _element_size_at(sol.mesh, i_peak), _on_floor_radius(sol.mesh.p[:, i_peak], pb))
    zone = keep & _stress_zone(x, pb)
    feature_peak = float(vm[zone].max()) if zone.any() else float(vm[keep].max())
    margin = pb.depth / 2
    floor = _floor_radius_mask(sol.mesh.p, pb)
    face = sol.mesh.p[2] >= pb.depth / 2 - PLANE_TOLERANCE * pb.size
    largest = lambda mask: float(vm[mask].max()) if mask.any() else 0.0  # noqa: E731 - a local reader
    stations, places = [], []
    for a, b in pb.spans:
        here = keep & (x >= a - margin) & (x <= b + margin)
        stations.append(largest(here))
        places.append((largest(here & floor), largest(here & face)))
    return peak, feature_peak, tuple(stations), tuple(places)


def stress_near(sol: Solution, pb: Problem, refinement: float, point) -> float:
    """The largest von Mises stress at the vertices within STRESS_NEAR_ELEMENTS detail elements
    of ``point`` (m): this mesh's value at another mesh's peak."""
    vm = vertex_von_mises(sol, pb)
    distance = np.linalg.norm(sol.mesh.p - np.asarray(point, float)[:, None], axis=0)
    near = distance <= STRESS_NEAR_ELEMENTS * pb.detail_size / refinement
    return float(vm[near].max()) if near.any() else float(vm[distance.argmin()])
