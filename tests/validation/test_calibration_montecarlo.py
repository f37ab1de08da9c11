"""Calibration and measurement (issue 6) by Monte Carlo: calibrate-and-measure round trips
against the predicted standard errors and sigma.

Fixtures ``tests/data/cal_prototype_{a,b,c}.json`` are the paper's Prototypes A, B and C
(Noh et al. 2025, Table 1; loads of Table 2) with k_i from MODEL.md section 3. The paper does
not give their electronics; assumed (as in examples/prototype-*.yaml): 5 V excitation,
sigma_V = 1.3 mV RMS per channel (measured on Prototype B, section 4.3) and gain 100 (A, full
bridges), 1000 (B, half bridges at all three stations) and 1000 (C, half bridges, two axes).

Monte Carlo references use fixed seeds; their tolerances are set from the sampling error of
the statistic (stated at each test), so that they fail when the model is wrong, not by chance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from designer import calibration as cal
from designer.model import estimator
from designer.calibration import readings as rd

from shared_inputs import calibration_record as record, calibration_constants as constants

PROTOTYPES = ("a", "b", "c")


#: Median of |e| for e ~ N(0, sigma^2) is 0.6745 sigma (the 75th percentile of the normal).
HALF_NORMAL_MEDIAN = 0.6744897501960817


def _tile(a, draws):
    return None if a is None else np.tile(a, draws)


def _simulate_draws(rec, loads: cal.LoadSet, draws: int, rng, offsets) -> np.ndarray:
    """(draws, rows, bridges) voltages from ``readings.simulate_readings``."""
    r = rd.simulate_readings(rec, _tile(loads.force, draws), _tile(loads.position, draws), rng,
                             _tile(loads.angle, draws), offsets)
    return r.voltages.reshape(draws, len(loads), -1)


def _axes(dc):
    return ("",) if dc.axes == 1 else ("y", "z")


def _round_trip(key: str, scheme: str, draws: int, seed: int, repeats: int = 1):
    """Calibrate ``draws`` times on the scheme, measure the remaining Table 2 loads each time."""
    rec, dc = record(key), constants(key)
    rng = np.random.default_rng(seed)
    cal_loads = cal.scheme_loads(dc, scheme).repeated(repeats)
    table2 = cal.scheme_loads(dc, "paper")
    used = {(round(f, 9), round(x, 9)) for f, x in zip(cal_loads.force, cal_loads.position)}
    keep = np.array([(round(f, 9), round(x, 9)) not in used for f, x in zip(table2.force, table2.position)])
    test = cal.LoadSet(table2.force[keep], table2.position[keep], None if table2.angle is None else table2.angle[keep])
    offsets = rd.simulated_sensor_offsets(rec, seed)
    v_cal = _simulate_draws(rec, cal_loads, draws, rng, offsets)
    v_test = _simulate_draws(rec, test, draws, rng, offsets)
    fits, z = {}, {}
    for axis in _axes(dc):
        cols = [i for i, b in enumerate(dc.bridges) if b.axis == axis]
        fit = cal.regress(cal.axis_force(cal_loads.force, cal_loads.angle, axis), cal_loads.position,
                          v_cal[..., cols])
        fits[axis] = (cols, fit)
        f_axis, x_axis = estimator.estimate(v_test[..., cols], fit.k[:, None, :], fit.d[:, None, :],
                                            fit.c[:, None, :])
        z[axis] = (f_axis * x_axis, f_axis)
    force, position, angle, *_ = cal.combine(z, {a: (0.0, 0.0, 0.0) for a in z})
    return dict(dc=dc, cal_loads=cal_loads, test=test, fits=fits, offsets=offsets, force=force,
                position=position, angle=angle)


CASES = [(key, scheme) for key in PROTOTYPES for scheme in ("4", "9")]
#: 4000 draws: the sample median of |e| has a relative standard error of about
#: 0.5 / (sqrt(N) f(q) q) = 1.85 % (f the half-normal density at its median q), and a z-score
#: standard deviation 1/sqrt(2 N) = 1.1 %.
DRAWS = 4000


@pytest.mark.parametrize("key,scheme", CASES)
def test_calibration_constants_match_the_model_within_their_standard_errors(key, scheme):
    """z = (fitted - true) / standard error over 4000 calibrations is N(0, 1) (design sigma_V).

    c and k are linear in the readings, so exactly normal; d = -b2/b1 by the delta method.
    Tolerances: mean within 0.1 (9 sigma of the mean), sd within 5 % (4.5 sigma), and at
    least 99 % of |z| < 3 (expected 99.73 %).
    """
    rt = _round_trip(key, scheme, DRAWS, seed=11)
    dc = rt["dc"]
    for axis, (cols, fit) in rt["fits"].items():
        se_k, se_d, se_c = fit.standard_errors(dc.noise)
        truth = {"k": (dc.bridge_k()[cols], fit.k, se_k), "d": (dc.bridge_d()[cols], fit.d, se_d),
                 "c": (rt["offsets"][cols], fit.c, se_c)}
        for name, (true, fitted, se) in truth.items():
            z = (fitted - true) / se
            assert abs(z.mean()) < 0.1, (name, z.mean())
            assert z.std() == pytest.approx(1.0, rel=0.05), (name, z.std(axis=0))
            assert np.mean(np.abs(z) < 3) > 0.99, name


@pytest.mark.parametrize("key,scheme", CASES)
def test_measurement_errors_match_the_analytic_prediction(key, scheme):
    """Median |error| over 4000 calibrate-and-measure draws = 0.6745 sigma within 10 %, per load.

    The prediction includes the calibration constants' uncertainty (the (1 + h) term; every
    draw is a new calibration). Each remaining Table 2 load is checked separately, Prototype B's
    20 g loads too (sigma_F/F = 40 %; there the ratio x = z1/z2 is skewed and its median lies
    about 5 % below the linear prediction). The test can tell: leaving out the calibration term
    would change the prediction by more than 15 % at some loads.
    """
    rt = _round_trip(key, scheme, DRAWS, seed=5)
    dc, test = rt["dc"], rt["test"]
    sf, sx, sa = cal.predicted_sigma(dc.sensitivity, dc.stations, test, dc.noise, rt["cal_loads"], dc.axes)
    sf0, sx0, _ = cal.predicted_sigma(dc.sensitivity, dc.stations, test, dc.noise, None, dc.axes)
    ratio_f = np.median(np.abs(rt["force"] - test.force), axis=0) / (HALF_NORMAL_MEDIAN * sf)
    ratio_x = np.median(np.abs(rt["position"] - test.position), axis=0) / (HALF_NORMAL_MEDIAN * sx)
    assert ratio_f == pytest.approx(np.ones_like(ratio_f), abs=0.10)
    assert ratio_x == pytest.approx(np.ones_like(ratio_x), abs=0.10)
    assert np.max(sf / sf0) > 1.15 and np.max(sx / sx0) > 1.15
    if dc.axes == 2:
        ratio_a = np.median(np.abs(rt["angle"] - test.angle), axis=0) / (HALF_NORMAL_MEDIAN * sa)
        assert ratio_a == pytest.approx(np.ones_like(ratio_a), abs=0.10)


def test_residual_noise_standard_errors_follow_student_t():
    """With sigma_V estimated from the residuals, z = (k - k_true)/se_k is Student t with the
    pooled residual dof (Prototype A, 9 points, 2 bridges: nu = 2 x 6 = 12, sd = sqrt(nu/(nu-2))
    = 1.095). 1500 calibrations through ``calibrate``: 9000 z values, sd known to about 1 %;
    tolerance 4 %, while N(0, 1) would be 9 % off."""
    rec, dc = record("a"), constants("a")
    rng = np.random.default_rng(3)
    offsets = rd.simulated_sensor_offsets(rec, 3)
    loads = cal.scheme_loads(dc, "9")
    zs = []
    for _ in range(1500):
        r = rd.simulate_readings(rec, loads.force, loads.position, rng, offsets=offsets)
        c = cal.calibrate(r, dc, noise="residual")
        assert c.noise_source == "residual" and c.residual_dof == 12
        for b, true_c in zip(c.bridges, offsets):
            zs += [(b.k - b.design_k) / b.se_k, (b.d - b.design_d) / b.se_d, (b.c - true_c) / b.se_c]
    nu = 12
    assert np.std(zs) == pytest.approx(math.sqrt(nu / (nu - 2)), rel=0.04)


@pytest.mark.parametrize("key", PROTOTYPES)
def test_single_calibration_round_trip(key):
    """One simulated sensor per prototype: R^2 >= 0.999 (the paper's Table 3: 0.99917 to
    1.00000), no warnings on clean data, constants within 4 standard errors (design sigma_V,
    so z is N(0, 1): P(|z| > 4) = 6e-5 for each of at most 24 constants; the 3-sigma rate
    itself is checked over 4000 calibrations above), the vectorised regression identical to
    ``calibrate``, and every remaining Table 2 load measured within 4.5 predicted sigma
    (210 loads at most: P(any beyond) < 0.2 %)."""
    rec, dc = record(key), constants(key)
    for scheme in ("4", "9"):
        readings = rd.simulated_scheme_readings(rec, scheme, seed=7)
        assert cal.calibrate(readings, dc).warnings == ()
        c = cal.calibrate(readings, dc, noise="design")
        offsets = rd.simulated_sensor_offsets(rec, 7)
        assert c.warnings == ()
        for b, true_c in zip(c.bridges, offsets):
            assert abs(b.k - b.design_k) < 4 * b.se_k and abs(b.d - b.design_d) < 4 * b.se_d
            assert abs(b.c - true_c) < 4 * b.se_c
            assert b.r2 >= cal.MIN_R2
        axis = c.bridges[0].bridge.axis
        cols = [i for i, b in enumerate(readings.bridges) if b.axis == axis]
        fit = cal.regress(cal.axis_force(readings.force, readings.angle, axis), readings.position,
                          readings.voltages[:, cols])
        assert [b.k for b in c.axis(axis)] == pytest.approx(fit.k, rel=1e-14)
        test = rd.simulated_scheme_readings(rec, "paper", seed=7)
        m = cal.measure_readings(c, test)
        assert np.all(np.abs(m.force - test.force) < 4.5 * m.sigma_force)
        assert np.all(np.abs(m.position - test.position) < 4.5 * m.sigma_position)


def test_prototype_c_recovers_magnitude_angle_and_position():
    """Biaxial: sigma_theta = sigma_F,component / |F| (rad) for an isotropic section.

    Closed form (no calibration term): sigma_theta F = sigma_F = sqrt(2) sigma_V /(k delta) at every
    angle. Monte Carlo: the 9-point scheme read 25 times per load shrinks the calibration term to
    h / 25 (at most 2 % on sigma); 3000 draws give the sd of the angle error to 1.3 %; tolerance 10 %.
    """
    dc = constants("c")
    loads = cal.scheme_loads(dc, "paper")
    # k by the paper's eq. 7 from Table 1 (6061 tube 12.7 x 1.65 mm: I = pi (D^4 - (D - 2t)^4)/64,
    # y = D/2; half bridges n = 2; 5 V, gain 1000, G = 2.0; E = 68.9 GPa), stations 20 and 70 mm
    i_tube = math.pi * ((12.7e-3) ** 4 - (12.7e-3 - 2 * 1.65e-3) ** 4) / 64
    k = 5 * 2.0 * 1000 * 2 * (12.7e-3 / 2) / (4 * 68.9e9 * i_tube)
    sigma_component = math.sqrt(2) * 1.3e-3 / (k * (0.070 - 0.020))
    sf, _, sa = cal.predicted_sigma(dc.sensitivity, dc.stations, loads, dc.noise, None, 2)
    assert sf == pytest.approx(sigma_component, rel=1e-12)
    assert sa * loads.force == pytest.approx(sigma_component, rel=1e-12)

    rt = _round_trip("c", "9", draws=3000, seed=21, repeats=25)
    test = rt["test"]
    err = rt["angle"] - test.angle
    assert np.std(err, axis=0) == pytest.approx(sigma_component / test.force, rel=0.10)
    # the means over draws recover the truth, to 4.5 standard errors of a mean of 3000:
    # magnitude, angle 0-90 degrees and position (x = z1/z2 also carries the ratio bias
    # (sigma_F/F)^2 (x - mean d), at most 0.5 mm at 250 g: hence 1 mm rather than 4.5 SE = 0.8 mm)
    sf, sx, sa = cal.predicted_sigma(dc.sensitivity, dc.stations, test, dc.noise, rt["cal_loads"], 2)
    se = 4.5 / math.sqrt(3000)
    assert np.all(np.abs(np.mean(rt["force"], axis=0) - test.force) < se * sf)
    assert np.all(np.abs(np.mean(rt["angle"], axis=0) - test.angle) < se * sa)
    assert set(np.round(np.degrees(test.angle))) == set(range(0, 91, 15))
    assert np.mean(rt["position"], axis=0) == pytest.approx(test.position, abs=1e-3)
