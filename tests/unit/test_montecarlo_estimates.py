"""designer.checks.montecarlo: the biaxial estimate without noise, and seeded draws."""

from __future__ import annotations

import math

import numpy as np
import pytest

from designer.checks.montecarlo import estimate_biaxial, simulate
from shared_inputs import montecarlo_prototype as prototype


def test_biaxial_estimate_recovers_magnitude_angle_and_position():
    # Noise-free voltages on both axes: exact recovery (rel 1e-12, rounding).
    k, d, c = np.array([0.5, 0.5]), np.array([0.02, 0.07]), np.array([0.001, -0.002])
    F, theta, x = 7.0, math.radians(130.0), 0.15
    vy = k * F * math.cos(theta) * (x - d) + c
    vz = k * F * math.sin(theta) * (x - d) + c
    mag, ang, pos = estimate_biaxial(vy, vz, k, d, c, c)
    assert (float(mag), float(ang), float(pos)) == pytest.approx((F, theta, x), rel=1e-12)


def test_the_same_seed_gives_the_same_answer(examples):
    spec, k, d, forces, positions = prototype(examples, "prototype-b")
    a = simulate(k, d, spec.sigma_v, forces[:3], positions[:3], draws=2000, seed=3)
    b = simulate(k, d, spec.sigma_v, forces[:3], positions[:3], draws=2000, seed=3)
    c = simulate(k, d, spec.sigma_v, forces[:3], positions[:3], draws=2000, seed=4)
    np.testing.assert_array_equal(a.sigma_force_mc, b.sigma_force_mc)
    assert not np.array_equal(a.sigma_force_mc, c.sigma_force_mc)


@pytest.mark.parametrize("degrees", [180.0, -180.0, 179.9, 30.0])
def test_the_angle_s_spread_is_the_same_on_either_side_of_half_a_turn(degrees):
    """Two equal axes of bridges with the same noise: the angle's 1 sigma is sigma_F / F in any
    direction (the noise across the force moves the angle by it over F, linear propagation). At
    180 deg the estimates fall on both sides of -180/180 deg; their spread had been taken as a
    whole turn's (MC/model 2992924 %)."""
    k, d = np.array([0.5, 0.5]), np.array([0.02, 0.07])
    sigma_v, F, x = 1e-4, 2.0, 0.15
    result = simulate(k, d, sigma_v, [F], [x], draws=20_000, seed=1, angle=math.radians(degrees))
    assert float(result.sigma_angle[0]) == pytest.approx(float(result.sigma_force[0]) / F, rel=1e-12)
    # 20,000 draws: the spread of a standard deviation's estimate is 1/sqrt(2 n) = 0.5 %
    assert float(result.sigma_angle_mc[0] / result.sigma_angle[0]) == pytest.approx(1.0, abs=0.03)
