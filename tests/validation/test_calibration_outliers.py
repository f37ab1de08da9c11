"""The calibration's outlier test (designer.calibration.fit.outlier_rows) against its closed
forms and Monte Carlo.

Source: Cook & Weisberg (1982), *Residuals and Influence in Regression*, §2.2.2 (the mean-shift
outlier model: the externally studentized residual follows t(n - p - 1), and its square F(1,
n - p - 1)); pooled over m bridges with one noise sigma_V the row's statistic follows F(m,
m (n - p - 1)), and, when the row's load is misplaced by dx, the noncentral F with
lambda = (1 - h_ii) sum_j (k_j F dx)^2 / sigma_V^2 (Montgomery, Peck & Vining 2012, §3.3.4,
the general linear hypothesis). Readings are simulated with the design's noise
(Prototype B of tests/data/cal_prototype_b.json: three half bridges, sigma_V = 1.3 mV).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from designer import calibration as cal
from designer.calibration import readings as rd
from designer.model import estimator

DATA = Path(__file__).resolve().parents[1] / "data"
RECORD = json.loads((DATA / "cal_prototype_b.json").read_text())
DESIGN = cal.design_constants(RECORD)
MISPLACED = 0.010   # m: one load hung 10 mm from where the plan puts it


def _voltages(loads, rng, shift_row=None, dx=0.0):
    """Bridge readings of the design at ``loads``; the load of ``shift_row`` really hangs dx further out."""
    k, d = np.asarray(DESIGN.sensitivity), np.asarray(DESIGN.stations)
    x = loads.position.copy()
    if shift_row is not None:
        x[shift_row] += dx
    v = estimator.bridge_voltages(k, d, np.zeros_like(k), loads.force, x)
    return v + rng.normal(0.0, DESIGN.noise, v.shape)


def _power(loads, row, dx, alpha_row):
    """Closed form: the probability that the test flags ``row`` misplaced by ``dx``."""
    fit = cal.regress(loads.force, loads.position, np.zeros((len(loads.force), len(DESIGN.stations))))
    n, m = len(loads.force), len(DESIGN.stations)
    dof = m * (n - 4)
    k = np.asarray(DESIGN.sensitivity)
    lam = (1 - fit.leverage[row]) * np.sum((k * loads.force[row] * dx) ** 2) / DESIGN.noise ** 2
    return float(stats.ncf.sf(stats.f.isf(alpha_row, m, dof), m, dof, lam))


def _flag_rate(loads, draws, seed, shift_row=None, dx=0.0, row_only=False):
    rng = np.random.default_rng(seed)
    n = len(loads.force)
    flagged = 0
    for _ in range(draws):
        fit = cal.regress(loads.force, loads.position, _voltages(loads, rng, shift_row, dx))
        rows = [o.row for o in cal.outlier_rows(fit, cal.OUTLIER_ALPHA / n)]
        flagged += (shift_row in rows) if row_only else bool(rows)
    return flagged / draws


@pytest.mark.parametrize("scheme, draws", [("9", 4000), ("grid", 2000)])
def test_clean_readings_raise_no_flag_beyond_the_stated_false_alarm_rate(scheme, draws):
    """Monte Carlo over clean calibrations: the rate of any flag is at most OUTLIER_ALPHA
    (Bonferroni over the rows), within 3 binomial standard errors."""
    loads = cal.scheme_loads(DESIGN, scheme)
    rate = _flag_rate(loads, draws, seed=11)
    se = np.sqrt(cal.OUTLIER_ALPHA * (1 - cal.OUTLIER_ALPHA) / draws)
    assert rate <= cal.OUTLIER_ALPHA + 3 * se


def test_a_clean_row_statistic_follows_its_f_distribution():
    """Under no outlier the row statistic's p-value is uniform (Kolmogorov-Smirnov against
    U(0, 1), 2000 draws of the 9-point scheme's middle row)."""
    loads = cal.scheme_loads(DESIGN, "9")
    rng = np.random.default_rng(5)
    p = []
    for _ in range(2000):
        fit = cal.regress(loads.force, loads.position, _voltages(loads, rng))
        p.append(next(o.p_value for o in cal.outlier_rows(fit, 1.0 + 1e-12) if o.row == 4))
    assert stats.kstest(p, "uniform").pvalue > 1e-3


@pytest.mark.parametrize("scheme", ["9", "grid"])
def test_a_load_misplaced_by_10_mm_at_f_max_is_flagged(scheme):
    """The load at F_max in the middle of the positions, hung 10 mm out: the closed-form power
    is above 0.9999, and every one of 20 simulated calibrations (each with its own noise) flags
    that row, through ``calibrate`` and its warning."""
    loads = cal.scheme_loads(DESIGN, scheme)
    n = len(loads.force)
    fmax = np.isclose(loads.force, loads.force.max())
    mid = np.argmin(np.where(fmax, np.abs(loads.position - np.median(loads.position)), np.inf))
    assert _power(loads, mid, MISPLACED, cal.OUTLIER_ALPHA / n) > 0.9999
    for seed in range(20):
        v = _voltages(loads, np.random.default_rng(100 + seed), mid, MISPLACED)
        readings = cal.Readings(cal.bridges_for(len(DESIGN.stations), 1), v, loads.force, loads.position,
                                lines=tuple(range(2, n + 2)), source="cal.csv")
        warnings = [w for w in cal.calibrate(readings, DESIGN).warnings if "misplaced or mis-recorded" in w]
        assert len(warnings) == 1 and warnings[0].startswith(f"line {mid + 2} "), warnings


@pytest.mark.parametrize("scheme, row, target", [("9", 4, 0.3), ("9", 8, 0.7), ("grid", 24, 0.5)])
def test_the_flag_rate_of_a_misplaced_load_is_the_noncentral_f_power(scheme, row, target):
    """Monte Carlo against the closed form: a load misplaced by the shift whose closed-form
    power is ``target`` (between the extremes, where the comparison can fail) is flagged as
    often as the noncentral F says."""
    from scipy.optimize import brentq

    loads = cal.scheme_loads(DESIGN, scheme)
    n = len(loads.force)
    dx = brentq(lambda s: _power(loads, row, s, cal.OUTLIER_ALPHA / n) - target, 1e-6, 0.1)
    power = _power(loads, row, dx, cal.OUTLIER_ALPHA / n)
    draws = 1000
    rate = _flag_rate(loads, draws, seed=21 + row, shift_row=row, dx=dx, row_only=True)
    assert rate == pytest.approx(power, abs=4 * np.sqrt(power * (1 - power) / draws))


def test_the_old_score_could_not_flag_it():
    """Why leave-one-out: a residual scored against its own fit's spread is bounded by
    sqrt(n - p) (Cook & Weisberg 1982, §2.2.1), 2.45 for the 9-point scheme with one bridge,
    below any useful threshold; the externally studentized residual of the same row is not."""
    loads = cal.scheme_loads(DESIGN, "9")
    v = _voltages(loads, np.random.default_rng(3), 7, 0.05)[:, :1]
    fit = cal.regress(loads.force, loads.position, v)
    e, h = fit.residuals[:, 0], fit.leverage
    s = np.sqrt(np.sum(e ** 2) / fit.dof)
    internal = np.abs(e) / (s * np.sqrt(1 - h))
    assert internal.max() <= np.sqrt(len(e) - 3) + 1e-12
    flagged = cal.outlier_rows(fit, cal.OUTLIER_ALPHA / len(e))
    assert [o.row for o in flagged] == [7] and abs(flagged[0].t) > np.sqrt(len(e) - 3)
