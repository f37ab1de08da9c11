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


def test_a_slot_peaks_on_its_floor_radius_or_at_its_rim():
    """docs/model.md §7: of the study's 243 slots inside the K_t fit's domain, 185 peak on the floor
    radius, 52 at the rim on the loaded outer face, 6 elsewhere in the slot's zone (a side wall
    below the top face, the wire channel's edge), each of those within 6 % of the larger place's
    peak (the far features alike). The rim carries at least the net section's top-fibre stress
    ``M (h/2) / I_s`` (the nominal the columns are over: beam theory), and the slots that peak there
    are the deep ones (median depth 0.27 h against 0.15 h). Reference: the study's 3-D rows."""
    import statistics

    from designer.checks import fit_forms

    box = fit_forms.FIT_DOMAINS["rectangle-pocket"]["stress"]
    slots = [r for r in _slots() if fits._in_domain(r, box)]
    assert len(slots) == 243 and all(math.isfinite(r.get(c, math.nan)) for r in slots for c in peak_places.COLUMNS)
    floor = [r for r in slots if r["stress_floor"] >= 0.999 * r["stress_ratio"]]
    face = [r for r in slots if r not in floor and r["stress_face"] >= 0.999 * r["stress_ratio"]]
    assert len(floor) >= 0.7 * len(slots) and len(face) >= 0.15 * len(slots)
    assert len(slots) - len(floor) - len(face) <= 0.05 * len(slots)
    for zone, places in (("stress_ratio", ("stress_floor", "stress_face")), ("stress_far", ("stress_floor_far", "stress_face_far"))):
        assert max(r[zone] / max(r[p] for p in places) for r in slots) <= 1.06
    assert min(r["stress_face"] for r in slots) >= 1.0 and min(r["stress_face_far"] for r in slots) >= 1.0
    assert statistics.median(r["depth_ratio"] for r in face) >= 1.5 * statistics.median(r["depth_ratio"] for r in slots)
