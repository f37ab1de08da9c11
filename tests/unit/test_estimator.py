"""The estimator's least squares for N stations (MODEL.md section 3) against numpy: the
solution, the propagated covariance (GUM linear propagation) and the fast path for one
calibration.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from designer.model import estimator


def test_least_squares_with_three_stations_matches_numpy():
    # N >= 2: rows V_i - c_i = k_i z1 - k_i d_i z2, solved by numpy.linalg.lstsq.
    k, d, c = (0.3, 0.33, 0.35), (0.02, 0.06, 0.10), (0.01, 0.0, -0.02)
    rng = np.random.default_rng(2)
    v = estimator.bridge_voltages(k, d, c, 4.0, 0.25) + rng.normal(0, 0.01, 3)
    A = np.column_stack([k, -np.multiply(k, d)])
    z, *_ = np.linalg.lstsq(A, v - np.asarray(c), rcond=None)
    f_hat, x_hat = estimator.estimate(v, k, d, c)
    assert f_hat == pytest.approx(z[1], rel=1e-10)
    assert x_hat == pytest.approx(z[0] / z[1], rel=1e-10)
    f0, x0 = estimator.estimate(estimator.bridge_voltages(k, d, c, 4.0, 0.25), k, d, c)
    assert (f0, x0) == pytest.approx((4.0, 0.25), rel=1e-9)


def test_predicted_covariance_is_sigma_squared_times_inverse_normal_matrix():
    # GUM linear propagation: Cov(z) = sigma_V^2 (A^T A)^-1; sigma_x from the gradient of
    # x = z1/z2, [1/F, -x/F]. Compared with numpy's inverse at rel 1e-10.
    k, d, sigma_v, force, x = (0.3, 0.33, 0.35), (0.02, 0.06, 0.10), 1e-3, 3.0, 0.3
    A = np.column_stack([k, -np.multiply(k, d)])
    cov = sigma_v ** 2 * np.linalg.inv(A.T @ A)
    grad = np.array([1 / force, -x / force])
    assert estimator.sigma_force(k, d, sigma_v) == pytest.approx(math.sqrt(cov[1, 1]), rel=1e-10)
    assert estimator.sigma_position(k, d, sigma_v, force, x) == pytest.approx(math.sqrt(grad @ cov @ grad), rel=1e-10)


def test_one_calibration_for_all_readings_or_one_per_reading_give_the_same_estimate():
    # estimate() has a fast path (matrix products) for one calibration and a general one for
    # calibrations that vary per reading; on the same numbers they must agree (rel 1e-12).
    rng = np.random.default_rng(4)
    k, d, c = np.array([0.3, 0.33, 0.35]), np.array([0.02, 0.06, 0.10]), np.array([0.01, 0.0, -0.02])
    v = estimator.bridge_voltages(k, d, c, 4.0, 0.25) + rng.normal(0, 0.01, (50, 3))
    fast = estimator.estimate(v, k, d, c)
    general = estimator.estimate(v, np.tile(k, (50, 1)), np.tile(d, (50, 1)), np.tile(c, (50, 1)))
    np.testing.assert_allclose(fast, general, rtol=1e-12)
    scalar_offset = estimator.estimate(v - c, k, d, 0.0)
    np.testing.assert_allclose(fast, scalar_offset, rtol=1e-12)
