"""A design's beam model adjusted to its own 3-D check (docs/model.md §11).

An ``Adjustment`` holds multiplicative 3-D/model factors measured at one design: the gauge strain
of each station, the free-end deflection and the peak stress at the feature. ``model.analyse``
applies it: the strain factors scale the sensitivities ``k_i`` and the gauge strains (and so the
force and position errors and the signal-to-noise ratio), the deflection factor the deflection
and the stress factor the stress concentration ``K_t``. The factors are plain floats, so inside
the optimiser's graph they are constants.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from designer.errors import brief


@dataclass(frozen=True)
class Adjustment:
    """3-D/model factors of one design; 1 leaves a figure as the beam model has it."""

    gauge_strain: tuple          # per station, in station order
    deflection: float = 1.0
    stress_concentration: float = 1.0

    def __post_init__(self):
        strain = tuple(float(f) for f in self.gauge_strain)
        object.__setattr__(self, "gauge_strain", strain)
        object.__setattr__(self, "deflection", float(self.deflection))
        object.__setattr__(self, "stress_concentration", float(self.stress_concentration))
        for name, value in [("gauge_strain", f) for f in strain] + [("deflection", self.deflection),
                                                                   ("stress_concentration",
                                                                    self.stress_concentration)]:
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"adjustment.{name}: {value!r} must be a positive number (a 3-D/model ratio)")
        if not strain:
            raise ValueError("adjustment.gauge_strain: must hold one factor per station")

    @classmethod
    def identity(cls, stations: int) -> "Adjustment":
        return cls((1.0,) * stations)

    def times(self, other: "Adjustment") -> "Adjustment":
        """Both adjustments applied in turn: every factor the product of the two."""
        if len(other.gauge_strain) != len(self.gauge_strain):
            raise ValueError(f"adjustment.gauge_strain: {len(other.gauge_strain)} factors for "
                             f"{len(self.gauge_strain)} stations")
        return Adjustment(tuple(a * b for a, b in zip(self.gauge_strain, other.gauge_strain)),
                          self.deflection * other.deflection,
                          self.stress_concentration * other.stress_concentration)

    def as_dict(self) -> dict:
        """As design.json holds it (``design.adjustment``)."""
        return {"gauge_strain": list(self.gauge_strain), "deflection": self.deflection,
                "stress_concentration": self.stress_concentration}

    @classmethod
    def from_dict(cls, data) -> "Adjustment":
        """The inverse of ``as_dict``; ValueError names the key that is missing or impossible."""
        if not isinstance(data, dict):
            raise ValueError(f"adjustment: {brief(data)} must be an object with gauge_strain, deflection and "
                             "stress_concentration")
        strain = data.get("gauge_strain")
        if not isinstance(strain, list) or not all(_is_number(f) for f in strain):
            raise ValueError(f"adjustment.gauge_strain: {brief(strain)} must be a list of numbers, one per station")
        for key in ("deflection", "stress_concentration"):
            if not _is_number(data.get(key, 1.0)):
                raise ValueError(f"adjustment.{key}: {data.get(key)!r} must be a number")
        return cls(tuple(strain), data.get("deflection", 1.0), data.get("stress_concentration", 1.0))


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)
