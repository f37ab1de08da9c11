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
        if fam == "plain":
            continue  # the clamp: test_the_clamp_fit_reproduces_the_series
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
            if isinstance(fit, corrections.ClampFit):
                _same_clamp(again, fit)
                continue
            assert again.exponents == fit.exponents
            assert again.coefficients == pytest.approx(fit.coefficients, rel=1e-9, abs=1e-12)


def _same_clamp(a, b) -> bool:
    for k in corrections.CLAMP_COEFFICIENTS:
        assert getattr(a, k) == pytest.approx(getattr(b, k), rel=1e-6), k
    return True


def test_the_clamp_fit_reproduces_the_series():
    # every plain-bar point of the study inside the fit's domain within 1 % (the 3-D acceptance
    # on gauge strain is 2 %), and the points left out of the fit within 2 %
    from designer.checks import clamp_study

    fit = corrections.clamp_fit(corrections.load())
    inside = [(w, u, c) for w, u, c in clamp_study.points(_rows()) if u >= fit.domain["station_width_ratio"][0]]
    assert len(inside) >= 25
    for w, u, c in inside:
        assert float(fit(w, u)) == pytest.approx(c, abs=0.01), (w, u)
    assert fit.loo_max <= 0.02
    # the clamp leaves round bars (w = 1) and points far from it alone, and its restraint of a
    # wide plate tends to the plane-strain limit nu^2 = 0.11 (nu = 0.33): never more
    assert float(fit(1.0, 0.3)) == 1.0 and float(fit(16.0, 5.0)) == pytest.approx(1.0, abs=1e-4)
    assert 1 - float(fit(16.0, fit.u0)) < 0.33 ** 2


@pytest.mark.slow
@pytest.mark.parametrize("index", [10, 28])
def test_fresh_3d_runs_reproduce_points_of_the_clamp_series(index):
    # a 4:1 bar 0.2 widths from the clamp, and a 16:1 plate 0.5 widths out
    case = study.clamp_cases()[index]
    rows = [r for r in _rows() if r["family"] == "rectangle-none"]
    row = min(rows, key=lambda r: abs(r["width_ratio"] - case.width / case.height)
              + abs(r["clamp_ratio"] * case.height - case.clamp_clearance) * 1e3)
    fresh = study.run_case(case, mesh=row["mesh"])
    assert fresh.strain_near / fresh.strain_far == pytest.approx(row["strain_near"] / row["strain_far"], rel=1e-4)


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
