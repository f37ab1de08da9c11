"""A biaxial sensor's side features and its gauge strain (docs/model.md §9)."""

from __future__ import annotations

from dataclasses import replace

from designer.model.ops import NUMERIC, ops_for
from designer.model.sections import Geometry, section_properties

# A biaxial sensor's side features (docs/model.md §9): the reduced section takes off their whole
# second moment, and in 3-D only part of that step appears where the feature is short against the
# section (benchmarks/biaxial_strain.md: the 3-D gauge strain of biaxial bars over their single-
# axis twins', normal mesh, 25 stations on round bars and a tube, 10 on squares). The factor on
# the gauge strain is ``1 - a q exp(-k l_f / size)``, ``q`` the flat's depth over the diameter on
# round bars and tubes, on squares the step itself, ``I_s (one axis) / I_s (two axes) - 1``; the
# third figure is the law's largest left-out error (one design left out at a time), kept as room.
BIAXIAL_STRAIN = {"round": (1.76, 5.13, 0.0057), "tube": (1.76, 5.13, 0.0057), "rectangle": (1.77, 2.36, 0.0065)}


def side_features(g: Geometry) -> bool:
    """Whether ``g`` has features on its side faces too: a biaxial sensor with pockets or flats."""
    return g.axes == 2 and g.feature == "pocket"


def biaxial_strain_factor(g: Geometry, ops=None):
    """The gauge-strain factor of a biaxial sensor's side features (BIAXIAL_STRAIN); 1 for a
    single-axis sensor or one without pockets or flats."""
    if not side_features(g):
        return 1.0
    a, k, _ = BIAXIAL_STRAIN[g.section]
    if g.section == "rectangle":
        both = section_properties(g, ops or NUMERIC)
        step = section_properties(replace(g, axes=1), ops or NUMERIC).I_s / both.I_s - 1
    else:
        step = g.depth / g.size
    ops = ops or ops_for(step, g.feature_length, g.size)
    return 1 - a * step * ops.exp(-k * g.feature_length / g.size)


def biaxial_strain_room(g: Geometry) -> float:
    """How far the 3-D gauge strain may lie off ``biaxial_strain_factor``: its largest left-out
    error; 0 where it is 1."""
    return BIAXIAL_STRAIN[g.section][2] if side_features(g) else 0.0
