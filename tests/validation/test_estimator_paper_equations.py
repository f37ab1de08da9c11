"""The estimator (MODEL.md section 3) against the paper's equations, written out literally.

Reference: Noh et al. 2025 (shared/reference/noh2025-force-position-cantilever.txt): eqs. 4,
9-10 (bridge voltages), 11-12 (force and position from two bridges) and the two-station
closed forms of the errors (eqs. 24, 35, 36).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from designer.model import estimator


def eq_11_position(V1, V2, k1, k2, d1, d2, c1, c2):
    """Noh et al. 2025, eq. 11, literally."""
    return (k2 * d2 * (V1 - c1) - k1 * d1 * (V2 - c2)) / (k2 * (V1 - c1) - k1 * (V2 - c2))


def eq_12_force(V1, V2, k1, k2, d1, d2, c1, c2):
    """Noh et al. 2025, eq. 12, literally."""
    return (k2 * (V1 - c1) - k1 * (V2 - c2)) / (k1 * k2 * (d2 - d1))


K = (0.34, 0.31)           # V/(N m): unequal bridges, as after a calibration
D = (0.020, 0.100)         # m
C = (0.012, -0.007)        # V: unbalanced bridges


@pytest.mark.parametrize("force, position", [(1.96, 0.15), (19.6, 0.45), (7.3, 0.2915), (0.05, 0.12)])
def test_forward_model_then_eqs_11_12_recover_the_load(force, position):
    # Noise-free voltages from eq. 9-10 (V_i = k_i F (x - d_i) + c_i) solved by eqs. 11-12 and
    # by the package's least squares must give the load back: rel 1e-9 allows for the
    # cancellation in V_i - c_i only.
    V1, V2 = estimator.bridge_voltages(K, D, C, force, position)
    assert V1 == pytest.approx(K[0] * force * (position - D[0]) + C[0], rel=1e-14)
    assert eq_12_force(V1, V2, *K, *D, *C) == pytest.approx(force, rel=1e-9)
    assert eq_11_position(V1, V2, *K, *D, *C) == pytest.approx(position, rel=1e-9)
    f_hat, x_hat = estimator.estimate([V1, V2], K, D, C)
    assert f_hat == pytest.approx(force, rel=1e-9)
    assert x_hat == pytest.approx(position, rel=1e-9)


def test_least_squares_with_two_stations_is_eqs_11_12():
    # MODEL.md: for two stations the least squares is exactly eqs. 11-12, also for noisy
    # voltages that no load explains (two equations, two unknowns). rel 1e-9: rounding.
    rng = np.random.default_rng(1)
    v = estimator.bridge_voltages(K, D, C, 5.0, 0.3) + rng.normal(0, 0.02, (1000, 2))
    f_hat, x_hat = estimator.estimate(v, K, D, C)
    np.testing.assert_allclose(f_hat, eq_12_force(v[:, 0], v[:, 1], *K, *D, *C), rtol=1e-9)
    np.testing.assert_allclose(x_hat, eq_11_position(v[:, 0], v[:, 1], *K, *D, *C), rtol=1e-9)


def test_predicted_sigma_for_two_equal_stations():
    # MODEL.md section 3 (compare the paper's eqs. 24, 35, 36): sigma_F = sqrt(2) sigma_V/(k delta),
    # sigma_x = sigma_V sqrt((x-d1)^2 + (x-d2)^2)/(k delta F). Exact algebra: rel 1e-12.
    k, d, sigma_v = 0.3446, (0.02, 0.10), 1.3e-3
    delta = d[1] - d[0]
    assert estimator.sigma_force([k, k], d, sigma_v) == pytest.approx(math.sqrt(2) * sigma_v / (k * delta), rel=1e-12)
    for force, x in [(1.96, 0.15), (19.6, 0.45)]:
        expected = sigma_v * math.hypot(x - d[0], x - d[1]) / (k * delta * force)
        assert estimator.sigma_position([k, k], d, sigma_v, force, x) == pytest.approx(expected, rel=1e-12)


def test_prototype_b_strains_through_eq_4_then_eqs_11_12_give_the_load_back(examples):
    # The whole forward chain of the package for Prototype B (Table 1): gauge strains from the
    # beam model (eq. 3, with the holes' 3-D correction, docs/model.md §7) at F_max, x_max,
    # turned into volts by eq. 4 (V = V_s g G n eps / 4), then eqs. 11-12 with the model's k_i
    # (eq. 7 with the same correction) and balanced bridges: F and x to rel 1e-9.
    from designer.result.evaluation import evaluate, fixed_design
    from designer.spec.reader import load_spec

    spec = load_spec(examples / "prototype-b.yaml")
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    a, e = ev.analysis, spec.electronics
    V1, V2 = (e.excitation * e.gain * spec.gauge.factor * spec.bridge_factor * eps / 4 for eps in a.gauge_strain)
    d1, d2 = ev.design.geometry.stations
    k1, k2 = a.sensitivities
    assert eq_12_force(V1, V2, k1, k2, d1, d2, 0.0, 0.0) == pytest.approx(spec.load.force_max, rel=1e-9)
    assert eq_11_position(V1, V2, k1, k2, d1, d2, 0.0, 0.0) == pytest.approx(spec.load.position_max, rel=1e-9)
