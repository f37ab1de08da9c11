"""The shipped feature corrections against the project's own 3-D study (docs/model.md §7).

Reference: ``materials/corrections_study.csv``, made by ``python -m designer.checks.study``
(fpdesign verify's 3-D elasticity on a parametric grid), and fresh 3-D runs of a few of its
points."""

import math
from pathlib import Path

import pytest

from designer.checks import study
from designer.model import corrections

STUDY = Path(corrections.__file__).resolve().parents[2] / "materials" / "corrections_study.csv"


def _rows():
    return study.read_csv(STUDY)


def test_every_shipped_fit_reproduces_the_study_and_its_held_out_points():
    table = corrections.load()
    assert table.fits, "no corrections shipped"
    rows = _rows()
    for fam, quantities in table.fits.items():
        mine = [r for r in rows if r["family"] == fam]
        for quantity, fit in quantities.items():
            column = study.TARGETS[quantity]
            for r in mine:
                if math.isfinite(r.get(column, math.nan)):
                    # within the acceptance the fit was shipped under (leave-one-out, 2 %)
                    assert fit(r) == pytest.approx(r[column], abs=study.FIT_ACCEPT[quantity]), (fam, quantity, r)
            assert fit.loo_max <= study.FIT_ACCEPT[quantity]


def test_refitting_the_study_gives_the_shipped_table():
    table, _ = study.fit_table(_rows())
    shipped = corrections.load()
    assert table.fits.keys() == shipped.fits.keys()
    for fam, quantities in shipped.fits.items():
        for quantity, fit in quantities.items():
            again = table.fits[fam][quantity]
            assert again.exponents == fit.exponents
            assert again.coefficients == pytest.approx(fit.coefficients, rel=1e-9, abs=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("index", [13, 29])
def test_fresh_3d_runs_reproduce_points_of_the_table(index):
    # two hole cases of the study (one near Prototype B, the largest hole), run again with the
    # 3-D check on the study's own mesh
    cases = [c for c in study.cases() if c.family == "rectangle-hole"]
    rows = [r for r in _rows() if r["family"] == "rectangle-hole"]
    case, row = cases[index], rows[index]
    fresh = study.run_case(case, mesh=row["mesh"])
    assert fresh.parameters["hole_ratio"] == pytest.approx(row["hole_ratio"], rel=1e-5)
    assert fresh.strain_far == pytest.approx(row["strain_far"], rel=1e-4)
    assert fresh.strain_near == pytest.approx(row["strain_near"], rel=1e-4)
    assert fresh.deflection_ratio == pytest.approx(row["deflection_ratio"], rel=1e-4)
