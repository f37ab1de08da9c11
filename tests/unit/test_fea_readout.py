"""The 3-D check's readout of the beam's surface (designer.checks.fea.readout)."""

import pytest


def test_surface_is_found_next_to_a_crowd_of_fine_facets():
    """A gauge or profile point just past a finely meshed region (a floor radius) lies on a coarse
    facet whose centroid is farther than the nearest fine ones: the readout must still find the
    top surface there (it once stopped with "no beam surface found"). Reference: the block's top
    is the plane z = 1 mm everywhere."""
    import numpy as np
    from scipy.spatial import cKDTree
    from skfem import MeshTet

    from designer.checks.fea import readout

    x = np.r_[np.linspace(0, 1, 41), 10.0]        # 40 fine divisions, then one 9-unit-long cell
    m = MeshTet.init_tensor(x, np.linspace(0, 1, 9), np.array([0.0, 1.0]))
    xy = np.array([[1.2, 0.5], [0.5, 0.5]])
    tri, _ = readout._up_facets(m)
    first, _ = readout._highest_facet(tri, xy[:, :1], cKDTree(tri[:2].mean(axis=1).T),
                                      readout.FACET_CANDIDATES, None)
    assert not np.isfinite(first[0])              # the nearest candidates miss it ...
    points, _ = readout._surface_points(m, xy)
    assert points[2] == pytest.approx([1.0, 1.0])  # ... the search finds the plane z = 1


def test_a_peak_is_on_the_floor_radius_only_at_a_pockets_end_and_floor():
    # a 0.2 mm corner radius at the ends of a pocket spanning 20-30 mm with its floor at Z = 4 mm:
    # the fillet occupies one radius along the beam from each end wall and one radius up from the
    # floor; a slot's side wall halfway along, or the floor's middle, is not the radius
    from types import SimpleNamespace

    import numpy as np

    from designer.checks.fea.readout import _on_floor_radius

    r = 0.2e-3
    pb = SimpleNamespace(floor_radius=r, spans=((20e-3, 30e-3),), size=10e-3, gauge_z=4e-3)
    assert _on_floor_radius(np.array([20e-3 + 0.5 * r, 1e-3, 4e-3 + 0.3 * r]), pb) is True   # JSON takes it
    assert _on_floor_radius(np.array([30e-3 - 0.2 * r, 0.0, 4e-3]), pb)
    assert not _on_floor_radius(np.array([25e-3, 2e-3, 4e-3 + 0.5e-3]), pb)     # side wall, mid-pocket
    assert not _on_floor_radius(np.array([25e-3, 0.0, 4e-3]), pb)              # the floor's middle
    assert not _on_floor_radius(np.array([20e-3, 0.0, 4e-3 + 5 * r]), pb)       # high on the end wall
    assert not _on_floor_radius(np.array([20e-3, 0.0, 4e-3]), SimpleNamespace(**{**vars(pb), "floor_radius": 0.0}))
