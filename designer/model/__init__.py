"""The sensor model (docs/model.md), written once for numbers and for casadi expressions.

``sections`` (geometry and section properties) -> ``beam`` (deflection, EI(s), frequency) and
``electronics`` (volts per strain, noise) -> ``estimator`` (least squares, 1-sigma errors) ->
``analysis`` (every predicted quantity of a design) -> ``limits`` and ``objective`` (what a
design must meet, how designs rank). Every function takes its math through ``ops``.
"""

from designer.model.adjust import Adjustment
from designer.model.analysis import Analysis, MaterialParams, analyse, grid_arc_factor
from designer.model.beam import (CLAMPED_FREE_ROOT, LARGE_DEFLECTION_RATIO, channel_deflection, is_large_deflection,
                                 natural_frequency, rigidity_segments, tip_deflection)
from designer.model.electronics import BRIDGE_FACTORS, output_noise, volts_per_strain
from designer.model.limits import (ACTIVE_TOLERANCE, DUTY_LIMITS, SIZE_LIMITS, TARGET_LIMITS, Limit, limits,
                                   minimum_room, section_limits, smallest_feature_length, worst_normalised)
from designer.model.objective import (FEASIBILITY_TOLERANCE, OBJECTIVES, SECONDARY, TIE_TOLERANCE, error_ratio, error_terms,
                                      objective, rank, ranks_before, secondary, ties)
from designer.model.ops import NUMERIC, Ops, casadi_ops
from designer.model.sections import (Geometry, SectionProperties, default_channel, feature_length, features_apart,
                                     flat_half_angle, section_properties, segment_area, segment_inertia_across,
                                     segment_inertia_normal, shoulder_ratio, stations_before_load, unbuildable)

__all__ = [name for name in dir() if not name.startswith("_")]
