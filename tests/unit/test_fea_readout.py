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
