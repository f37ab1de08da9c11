"""The linear-elasticity solve of the 3-D check: quadratic tetrahedra, vectorised assembly,
conjugate gradients with a two-level (quadratic / linear) preconditioner.

The clamp face is held fixed, the symmetry planes carry their (anti)symmetry conditions, and
the load beyond the cut enters at the cut face as its resultant (Saint-Venant): a uniform shear
``tau = -F/A`` and a bending stress ``sigma = M z / I`` with ``M = F (x_max - x_cut)``; ``A``
and ``I`` are integrated over the meshed cut face. scipy, scikit-fem and pyamg are imported
inside the functions.

Memory: the stiffness is assembled ``ASSEMBLY_CHUNK`` elements at a time (the quadratic
shape-function gradients written out from the barycentric ones) straight into one matrix of
3 x 3 blocks, handed on as CSR; the held components are eliminated in place (row and column
zeroed, diagonal kept), so no free-block copy of the matrix is made. The preconditioner's
linear level is factorised only while that is small (EXACT_COARSE); past it one multigrid cycle
keeps its memory in proportion to the mesh. A thin wide plate is solved directly instead: its
linear coarse level locks in bending (hundreds of iterations), while its nearly
two-dimensional sparsity makes the factorisation small.

Every solution, iterative or direct, is checked against the system: its true relative residual
must be at most RESIDUAL_LIMIT, whatever the solver reports.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.checks.fea.geometry_mesh import PLANE_TOLERANCE, Problem, tetrahedron_shapes
from designer.errors import SolverError

# Conjugate gradients: relative residual, iteration cap; damping of the Jacobi smoother as a
# fraction of 2 / lambda_max(D^-1 K) (1.5 / lambda_max: inside the convergent range). From 1e-10
# to 1e-8 the gripper finger's displacements moved by 3e-12 of their largest, for 20 % fewer
# iterations.
CG_TOLERANCE = 1e-8
CG_MAX_ITERATIONS = 3000
SMOOTHER_DAMPING = 1.5
# Tetrahedra below this share of a regular one's volume (on their root-mean-square edge) are
# slivers: their unknowns are solved exactly within the cycle, as the Jacobi smoother barely
# reaches them. The weigh-bar's convergence mesh (15 558 tetrahedra, 118 below 0.01 where a
# floor radius's faces meet the floor and walls): 440 iterations without, 56 with 0.15, 43 with
# 0.3; its main mesh 72, 42 and 36 (the exact solve's setup grows with the share).
SLIVER_QUALITY = 0.15
# ... at most this share of the tetrahedra, the worst (the exact solve is of a small patch; a
# mesh of stretched elements would otherwise make it the whole problem)
MAX_SLIVER_SHARE = 0.05
# Every solution is checked against the system itself, whatever the solver says: its true relative
# residual ||f - K u|| / ||f|| must be at most RESIDUAL_LIMIT. Conjugate gradients stop at
# CG_TOLERANCE on their recursively updated residual (the true one measured 7e-9 to 1e-8 on the
# examples); the sparse LU of a thin plate leaves more before its refinement (Prototype A: 1.2e-7,
# the bench suite's 23.5 x 1.71 mm plate 1.0e-6). A solver that stops short, or reports success on a wrong answer
# (whose residual is of order one), fails it.
RESIDUAL_LIMIT = 1e-6
# The direct solve refines its answer until its residual is below REFINED, at most this many steps.
REFINEMENT_STEPS = 3
REFINED = 1e-9
# Elements assembled at a time: their blocks take 7.2 kB each.
ASSEMBLY_CHUNK = 4096
# The linear coarse level is factorised exactly up to this many unknowns (every example's
# meshes: 4 500 to 36 000). Above it an exact LU's fill outgrows the stiffness itself (the bench
# suite's 035-kilonewton, a 789 mm bar of Ø87 mm: 227 950 coarse unknowns, 563 M nonzeros in
# L + U; its solve took 11 minutes at a 10.9 GB peak), and one V-cycle of smoothed-aggregation
# algebraic multigrid (pyamg, the six rigid-body modes as its near null space) stands in for it,
# in memory linear in the unknowns: there 71 s (4.7 s of it the set-up), 54 iterations instead
# of 48, the same displacements to 3e-10 of the largest, and the stiffness's assembly (3.7 GB)
# the solve's peak.
EXACT_COARSE = 50_000
# The multigrid's own coarsest level, solved exactly, has at most this many unknowns.
AMG_COARSEST = 500

# The 4-point Gauss rule on a tetrahedron (exact for the quadratic integrand of P2 stiffness):
# barycentric coordinates of the points, one row per point.
_GAUSS_A, _GAUSS_B = 0.5854101966249685, 0.1381966011250105
_GAUSS_LAMBDA = np.full((4, 4), _GAUSS_B) + np.eye(4) * (_GAUSS_A - _GAUSS_B)
# scikit-fem's ElementTetP2: vertices 0-3, then the edge dofs on these vertex pairs.
_EDGES = np.array([[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]])


@dataclass(frozen=True)
class Solution:
    """The displacement field of one solve on one mesh."""

    mesh: object
    basis: object            # scalar P2 basis
    u: np.ndarray            # (3, N) displacement at the P2 nodes
    iterations: int          # CG iterations (0: solved directly)


def lame(E: float, nu: float) -> tuple[float, float]:
    """Lamé's ``(lambda, mu)`` of an isotropic material."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _p2_gradients(points: np.ndarray, tets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gradients (E, 4 points, 10 functions, 3) of the P2 shape functions at the Gauss points of
    the tetrahedra ``tets`` (4, E), and the elements' volumes: vertex ``i`` has
    ``(4 lambda_i - 1) grad lambda_i``, edge ``ij`` has ``4 (lambda_i grad lambda_j + lambda_j grad lambda_i)``."""
    x = points[:, tets]                                       # (3, 4, E)
    J = (x[:, 1:] - x[:, :1]).transpose(2, 0, 1)              # (E, 3, 3): edge vectors as columns
    inv = np.linalg.inv(J)                                    # rows: grad lambda_1..3
    g = np.empty((tets.shape[1], 4, 3))
    g[:, 1:] = inv
    g[:, 0] = -inv.sum(axis=1)
    G = np.empty((tets.shape[1], 4, 10, 3))
    i, j = _EDGES.T
    for q, lam in enumerate(_GAUSS_LAMBDA):
        G[:, q, :4] = (4 * lam - 1)[None, :, None] * g
        G[:, q, 4:] = 4 * (lam[i][None, :, None] * g[:, j] + lam[j][None, :, None] * g[:, i])
    return G, np.abs(np.linalg.det(J)) / 6


def _element_blocks(points, tets, lam: float, mu: float) -> np.ndarray:
    """Element stiffness blocks (E, 10, 10, 3, 3): node ``i``, node ``j``, components ``a``, ``b``.

    With ``M[ia, jb] = sum_q w_q d_a phi_i d_b phi_j`` (one batched matrix product),
    ``K[ia, jb] = lambda M[ia, jb] + mu M[ib, ja] + mu delta_ab sum_c M[ic, jc]``."""
    G, volume = _p2_gradients(points, tets)
    n = G.shape[0]
    Gw = (G * (volume / 4)[:, None, None, None]).reshape(n, 4, 30)
    M = np.matmul(Gw.transpose(0, 2, 1), G.reshape(n, 4, 30)).reshape(n, 10, 3, 10, 3)
    K = lam * M
    K += mu * M.transpose(0, 1, 4, 3, 2)
    trace = mu * np.einsum("eicjc->eij", M)
    for a in range(3):
        K[:, :, a, :, a] += trace
    return np.ascontiguousarray(K.transpose(0, 1, 3, 2, 4))


def stiffness(mesh, element_dofs: np.ndarray, n_nodes: int, E: float, nu: float, fixed: np.ndarray):
    """The P2 elasticity stiffness (CSR, assembled as 3 x 3 blocks) on ``n_nodes`` nodes, dof
    ``3 n + component``; the ``fixed`` (n_nodes, 3) components eliminated symmetrically (their rows
    and columns zeroed, their diagonal kept), so that the load's zeros there hold them."""
    import scipy.sparse as sp

    lam, mu = lame(E, nu)
    n_el = element_dofs.shape[1]
    # the block pattern: sorted (row, column) node pairs, and where each element pair lands
    keys = element_dofs.T.astype(np.int64)
    keys = (keys[:, :, None] * n_nodes + keys[:, None, :]).ravel()            # element-major
    pairs, where = np.unique(keys, return_inverse=True)
    del keys
    where = where.astype(np.int32 if len(pairs) < 2 ** 31 else np.int64)
    rows = (pairs // n_nodes).astype(np.int32)
    cols = (pairs % n_nodes).astype(np.int32)
    del pairs
    n_blocks = len(cols)
    indptr = np.zeros(n_nodes + 1, dtype=np.int32)
    np.cumsum(np.bincount(rows, minlength=n_nodes), out=indptr[1:])
    data = np.zeros((n_blocks, 9))
    for start in range(0, n_el, ASSEMBLY_CHUNK):
        stop = min(n_el, start + ASSEMBLY_CHUNK)
        blocks = _element_blocks(mesh.p, mesh.t[:, start:stop], lam, mu).reshape(-1, 9)
        at = where[100 * start:100 * stop]
        order = np.argsort(at, kind="stable")
        at = at[order]
        first = np.flatnonzero(np.r_[True, at[1:] != at[:-1]])
        data[at[first]] += np.add.reduceat(blocks[order], first, axis=0)
    del where
    data = data.reshape(n_blocks, 3, 3)
    diagonal = np.flatnonzero(rows == cols)
    keep = data[diagonal, [[0], [1], [2]], [[0], [1], [2]]].T.copy()     # (n_nodes, 3)
    data *= ~fixed[rows][:, :, None]
    data *= ~fixed[cols][:, None, :]
    for a in range(3):
        data[diagonal, a, a] = np.where(fixed[rows[diagonal], a], keep[:, a], data[diagonal, a, a])
    # scipy's CSR product is about three times faster than its 3 x 3 BSR one
    return sp.bsr_matrix((data, cols, indptr), shape=(3 * n_nodes, 3 * n_nodes)).tocsr()


def _prolongation(mesh, n_nodes: int):
    """Linear (P1 on the vertices) to quadratic interpolation, scalar: vertex dofs first, then
    one dof per edge (scikit-fem's numbering)."""
    import scipy.sparse as sp

    nv, ne = mesh.p.shape[1], mesh.edges.shape[1]
    rows = np.concatenate([np.arange(nv), nv + np.arange(ne), nv + np.arange(ne)])
    cols = np.concatenate([np.arange(nv), mesh.edges[0], mesh.edges[1]])
    vals = np.concatenate([np.ones(nv), 0.5 * np.ones(2 * ne)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_nodes, nv))


def _constrained(xyz: np.ndarray, pb: Problem) -> np.ndarray:
    """(3, n) mask of fixed components at points ``xyz``: clamp, symmetry and antisymmetry (a load
    along -Z bends the quarter symmetrically about Y = 0 and antisymmetrically about Z = 0; one
    along -Y, ``pb.lateral``, the other way round)."""
    tol = PLANE_TOLERANCE * pb.size
    clamp = np.abs(xyz[0]) < tol
    y0 = np.abs(xyz[1]) < tol
    z0 = np.abs(xyz[2]) < tol
    if pb.lateral:
        return np.array([clamp | y0, clamp, clamp | y0 | z0])
    return np.array([clamp | z0, clamp | y0 | z0, clamp])


def _load(mesh, pb: Problem, n_nodes: int) -> np.ndarray:
    """The cut face's tractions as nodal forces (3 n_nodes,)."""
    from skfem import ElementTetP2, FacetBasis, Functional, LinearForm, asm

    tol = PLANE_TOLERANCE * pb.size
    cut_facets = mesh.facets_satisfying(lambda x: np.abs(x[0] - pb.cut) < tol, boundaries_only=True)
    if len(cut_facets) == 0:
        raise SolverError("the mesh has no face at the cut; please report this design")
    fb = FacetBasis(mesh, ElementTetP2(), facets=cut_facets)
    across = 1 if pb.lateral else 2                     # the load's axis: Y or Z
    area_q = asm(Functional(lambda w: 1.0 + 0.0 * w.x[0]), fb)
    inertia_q = asm(Functional(lambda w: w.x[across] ** 2), fb)
    area, inertia = 4 * area_q, 4 * inertia_q           # the whole section
    moment = pb.force * (pb.position - pb.cut)
    f = np.zeros(3 * n_nodes)
    f[0::3] = asm(LinearForm(lambda v, w: moment * w.x[across] / inertia * v), fb)
    f[across::3] = asm(LinearForm(lambda v, w: -pb.force / area * v), fb)
    return f


def _direct(K, f: np.ndarray, free: np.ndarray) -> np.ndarray:
    """Sparse LU of the free block (symmetric mode, minimum degree ordering), with up to
    REFINEMENT_STEPS steps of iterative refinement (u += LU^-1 (f - K u)): the factors of a thin
    plate leave a residual near RESIDUAL_LIMIT (the bench suite's 23.5 x 1.71 mm 2024 plate:
    1.0e-6), which one step takes to round-off."""
    import scipy.sparse.linalg as spla

    Kf = K[free][:, free].tocsc()
    try:
        lu = spla.splu(Kf, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    except RuntimeError as exc:
        raise SolverError(f"the finite-element system is singular ({exc}); the beam is not held") from exc
    rhs = f[free]
    x = lu.solve(rhs)
    for _ in range(REFINEMENT_STEPS):
        r = rhs - Kf @ x
        if np.linalg.norm(r) <= REFINED * np.linalg.norm(rhs):
            break
        x += lu.solve(r)
    u = np.zeros_like(f)
    u[free] = x
    return u


def sliver_dofs(points: np.ndarray, tets: np.ndarray, element_dofs: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """The free dofs of the tetrahedra whose volume is below SLIVER_QUALITY of a regular one's on
    their root-mean-square edge, at most the worst MAX_SLIVER_SHARE of the tetrahedra (sorted;
    empty when the mesh has none)."""
    squared, volume = tetrahedron_shapes(points, tets)
    rms = np.sqrt(np.mean(squared, axis=0))
    quality = volume / (rms ** 3 / (6 * np.sqrt(2)))
    worst = np.argsort(quality)[:int(MAX_SLIVER_SHARE * len(quality))]
    slivers = worst[quality[worst] < SLIVER_QUALITY]
    nodes = np.unique(element_dofs[:, slivers])
    dofs = (3 * nodes[:, None] + np.arange(3)).ravel()
    return dofs[~fixed.ravel()[dofs]]


def two_level_cg(K, f: np.ndarray, mesh, n_nodes: int, fixed: np.ndarray, free_v: np.ndarray,
                 slivers: np.ndarray, tolerance: float = CG_TOLERANCE) -> tuple[np.ndarray, int]:
    """Conjugate gradients, preconditioned by damped Jacobi on P2 around a solve of the Galerkin
    P1 problem on the mesh's vertices (exact, or one multigrid cycle: ``_coarse_solver``); the
    dofs of ``slivers`` (``sliver_dofs``) are also solved exactly, next to the Jacobi steps (a
    symmetric multiplicative cycle). ``fixed``: the held components (n_nodes, 3); ``free_v``: the
    vertices' free components, flattened."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    P = sp.kron(_prolongation(mesh, n_nodes), sp.eye(3), format="csr")
    P = (sp.diags((~fixed.ravel()).astype(float)) @ P).tocsc()[:, free_v].tocsr()
    coarse_solve = _coarse_solver(P.T @ (K @ P), mesh.p, free_v)
    dinv = 1.0 / K.diagonal()
    root = np.sqrt(dinv)
    scaled = spla.LinearOperator(K.shape, lambda v: root * (K @ (root * v)), dtype=float)
    lam_max = spla.eigsh(scaled, k=1, which="LA", tol=1e-2, return_eigenvectors=False)[0]
    omega_dinv = SMOOTHER_DAMPING / lam_max * dinv
    if len(slivers):
        K_columns = K[:, slivers].tocsr()
        patch = spla.splu(K_columns[slivers].tocsc(), permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})

        def exactly(x, residual):
            step = patch.solve(residual[slivers])
            x[slivers] += step
            residual -= K_columns @ step
    else:
        def exactly(x, residual):
            pass

    def cycle(r):
        x = omega_dinv * r
        residual = r - K @ x
        exactly(x, residual)
        x += P @ coarse_solve(P.T @ residual)
        residual = r - K @ x
        exactly(x, residual)
        return x + omega_dinv * residual

    count = [0]

    def tick(_):
        count[0] += 1

    x, info = spla.cg(K, f, M=spla.LinearOperator(K.shape, cycle, dtype=float), rtol=tolerance,
                      maxiter=CG_MAX_ITERATIONS, callback=tick)
    if info != 0:
        raise SolverError(f"the finite-element solve did not converge in {CG_MAX_ITERATIONS} iterations")
    return x, count[0]


def rigid_body_modes(points: np.ndarray) -> np.ndarray:
    """The six rigid-body motions (3 n, 6) at ``points`` (3, n), dof ``3 i + component``: three
    translations and three rotations, about X, Y and Z."""
    x, y, z = points
    modes = np.zeros((3 * points.shape[1], 6))
    for a in range(3):
        modes[a::3, a] = 1.0
    modes[1::3, 3], modes[2::3, 3] = -z, y
    modes[0::3, 4], modes[2::3, 4] = z, -x
    modes[0::3, 5], modes[1::3, 5] = -y, x
    return modes


def _coarse_solver(coarse, vertices: np.ndarray, free: np.ndarray):
    """The coarse level's solve ``r -> A^-1 r`` of the linear system ``coarse`` on the free
    components ``free`` of the mesh's ``vertices``: a sparse LU up to EXACT_COARSE unknowns, else
    one symmetric V-cycle of smoothed-aggregation multigrid (symmetric Gauss-Seidel smoothing, so
    the cycle stays a symmetric positive definite preconditioner for conjugate gradients)."""
    import scipy.sparse.linalg as spla

    if coarse.shape[0] <= EXACT_COARSE:
        try:
            lu = spla.splu(coarse.tocsc(), permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
        except RuntimeError as exc:
            raise SolverError(f"the coarse finite-element system is singular ({exc}); the beam is not held") from exc
        return lu.solve
    import pyamg

    hierarchy = pyamg.smoothed_aggregation_solver(coarse.tocsr(), B=rigid_body_modes(vertices)[free],
                                                  symmetry="symmetric", max_coarse=AMG_COARSEST,
                                                  coarse_solver="splu")
    cycle = hierarchy.aspreconditioner(cycle="V")
    return lambda r: cycle @ r


def solve(points, tets, pb: Problem) -> Solution:
    from skfem import ElementTetP2, MeshTet
    from skfem.assembly import Dofs

    mesh = MeshTet(points, tets)
    element = ElementTetP2()
    dofs = Dofs(mesh, element)
    n_nodes = dofs.N
    nodes = np.hstack([mesh.p, mesh.p[:, mesh.edges].mean(axis=1)])      # vertex dofs, then edge dofs
    fixed = _constrained(nodes, pb).T                                     # (n_nodes, 3)
    del nodes
    f = _load(mesh, pb, n_nodes)
    f[fixed.ravel()] = 0.0
    K = stiffness(mesh, dofs.element_dofs, n_nodes, pb.E, pb.poisson, fixed)
    if pb.plate:
        u, iterations = _direct(K, f, ~fixed.ravel()), 0
    else:
        slivers = sliver_dofs(mesh.p, mesh.t, dofs.element_dofs, fixed)
        u, iterations = two_level_cg(K, f, mesh, n_nodes, fixed, ~_constrained(mesh.p, pb).T.ravel(), slivers)
    residual = np.linalg.norm(f - K @ u) / np.linalg.norm(f)
    if not residual <= RESIDUAL_LIMIT:
        raise SolverError(f"the finite-element solve left a relative residual of {residual:.1e} (more than "
                          f"{RESIDUAL_LIMIT:.0e}); please report this design")
    del K
    u[fixed.ravel()] = 0.0
    return solution(mesh, u.reshape(-1, 3).T, iterations)


def solution(mesh, u: np.ndarray, iterations: int) -> Solution:
    """The Solution of displacements ``u`` (3, N) on a scikit-fem tetrahedral ``mesh`` (also one
    rebuilt from another process's arrays)."""
    from skfem import Basis, ElementTetP2

    basis = Basis(mesh, ElementTetP2(), intorder=1)      # the readout needs its dofs and mapping only
    return Solution(mesh, basis, u, iterations)
