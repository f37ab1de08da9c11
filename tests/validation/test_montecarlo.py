"""Monte Carlo of the estimator (Noh et al. 2025, section 4.3) against the analytic 1-sigma of
MODEL.md section 3, on the paper's Prototype B grid and for the biaxial Prototype C.

Tolerances: the standard deviation of N = 1e5 Gaussian draws scatters by 1/sqrt(2N) = 0.22 %;
the estimator x = z1/z2 and the biaxial magnitude and angle are nonlinear, which adds
second-order terms of order (sigma_F/F)^2, at most (3.4 %)^2 ~ 0.1 % here. 2 % (the issue's
acceptance) is therefore 9 sampling sigmas above the noise and far below any real model error
(a wrong factor of sqrt(2), or a missing (x - d) term, shows up as 10 % or more).

The analytic 1-sigma the draws are held to is the closed form for two equal stations (MODEL.md
section 3; the paper's eqs. 24, 35, 36), sigma_F = sqrt(2) sigma_V/(k delta) and
sigma_x = sigma_V sqrt((x - d1)^2 + (x - d2)^2)/(k delta F), with k by the paper's eq. 7 from
Table 1's dimensions (below), not the package's own prediction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from designer.checks.montecarlo import grid, simulate
from shared_inputs import montecarlo_prototype as prototype

DRAWS = 100_000
SAMPLING = 1 / math.sqrt(2 * DRAWS)  # relative 1-sigma scatter of a sample standard deviation

# k = V_s G g n y / (4 E I) (paper eq. 7) for the examples' electronics (5 V, gain 1000, G = 2.0,
# half bridges: n = 2) and the catalogue's E (2024-T3 73.1 GPa, 6061-T6 68.9 GPa). Prototype B:
# 12.7 mm square, the gauges over 9.5 mm through-holes, I = b (h^3 - d_h^3)/12 at the gauge,
# y = h/2. Prototype C: a 12.7 x 1.65 mm tube, I = pi (D^4 - (D - 2t)^4)/64, y = D/2.
I_B = 12.7e-3 * ((12.7e-3) ** 3 - (9.5e-3) ** 3) / 12
I_C = math.pi * ((12.7e-3) ** 4 - (12.7e-3 - 2 * 1.65e-3) ** 4) / 64
K_B = 5 * 2.0 * 1000 * 2 * (12.7e-3 / 2) / (4 * 73.1e9 * I_B)
K_C = 5 * 2.0 * 1000 * 2 * (12.7e-3 / 2) / (4 * 68.9e9 * I_C)


def closed_form_sigma(k, d, sigma_v, force, position):
    """(sigma_F, sigma_x) for two equal stations d = (d1, d2) (paper eqs. 24, 35, 36)."""
    delta = d[1] - d[0]
    force, position = np.asarray(force), np.asarray(position)
    sigma_x = sigma_v * np.hypot(position - d[0], position - d[1]) / (k * delta * force)
    return math.sqrt(2) * sigma_v / (k * delta), sigma_x


@pytest.fixture(scope="module")
def prototype_b(examples):
    """Section 4.3: 7 loads 200-2000 g x 7 positions 150-450 mm, 1e5 draws, 1.3 mV, bridges 80 mm apart."""
    spec, k, d, forces, positions = prototype(examples, "prototype-b")
    return spec, simulate(k, d, spec.sigma_v, forces, positions, draws=DRAWS, seed=11)


def test_the_grid_is_the_papers(prototype_b):
    spec, res = prototype_b
    assert len(res.force) == 49 and res.draws == DRAWS
    assert sorted(set(np.round(res.force / 9.80665e-3, 6))) == pytest.approx([200, 500, 800, 1100, 1400, 1700, 2000])
    assert sorted(set(np.round(res.position * 1e3, 6))) == pytest.approx([150, 200, 250, 300, 350, 400, 450])
    assert spec.sigma_v == pytest.approx(1.3e-3, rel=1e-12)


def test_analytic_sigma_within_2_percent_of_monte_carlo(prototype_b):
    # Issue 2 acceptance, over the whole 7 x 7 grid, force and position, against the closed form
    # with Prototype B's stations, 20 and 100 mm (Table 1).
    _, res = prototype_b
    sf, sx = closed_form_sigma(K_B, (0.020, 0.100), 1.3e-3, res.force, res.position)
    np.testing.assert_allclose(res.sigma_force_mc, sf, rtol=0.02)
    np.testing.assert_allclose(res.sigma_position_mc, sx, rtol=0.02)
    # the package's own analytic sigma is that closed form (the same algebra: rounding only)
    np.testing.assert_allclose(res.sigma_force, sf, rtol=1e-9)
    np.testing.assert_allclose(res.sigma_position, sx, rtol=1e-9)
    assert res.worst_ratio < 0.02
    # Both estimates are unbiased to well within their spread (the means are not stored; the
    # mean absolute error is, and for a Gaussian it is sqrt(2/pi) sigma -- MODEL.md section 3;
    # 1.5 % covers its own sampling scatter, 0.3 %, and the x estimate's slight skew).
    np.testing.assert_allclose(res.mean_abs_force_error * res.force, math.sqrt(2 / math.pi) * sf, rtol=0.015)
    np.testing.assert_allclose(res.mean_abs_position_error * res.position, math.sqrt(2 / math.pi) * sx, rtol=0.015)


def test_force_error_ignores_position_and_falls_with_load(prototype_b):
    # Paper Fig. 16 and eq. 35: the force error does not depend on the position and is
    # inversely proportional to the load. Rows: forces, columns: positions. sigma_F is the same
    # at all 49 points, so the Monte Carlo values may differ by sampling only (0.22 % each; a
    # spread of 1.5 % is 6.8 of those).
    _, res = prototype_b
    sf = res.sigma_force_mc.reshape(7, 7)
    assert np.ptp(sf / sf.mean(), axis=None) < 1.5e-2
    assert np.all(np.ptp(res.sigma_force.reshape(7, 7), axis=1) == 0)  # analytic: exactly constant
    relative = res.mean_abs_force_error.reshape(7, 7)
    forces = res.force.reshape(7, 7)[:, 0]
    assert np.all(np.diff(relative.mean(axis=1)) < 0)
    np.testing.assert_allclose(relative.mean(axis=1) * forces, (relative.mean(axis=1) * forces).mean(), rtol=0.015)


def test_position_error_rises_with_position(prototype_b):
    # Paper Fig. 17 and eq. 36: "Higher positions exhibited higher errors than lower positions",
    # absolute and relative, at every load; sigma_x ~ sqrt((x-d1)^2 + (x-d2)^2)/F rises for
    # x > (d1^2 + d2^2)/(d1 + d2) = 87 mm, and its relative form too. Adjacent grid columns
    # differ by at least 8 % in theory, far above the 0.22 % sampling scatter.
    _, res = prototype_b
    sx = res.sigma_position_mc.reshape(7, 7)
    rel = res.mean_abs_position_error.reshape(7, 7)
    assert np.all(np.diff(sx, axis=1) > 0)
    assert np.all(np.diff(rel, axis=1) > 0)
    assert np.all(np.diff(sx, axis=0) < 0)  # and falls with the load
    analytic = closed_form_sigma(K_B, (0.020, 0.100), 1.3e-3, res.force, res.position)[1].reshape(7, 7)
    assert np.min(np.diff(analytic, axis=1) / analytic[:, :-1]) > 0.08


def test_doubling_the_spacing_halves_the_force_error(examples, prototype_b):
    # Paper Fig. 13 and section 4.3: delta = 40 mm (prototype-b-inner) against 80 mm.
    # sigma_F = sqrt(2) sigma_V/(k delta): the Monte Carlo ratio is 2 up to sampling scatter
    # of both runs (0.3 %); 2 % as in the acceptance. A different seed keeps the runs independent.
    _, outer = prototype_b
    spec, k, d, forces, positions = prototype(examples, "prototype-b-inner")
    assert d[1] - d[0] == pytest.approx(0.040)
    inner = simulate(k, d, spec.sigma_v, forces, positions, draws=DRAWS, seed=12)
    np.testing.assert_allclose(inner.sigma_force_mc / outer.sigma_force_mc, 2.0, rtol=0.02)
    assert np.all(inner.sigma_position_mc > 1.9 * outer.sigma_position_mc)


@pytest.mark.parametrize("angle_deg", [30.0, 75.0])
def test_biaxial_spreads_match_the_analytic_ones(examples, angle_deg):
    # Prototype C (two half bridges per axis, Table 1). Per axis the force has sigma_F; the
    # magnitude's spread is sigma_F, the angle's sigma_F/|F| and the position's that of one
    # axis at F = |F| (linear propagation through |F| = hypot(Fy, Fz), theta = atan2,
    # x = (Fy z1y + Fz z1z)/|F|^2). sigma_F/|F| is at most 2.9 % here, so the nonlinear terms
    # stay below ~0.2 %; 3 % leaves 13 sampling sigmas. A 4 x 4 grid keeps the test fast.
    spec, k, d, _, _ = prototype(examples, "prototype-c")
    forces, positions = grid(spec.load.force_min, spec.load.force_max, spec.load.position_min,
                             spec.load.position_max, 4, 4)
    res = simulate(k, d, spec.sigma_v, forces, positions, draws=DRAWS, seed=5, angle=math.radians(angle_deg))
    # MODEL.md section 3, two equal stations at 20 and 70 mm (Table 1), k from eq. 7 (K_C)
    sigma_f, sigma_x = closed_form_sigma(K_C, (0.020, 0.070), 1.3e-3, forces, positions)
    np.testing.assert_allclose(res.sigma_force, sigma_f, rtol=1e-12)
    np.testing.assert_allclose(res.sigma_angle, sigma_f / forces, rtol=1e-12)
    np.testing.assert_allclose(res.sigma_position, sigma_x, rtol=1e-12)
    np.testing.assert_allclose(res.sigma_force_mc, sigma_f, rtol=0.03)
    np.testing.assert_allclose(res.sigma_angle_mc, sigma_f / forces, rtol=0.03)
    np.testing.assert_allclose(res.sigma_position_mc, sigma_x, rtol=0.03)
    assert res.worst_ratio < 0.03


def test_more_draws_than_one_batch(examples):
    # simulation.CHUNK bounds memory; 300 000 draws span two batches that must be joined.
    # Sampling scatter 1/sqrt(6e5) = 0.13 %; 1 % is 7.7 of those.
    from designer.checks import montecarlo as simulation

    spec, k, d, _, _ = prototype(examples, "prototype-b")
    draws = simulation.CHUNK + 50_000
    res = simulate(k, d, spec.sigma_v, np.array([2.0]), np.array([0.3]), draws=draws, seed=9)
    assert res.draws == draws
    sf, sx = closed_form_sigma(K_B, (0.020, 0.100), 1.3e-3, [2.0], [0.3])
    np.testing.assert_allclose(res.sigma_force_mc, sf, rtol=0.01)
    np.testing.assert_allclose(res.sigma_position_mc, sx, rtol=0.01)
