"""The spec's ``tolerances`` block: how far a built beam's section and feature may be from their
nominal sizes, as a general-tolerance class of ISO 2768-1 or as explicit deviations
(docs/spec.md §2.12, docs/model.md §14)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.errors import SpecError, describe_allowed
from designer.spec import units
from designer.spec.keys import mapping

#: ISO 2768-1:1989, Table 1: permissible deviations (±, mm) for linear dimensions without an
#: individual tolerance, by tolerance class, for nominal sizes up to each upper end in
#: ISO_2768_RANGES (0.5-3, over 3-6, 6-30, 30-120, 120-400, 400-1000, 1000-2000 mm). Sizes under
#: 0.5 mm, for which the standard asks for a deviation beside the size, take the first range's;
#: class v gives none up to 3 mm, and takes its 3-6 mm value there.
ISO_2768_RANGES = (3.0, 6.0, 30.0, 120.0, 400.0, 1000.0, 2000.0)
ISO_2768_CLASSES = {
    "f": (0.05, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5),   # fine
    "m": (0.1, 0.1, 0.2, 0.3, 0.5, 0.8, 1.2),      # medium
    "c": (0.2, 0.3, 0.5, 0.8, 1.2, 2.0, 3.0),      # coarse
    "v": (0.5, 0.5, 1.0, 1.5, 2.5, 4.0, 6.0),      # very coarse
}
CLASSES = ("none", *ISO_2768_CLASSES)
DEFAULT_CLASS = "m"
PARTS = ("section", "feature")


@dataclass(frozen=True)
class Tolerances:
    """``grade``: an ISO 2768-1 class (f, m, c, v) or none; ``section`` and ``feature``: an explicit
    deviation (±, m) for the section's sizes and for the pocket's depth or the hole's diameter,
    used instead of the class's."""

    grade: str = DEFAULT_CLASS
    section: float | None = None
    feature: float | None = None

    @property
    def active(self) -> bool:
        return self.grade != "none" or bool(self.section) or bool(self.feature)

    def deviation(self, size, part: str):
        """The ± deviation (m) of a nominal ``size`` (m; a number or an array) of ``part``."""
        given = self.section if part == "section" else self.feature
        if given is not None:
            return np.zeros_like(np.asarray(size, dtype=float)) + given
        if self.grade == "none":
            return np.zeros_like(np.asarray(size, dtype=float))
        table = np.array(ISO_2768_CLASSES[self.grade]) * 1e-3
        mm = np.asarray(size, dtype=float) * 1e3
        return table[np.minimum(np.searchsorted(ISO_2768_RANGES, mm, side="left"), len(table) - 1)]

    def smaller_range_end(self, size: float, part: str) -> float | None:
        """The upper end (m) of the class's next smaller size range below ``size`` (m) of ``part``,
        where its deviation is smaller; None when ``part``'s deviation is given, without a class, or
        in the smallest range."""
        if self.grade == "none" or (self.section if part == "section" else self.feature) is not None:
            return None
        k = int(np.searchsorted(ISO_2768_RANGES, size * 1e3, side="left"))
        return ISO_2768_RANGES[k - 1] * 1e-3 if k > 0 else None

    def label(self) -> str:
        """As the report and the drawing say it, e.g. ``ISO 2768-m`` or ``±0.02 mm (section)``."""
        parts = [f"ISO 2768-{self.grade}"] if self.grade != "none" else []
        parts += [f"±{v * 1e3:g} mm ({name})" for name, v in (("section", self.section), ("feature", self.feature))
                  if v is not None]
        return ", ".join(parts) or "none"

    def as_dict(self) -> dict:
        return {"class": self.grade, "section": self.section, "feature": self.feature}


def parse_tolerances(raw) -> Tolerances:
    """``tolerances: {class: m, section: 0.02 mm, feature: 0.05 mm}``; every key optional."""
    raw = mapping(raw, "tolerances", ("class", *PARTS))
    grade = raw.get("class", DEFAULT_CLASS)
    if grade is None or str(grade) not in CLASSES:
        raise SpecError(f"tolerances.class: {grade!r} is not allowed; must be {describe_allowed(CLASSES)} "
                        "(ISO 2768-1 fine, medium, coarse, very coarse)")
    given = {}
    for part in PARTS:
        if raw.get(part) is None:
            continue
        value = units.parse(raw[part], "length", f"tolerances.{part}")
        if not 0 <= value <= 0.005:
            raise SpecError(f"tolerances.{part}: {raw[part]!r} is outside the allowed range; must be a deviation "
                            "(±) from 0 to 5 mm")
        given[part] = value
    return Tolerances(str(grade), given.get("section"), given.get("feature"))
