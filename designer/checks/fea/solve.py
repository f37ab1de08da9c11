"""The linear-elasticity solve of the 3-D check: quadratic tetrahedra, vectorised assembly,
conjugate gradients with a two-level (quadratic / linear) preconditioner.

The clamp face is held fixed, the symmetry planes carry their (anti)symmetry conditions, and
the load beyond the cut enters at the cut face as its resultant (Saint-Venant): a uniform shear
``tau = -F/A`` and a bending stress ``sigma = M z / I`` with ``M = F (x_max - x_cut)``; ``A``
and ``I`` are integrated over the meshed cut face. scipy and scikit-fem are imported inside the
functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.checks.fea.geometry_mesh import PLANE_TOLERANCE, Problem
from designer.errors import SolverError

# Conjugate gradients: relative residual, iteration cap; damping of the Jacobi smoother as a
# fraction of 2 / lambda_max(D^-1 K) (1.5 / lambda_max: inside the convergent range).
CG_TOLERANCE = 1e-10
CG_MAX_ITERATIONS = 3000
SMOOTHER_DAMPING = 1.5


@dataclass(frozen=True)
class Solution:
    """The displacement field of one solve on one mesh."""

    mesh: object
    basis: object            # scalar P2 basis
    u: np.ndarray            # (3, N) displacement at the P2 nodes
    iterations: int


def lame(E: float, nu: float) -> tuple[float, float]:
    """Lamé's ``(lambda, mu)`` of an isotropic material."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _stiffness(basis, E: float, nu: float):
    """The P2 elasticity stiffness, vector dofs interleaved (3 n + component)."""
    import scipy.sparse as sp

    lam, mu = lame(E, nu)
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


def _constrained(xyz: np.ndarray, pb: Problem) -> np.ndarray:
    """(3, n) mask of fixed components at points ``xyz``: clamp, symmetry and antisymmetry."""
    tol = PLANE_TOLERANCE * pb.size
    clamp = np.abs(xyz[0]) < tol
    y0 = np.abs(xyz[1]) < tol
    z0 = np.abs(xyz[2]) < tol
    return np.array([clamp | z0, clamp | y0 | z0, clamp])


def solve(points, tets, pb: Problem) -> Solution:
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
    return Solution(mesh, basis, u.reshape(-1, 3).T, count[0])
