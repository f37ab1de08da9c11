"""The 3-D check's mesh screening and solve check (designer.checks.fea.geometry_mesh, .solve)."""

import numpy as np
import pytest


def test_a_tetrahedron_of_no_volume_is_flat_and_a_sliver_is_not():
    """Reference: a tetrahedron's volume is |det(edges)|/6; a regular one on edge L has L^3/(6 sqrt 2).
    A fourth corner in the plane of the other three (the fill of a surface triangle whose corners
    are collinear) has none. A sliver of 1e-5 of the regular volume, as the worst tetrahedra of the
    meshes the 3-D check solves today, is kept."""
    from designer.checks.fea.geometry_mesh import FLAT_TETRAHEDRON, _flat_tetrahedra

    regular = np.array([[1.0, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]]).T     # edge 2 sqrt 2
    tets = np.arange(4).reshape(4, 1)
    assert not _flat_tetrahedra(regular, tets)
    flat = regular.copy()
    flat[:, 3] = (regular[:, 0] + regular[:, 1] + regular[:, 2]) / 3                # in the face 0-1-2
    assert _flat_tetrahedra(flat, tets)
    # lift the fourth corner off the face until the volume is q times the regular one's
    edge = 2 * np.sqrt(2)
    normal = np.cross(regular[:, 1] - regular[:, 0], regular[:, 2] - regular[:, 0])
    area = np.linalg.norm(normal) / 2
    for q, is_flat in ((1e-5, False), (1e-3 * FLAT_TETRAHEDRON, True)):
        height = 3 * q * edge ** 3 / (6 * np.sqrt(2)) / area
        sliver = flat.copy()
        sliver[:, 3] += height * normal / np.linalg.norm(normal)
        assert _flat_tetrahedra(sliver, tets) is is_flat
    # a mesh is flat when any one of its tetrahedra is
    both = np.hstack([regular, flat])
    assert _flat_tetrahedra(both, np.array([[0, 4], [1, 5], [2, 6], [3, 7]]))


def _block_problem():
    """A 20 x 4 x 4 mm steel bar's quarter (the symmetry planes Y = 0 and Z = 0), clamped at X = 0,
    cut at X = 20 mm, loaded 10 N at 40 mm: a coarse tensor mesh."""
    from skfem import MeshTet

    from designer.checks.fea.geometry_mesh import Problem

    mm = 1e-3
    m = MeshTet.init_tensor(np.linspace(0, 20 * mm, 6), np.linspace(0, 2 * mm, 3), np.linspace(0, 2 * mm, 3))
    pb = Problem(E=200e9, poisson=0.3, force=10.0, position=40 * mm, free_length=40 * mm, cut=20 * mm,
                 EI=200e9 * (4 * mm) ** 4 / 12, depth=4 * mm, size=4 * mm, stations=(10 * mm,), feature="none",
                 feature_length=0.0, spans=(), gauge_z=2 * mm, grid_length=1 * mm, grid_width=1 * mm,
                 global_size=2 * mm, detail_size=2 * mm, detail_reach=0.0, bore=0.0, radius=0.0, floor_radius=0.0,
                 plate=False)
    return m.p, m.t, pb


def test_a_solution_is_checked_against_its_residual_not_the_solvers_word(monkeypatch):
    """Conjugate gradients that report success with a wrong answer (here u = 0, whose relative
    residual ||f - K u|| / ||f|| is exactly 1) are refused; the true solve passes the check."""
    import scipy.sparse.linalg as spla

    from designer.checks.fea import solve as fea_solve
    from designer.errors import SolverError

    points, tets, pb = _block_problem()
    good = fea_solve.solve(points, tets, pb)
    assert good.iterations > 0 and np.abs(good.u).max() > 0
    monkeypatch.setattr(spla, "cg", lambda K, f, **kw: (np.zeros_like(f), 0))
    with pytest.raises(SolverError, match="relative residual of 1.0e\\+00"):
        fea_solve.solve(points, tets, pb)


def test_the_slivers_unknowns_are_solved_exactly_and_save_iterations(monkeypatch):
    """A slab 0.02 mm thick across the bar (tetrahedra of about 1 % of a regular one's volume, as
    gmsh leaves where a floor radius's faces meet the floor) slows the Jacobi-smoothed cycle; with
    its unknowns solved exactly the conjugate gradients need fewer iterations. Reference for the
    answer: the same bar without the slab (the slab adds nodes, not geometry), whose displacements
    agree with the slab mesh's within the discretisation (0.1 % of the largest), with or without
    the exact solve (1e-6: both solve one system to CG_TOLERANCE)."""
    from skfem import MeshTet

    from designer.checks.fea import solve as fea_solve

    mm = 1e-3
    _, _, pb = _block_problem()
    x = np.linspace(0, 20 * mm, 21)
    plain = MeshTet.init_tensor(x, np.linspace(0, 2 * mm, 3), np.linspace(0, 2 * mm, 3))
    slab = MeshTet.init_tensor(np.sort(np.r_[x, 8.02 * mm]), np.linspace(0, 2 * mm, 3), np.linspace(0, 2 * mm, 3))
    # the slab's tetrahedra, and only they, are slivers: their nodes lie within it
    from skfem import ElementTetP2
    from skfem.assembly import Dofs

    element_dofs = Dofs(slab, ElementTetP2()).element_dofs
    fixed = np.zeros((element_dofs.max() + 1, 3), dtype=bool)
    nodes = fea_solve.sliver_dofs(slab.p, slab.t, element_dofs, fixed)[::3] // 3
    xyz = np.hstack([slab.p, slab.p[:, slab.edges].mean(axis=1)])
    assert len(nodes) and np.all((xyz[0, nodes] > 8 * mm - 1e-9) & (xyz[0, nodes] < 8.02 * mm + 1e-9))
    reference = fea_solve.solve(plain.p, plain.t, pb)
    with_exact = fea_solve.solve(slab.p, slab.t, pb)
    monkeypatch.setattr(fea_solve, "SLIVER_QUALITY", 0.0)
    without = fea_solve.solve(slab.p, slab.t, pb)
    # measured: 24 iterations with the exact solve (as many as the plain bar's), 92 without
    assert with_exact.iterations < without.iterations / 2
    scale = np.abs(without.u).max()
    assert np.abs(with_exact.u - without.u).max() < 1e-6 * scale
    # the tip of the bar (the corner at the cut, on the load's face) in both meshes
    tip = lambda sol: sol.u[2, np.argmin(np.sum((sol.mesh.p - np.array([[20 * mm], [0], [2 * mm]])) ** 2, axis=0))]
    assert tip(with_exact) == pytest.approx(tip(reference), rel=1e-3)


def test_rigid_body_motions_strain_nothing():
    """Reference: a rigid motion (translation, or small rotation u = theta x r) has zero strain,
    so the stiffness of an unheld body maps each of the six modes to zero force (the near null
    space that the coarse level's multigrid is built on)."""
    from skfem import ElementTetP2, MeshTet
    from skfem.assembly import Dofs

    from designer.checks.fea import solve as fea_solve

    points, tets, pb = _block_problem()
    mesh = MeshTet(points, tets)
    dofs = Dofs(mesh, ElementTetP2())
    free = np.zeros((dofs.N, 3), dtype=bool)
    K = fea_solve.stiffness(mesh, dofs.element_dofs, dofs.N, pb.E, pb.poisson, free)
    nodes = np.hstack([mesh.p, mesh.p[:, mesh.edges].mean(axis=1)])
    modes = fea_solve.rigid_body_modes(nodes)
    assert np.linalg.matrix_rank(modes) == 6
    # a bending mode of the same size does strain the bar: the scale the zeros are measured on
    bending = np.zeros(3 * dofs.N)
    bending[2::3] = nodes[0] ** 2
    scale = np.abs(K @ (bending / np.abs(bending).max())).max()
    for k in range(6):
        mode = modes[:, k] / np.abs(modes[:, k]).max()
        assert np.abs(K @ mode).max() < 1e-12 * scale


def test_a_coarse_level_past_the_exact_limit_is_one_multigrid_cycle(monkeypatch):
    """Past EXACT_COARSE unknowns the linear coarse level is one V-cycle of smoothed-aggregation
    multigrid, not a sparse LU, whose fill outgrows the stiffness on a large bar (the bench suite's
    035-kilonewton: 563 M nonzeros, 9.5 GB). No LU of the coarse level is made: the only systems
    factorised are the multigrid's own coarsest, of at most AMG_COARSEST unknowns. Reference: the
    same system with the exact coarse solve; both are solved to CG_TOLERANCE, so they agree to
    1e-6 of the largest displacement, and the cycle costs few more iterations (measured: 45
    against 44 on a 61 x 7 x 7 block, 29 and 29 on this one, 54 against 48 on 035-kilonewton's 1.9 M
    unknowns)."""
    import scipy.sparse.linalg as spla
    from skfem import MeshTet

    from designer.checks.fea import solve as fea_solve

    _, _, pb = _block_problem()
    mm = 1e-3
    block = MeshTet.init_tensor(np.linspace(0, 20 * mm, 31), np.linspace(0, 2 * mm, 5), np.linspace(0, 2 * mm, 5))
    exact = fea_solve.solve(block.p, block.t, pb)
    factorised = []
    splu = spla.splu

    def spy(A, *args, **kwargs):
        factorised.append(A.shape[0])
        return splu(A, *args, **kwargs)

    monkeypatch.setattr(spla, "splu", spy)
    monkeypatch.setattr(fea_solve, "EXACT_COARSE", 1000)     # the block's coarse level: 1 830 unknowns
    cycled = fea_solve.solve(block.p, block.t, pb)
    assert max(factorised, default=0) <= fea_solve.AMG_COARSEST
    scale = np.abs(exact.u).max()
    assert np.abs(cycled.u - exact.u).max() < 1e-6 * scale
    assert cycled.iterations <= 1.3 * exact.iterations
