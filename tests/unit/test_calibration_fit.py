"""Calibration and measurement (issue 6) in the library: the regression on clean data, the
warnings, the noise choices and the calibration plan.

Fixtures ``tests/data/cal_prototype_{a,b,c}.json`` are the paper's Prototypes A, B and C
(Noh et al. 2025, Table 1; loads of Table 2) with k_i from MODEL.md section 3. The paper does
not give their electronics; assumed (as in examples/prototype-*.yaml): 5 V excitation,
sigma_V = 1.3 mV RMS per channel (measured on Prototype B, section 4.3) and gain 100 (A, full
bridges), 1000 (B, half bridges at all three stations) and 1000 (C, half bridges, two axes).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from designer import calibration as cal
from designer.model import estimator
from designer.calibration import readings as rd
from designer.errors import CsvError, InputError

from shared_inputs import calibration_record as record, calibration_constants as constants, clean_prototype_b as _clean_b

PROTOTYPES = ("a", "b", "c")


def test_non_prototype_paper_scheme_is_a_grid_over_the_region():
    rec = record("b")
    rec["design"]["section"]["width"] = 0.02   # no longer Prototype B
    dc = cal.design_constants(rec)
    assert dc.prototype is None
    loads = cal.scheme_loads(dc, "paper")
    assert len(loads) == cal.GRID_POINTS ** 2
    assert (loads.force.min(), loads.force.max()) == pytest.approx(dc.force_range, rel=1e-12)
    assert (loads.position.min(), loads.position.max()) == pytest.approx(dc.position_range, rel=1e-12)


def test_regression_recovers_constants_exactly_without_noise():
    """Noise-free bridges: eqs. 28-30 return k, d, c to rounding and R^2 = 1."""
    k, d, c = np.array([0.31, 0.29, 0.33]), np.array([0.02, 0.06, 0.10]), np.array([3e-3, -2e-3, 1e-3])
    loads = cal.scheme_loads(constants("b"), "9")
    v = estimator.bridge_voltages(k, d, c, loads.force, loads.position)
    result = cal.calibrate(cal.Readings(cal.bridges_for(3, 1), v, loads.force, loads.position))
    assert [b.k for b in result.bridges] == pytest.approx(k, rel=1e-9)
    assert [b.d for b in result.bridges] == pytest.approx(d, rel=1e-9)
    assert [b.c for b in result.bridges] == pytest.approx(c, abs=1e-12)
    assert [b.r2 for b in result.bridges] == pytest.approx([1.0] * 3, abs=1e-12)


def _with_voltages(r: cal.Readings, v) -> cal.Readings:
    return cal.Readings(r.bridges, v, r.force, r.position, r.angle, r.lines, r.source, r.mass)


def test_warning_for_bridges_whose_k_differ_more_than_the_design_predicts():
    _, dc, r = _clean_b()
    v = r.voltages.copy()
    v[:, 1] *= 1.2   # bridge 2 reads 20 % high (its offset too, which does not matter)
    c = cal.calibrate(_with_voltages(r, v), dc)
    assert any(w.startswith("V2: k =") and "differs by" in w for w in c.warnings), c.warnings
    assert not any(w.startswith(("V1: k", "V3: k")) for w in c.warnings)
    # without a design: the bridges are nominally identical
    c = cal.calibrate(_with_voltages(r, v))
    assert any(w.startswith("V2: k =") and "nominally equal" in w for w in c.warnings)


@pytest.mark.parametrize("reversed_columns", [[1], [0, 1, 2]])
def test_a_reversed_bridge_is_said_to_be_reversed_and_nothing_else(reversed_columns):
    """A bridge wired the other way round reads -k (docs/model.md §10: measurements still work):
    the warning says so, and its size is compared with the design's as any other's (its sign had
    made it "differ by -11277980 %" and the common scale "-100 %" or "-200 %")."""
    _, dc, r = _clean_b()
    v = r.voltages.copy()
    v[:, reversed_columns] *= -1
    c = cal.calibrate(_with_voltages(r, v), dc)
    for j in reversed_columns:
        assert any(w.startswith(f"V{j + 1}: k =") and "not positive" in w for w in c.warnings), c.warnings
    assert not any("differs by" in w or "on average" in w for w in c.warnings), c.warnings


NONLINEARITY = 0.30


def test_warning_for_a_poor_fit():
    """A bridge that grows quadratically with the moment, by 30 % of its span at the largest
    load: R^2 below 0.999 and residuals far above the design's sigma_V; the clean bridges get
    neither. (R^2 is a blunt test: 10 % still gives 0.9997, while the chi-square test fires.)"""
    _, dc, r = _clean_b()
    v = r.voltages.copy()
    m = r.force * r.position
    v[:, 0] += NONLINEARITY * np.ptp(v[:, 0]) * (m / m.max()) ** 2
    c = cal.calibrate(_with_voltages(r, v), dc)
    assert any(w.startswith("V1: R² =") for w in c.warnings), c.warnings
    assert not any(w.startswith(("V2: R²", "V3: R²")) for w in c.warnings)
    assert any("larger than the design's noise" in w for w in c.warnings)


def test_warning_for_a_misplaced_load_names_its_line_and_column():
    rec, dc = record("a"), constants("a")
    r = rd.simulated_scheme_readings(rec, "grid", seed=4)
    text = rd.format_readings(r)
    r = rd.parse_readings(text, "cal.csv", need_loads=True)
    v = r.voltages.copy()
    v[10, 1] += 20 * dc.noise
    c = cal.calibrate(_with_voltages(r, v), dc)
    outliers = [w for w in c.warnings if "standard deviations from the fit" in w]
    assert len(outliers) == 1 and outliers[0].startswith(f"line {r.lines[10]} ") and "column V2" in outliers[0]


def test_warnings_for_too_few_points_and_a_region_not_spanned():
    rec, dc = record("a"), constants("a")
    loads = cal.scheme_loads(dc, "grid")
    inner = (loads.force < dc.force_range[1] * 0.8) & (loads.position < 0.5)
    rng = np.random.default_rng(1)
    r = rd.simulate_readings(rec, loads.force[inner], loads.position[inner], rng)
    c = cal.calibrate(r, dc)
    assert sum("calibration loads span" in w for w in c.warnings) == 2   # force and position
    three = rd.simulate_readings(rec, [2.0, 10.0, 19.0], [0.15, 0.65, 0.3], rng)
    c = cal.calibrate(three, dc)
    assert any(w.startswith("only 3 calibration points") for w in c.warnings)
    assert c.noise_source == "design" and c.bridges[0].se_k is not None


def test_warning_when_a_gauge_sits_away_from_its_station():
    rec = record("b")
    dc = cal.design_constants(rec)
    rec["design"]["stations"] = [0.02, 0.065, 0.10]        # the gauge really sits 5 mm out
    r = rd.simulated_scheme_readings(rec, "9", seed=2)
    c = cal.calibrate(r, dc)
    assert any(w.startswith("V2: the fitted station d") for w in c.warnings), c.warnings


@pytest.mark.parametrize("value", [0.0, 1e-320, 0.1])
def test_a_bridge_that_reads_the_same_in_every_row_is_refused(value):
    """A disconnected bridge (a column of zeros, or of one value) has no k, and d = -b2/b1 would
    be 0/0: calibration refuses it, naming the rows and the column, instead of writing NaN; so
    too a column whose readings span less than the smallest voltage fpdesign handles."""
    _, dc, r = _clean_b()
    v = r.voltages.copy()
    v[:, 1] = value
    with pytest.raises(CsvError, match=rf"row 1 to row {len(r)}, column V2: does not respond to the load: "
                                       rf"it reads {value!r} V in every row"):
        cal.calibrate(_with_voltages(r, v), dc)
    # a real bridge's readings scaled so far down that they span less than fpdesign resolves
    v = r.voltages.copy()
    v[:, 1] *= 0.1 * cal.MIN_RESPONSE / np.ptp(v[:, 1])
    with pytest.raises(CsvError, match="column V2: does not respond to the load: its readings span only"):
        cal.calibrate(_with_voltages(r, v), dc)


def test_a_bridge_that_reads_noise_or_the_force_alone_is_refused():
    """A bridge whose readings do not follow the moment F·x: its fitted k lies within
    SIGNIFICANT_SIGMAS standard errors of zero, whether it reads an offset with the design's noise,
    the same noise ten times over (its own residuals, not the design's, set the standard error),
    or the force alone (V = c + b F, no station d)."""
    _, dc, r = _clean_b()
    rng = np.random.default_rng(5)
    dead = 0.1 + rng.normal(0.0, dc.noise, len(r))
    for column in (dead, 0.1 + 10 * (dead - 0.1), 0.1 + 0.01 * r.force):
        v = r.voltages.copy()
        v[:, 2] = column
        for noise in ("auto", "design"):
            with pytest.raises(CsvError, match=rf"row 1 to row {len(r)}, column V3: does not respond to the load: "
                                               rf"its fitted k = .* is within {cal.SIGNIFICANT_SIGMAS:g} standard "
                                               "errors"):
                cal.calibrate(_with_voltages(r, v), dc, noise)


def test_loads_of_one_moment_are_blamed_not_the_bridges():
    """Six loads whose moments F·x are all 0.1 N·m but one (0.100001 N·m): the design matrix is not
    singular enough for the rank test, but k cannot be told from zero, and the message had sent the
    user to V1's wiring. Two healthy bridges (V = k F (x - d) + c, k 0.2 and 0.4 V/(N·m))."""
    rows = [(1, 100), (2, 50), (4, 25), (5, 20), (0.5, 200), (1, 100.001)]
    k, d, c = np.array([0.2, 0.4]), np.array([0.01, 0.05]), np.array([0.0, 0.0])
    lines = ["force_N,position_mm,V1,V2"] + [
        ",".join([f"{f:g}", f"{x:g}"] + [repr(float(v)) for v in estimator.bridge_voltages(k, d, c, f, x / 1e3)])
        for f, x in rows]
    r = rd.parse_readings("\n".join(lines) + "\n", "cal.csv", need_loads=True)
    with pytest.raises(CsvError, match=r"its k cannot be told from zero, and the loads' moments F·x span "
                                       r"1e-05 of the largest: the loads cannot determine k and d") as err:
        cal.calibrate(r)
    assert "wiring" not in str(err.value)


def test_bridges_that_fit_one_station_are_refused():
    """One bridge read three times (every column the same) fits one d for all: force and position
    could not be told apart, so calibration refuses it rather than write what measure refuses."""
    _, dc, r = _clean_b()
    v = np.repeat(r.voltages[:, :1], 3, axis=1)
    with pytest.raises(CsvError, match=r"columns V1, V2, V3: all fit one station"):
        cal.calibrate(_with_voltages(r, v), dc)


@pytest.mark.parametrize("key", PROTOTYPES)
def test_real_noisy_bridges_still_calibrate(key):
    """Simulated readings at the design's own noise, on the fewest loads (the 4 corners, one
    residual degree of freedom per bridge) and on the 9-point scheme, calibrate for every seed
    tried; so do the same readings with one bridge ten times noisier than designed."""
    rec, dc = record(key), constants(key)
    for scheme in ("4", "9"):
        for seed in range(10):
            r = rd.simulated_scheme_readings(rec, scheme, seed=seed)
            assert len(cal.calibrate(r, dc).bridges) == len(dc.bridges)
            v = r.voltages.copy()
            v[:, 0] += np.random.default_rng(seed).normal(0.0, 10 * dc.noise, len(r))
            assert len(cal.calibrate(_with_voltages(r, v), dc).bridges) == len(dc.bridges)


# --------------------------------------------------------------------- measurement noise choices

def test_measurement_sigma_scales_with_the_noise_and_includes_the_calibration():
    rec, dc, r = _clean_b()
    c = cal.calibrate(r, dc, noise="design")
    v = rd.simulated_scheme_readings(rec, "paper", seed=2).voltages
    m1 = cal.measure(c, v)
    m2 = cal.measure(c, v, noise=2 * dc.noise)
    assert m2.sigma_force == pytest.approx(2 * m1.sigma_force, rel=1e-12)
    m0 = cal.measure(c, v, include_calibration=False)
    assert np.all(m0.sigma_force < m1.sigma_force)
    # Reading noise alone, by hand: rows (k_i, -k_i d_i) of A for z = (F x, F) with the calibrated
    # k and d, Cov(z) = sigma_V^2 (A^T A)^-1, and the 2 x 2 inverse's lower corner gives
    # sigma_F = sigma_V sqrt(S0 / (S0 S2 - S1^2)), S_j = sum k_i^2 d_i^j (two equal stations:
    # sqrt(2) sigma_V/(k delta), MODEL.md section 3). The same at every reading.
    k, d = np.array([b.k for b in c.bridges]), np.array([b.d for b in c.bridges])
    s0, s1, s2 = (np.sum(k ** 2 * d ** j) for j in range(3))
    assert m0.sigma_force == pytest.approx(dc.noise * math.sqrt(s0 / (s0 * s2 - s1 ** 2)), rel=1e-12)


def test_noise_choice_auto_uses_the_residuals_only_with_enough_dof():
    rec, dc = record("a"), constants("a")
    four = rd.simulated_scheme_readings(rec, "4", seed=1)      # 2 residual dof
    nine = rd.simulated_scheme_readings(rec, "9", seed=1)      # 12 residual dof
    assert cal.calibrate(four, dc).noise_source == "design"
    assert cal.calibrate(nine, dc).noise_source == "residual"
    c = cal.calibrate(four)
    assert c.noise_source == "residual" and any("degrees of" in w for w in c.warnings)


def test_noise_choices_that_cannot_be_met_are_errors():
    rec, dc = record("a"), constants("a")
    three = rd.simulate_readings(rec, [2.0, 10.0, 19.0], [0.15, 0.65, 0.3], np.random.default_rng(1))
    with pytest.raises(CsvError, match="no residual to estimate the noise"):
        cal.calibrate(three, dc, noise="residual")
    with pytest.raises(InputError, match="'design' needs a design"):
        cal.calibrate(three, None, noise="design")
    c = cal.calibrate(three)
    assert c.noise is None and c.bridges[0].se_k is None and any("fit exactly" in w for w in c.warnings)
    m = cal.measure(c, three.voltages)
    assert np.all(np.isnan(m.sigma_force)) and m.force == pytest.approx(three.force, rel=1e-9)


# --------------------------------------------------------------------- plan

def test_plan_worst_cases_match_the_design_and_grow_with_calibration_uncertainty():
    for key in PROTOTYPES:
        rec, dc = record(key), constants(key)
        p = cal.plan(dc)
        p10 = cal.plan(dc, repeats=10)
        for s, s10 in zip(p.schemes, p10.schemes):
            # worst case without calibration uncertainty: sigma_F/F_min and sigma_x(F_min, x_max)
            assert s.force_error == pytest.approx(rec["predicted"]["force_error"], rel=1e-9)
            assert s.position_error == pytest.approx(rec["predicted"]["position_error"], rel=1e-9)
            assert s.force_error_calibrated > s.force_error
            assert s.force_error < s10.force_error_calibrated < s.force_error_calibrated
            assert s.position_error_calibrated > s.position_error
        four, nine = p.schemes
        assert nine.force_error_calibrated < four.force_error_calibrated
        assert (four.loadings, nine.loadings) == ((4, 9) if dc.axes == 1 else (8, 18))
