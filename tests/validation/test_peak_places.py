"""Where the study's slots peak: the floor radius or the outer face (``checks.peak_places``,
docs/model.md §7).

Reference: ``materials/corrections_study.csv``'s place columns, each the 3-D check's peak on a
slot's floor radius and on the loaded outer face (``fea.readout.stress_peaks``), and fresh 3-D
runs of the study's cases."""

import math
from pathlib import Path

import pytest

from designer.checks import fits, peak_places, study
from designer.model import corrections

STUDY = Path(corrections.__file__).resolve().parents[2] / "materials" / "corrections_study.csv"

pytestmark = pytest.mark.slow


def _slots():
    return [r for r in fits.with_nearness(study.read_csv(STUDY)) if r["family"] == "rectangle-pocket"]


def test_every_slot_row_of_the_table_is_found_again_among_the_study_cases():
    """The place columns are read on the table's rows by finding each row's case again
    (``peak_places.pending``): every slot row must be found, or its columns could not be read."""
    rows = study.read_csv(STUDY)
    stripped = [{k: v for k, v in r.items() if k not in peak_places.COLUMNS} for r in rows]
    found = peak_places.pending(stripped, ["rectangle-pocket"])
    slots = [i for i, r in enumerate(rows) if r["family"] == "rectangle-pocket"]
    assert sorted(i for i, _ in found) == slots
    # and each is its own case: no two rows found as one
    assert len({id(case) for _, case in found}) == len(slots)
