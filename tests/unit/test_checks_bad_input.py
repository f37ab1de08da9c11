"""The elastica and the 3-D check refuse input they cannot use, with a message."""

from __future__ import annotations

import pytest

from designer.checks import elastica
from designer.checks import fea
from designer.errors import DesignFileError, InputError
from shared_inputs import fea_bar as bar


def test_bad_segments_and_positions_are_refused():
    with pytest.raises(ValueError, match="must cover"):
        elastica.solve_elastica(1.0, 0.5, 1.0, [(0.0, 0.4, 1.0), (0.5, 1.0, 1.0)])
    with pytest.raises(ValueError, match="must lie on the beam"):
        elastica.solve_elastica(1.0, 1.5, 1.0, 1.0)


def test_library_refuses_an_unknown_mesh_level():
    with pytest.raises(InputError, match=r"mesh: 'medium' is not allowed; must be one of \[coarse, normal, fine\]"):
        fea.verify_design(bar(310, (60, 300)), mesh="medium")
    with pytest.raises(DesignFileError, match="design"):
        fea.verify_design({"spec": {}}, mesh="coarse")
