"""The plots' numbers against the paper: the operating region (its Fig. 3, eqs. 13-22), the
voltage isolines (Fig. 2, eqs. 6 and 11-12) and the error maps (Figs. 13-17, eqs. 24, 35, 36,
section 5.5).

Reference: Noh et al. 2025 (shared/reference/noh2025-force-position-cantilever.txt), with
MODEL.md sections 2-3 for the closed forms. Fixtures (tests/data): ``plot_prototype_b.json`` and
``plot_prototype_c.json`` are ``fpdesign evaluate examples/prototype-b.yaml`` and
``examples/prototype-c.yaml``: Prototype B is a 2024-T3 12.7 x 12.7 mm bar with 9.5 mm
through-holes, half bridges at 20 and 100 mm, 200-2000 g at 150-450 mm, sigma_V = 1.3 mV (paper
section 4.3); 5 V and a gain of 1000 are assumed (the paper gives neither).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from designer.model import estimator
from designer.outputs import plots
from designer.outputs.plots import common

G0 = 9.80665  # standard gravity, m/s^2 (the paper's loads are masses)


def prototype_b_closed_form():
    """Prototype B from its dimensions alone (MODEL.md sections 2-3, the paper's eqs. 3 and 7)."""
    b = h = 0.0127
    d_h = 0.0095
    E = 73.1e9
    I_s = b * (h ** 3 - d_h ** 3) / 12          # net section through the hole
    y_g = h / 2
    k = 5.0 * 2.0 * 1000.0 * 2 * y_g / (4 * E * I_s)   # V_s G g n y_g / (4 E I_s)
    return {"I_s": I_s, "I": b * h ** 3 / 12, "y_g": y_g, "k": k, "E": E, "d": (0.02, 0.10),
            "x": (0.15, 0.45), "F": (0.2 * G0, 2.0 * G0), "sigma_v": 1.3e-3, "eps_max": 1.5e-3,
            "min_snr": 5.0, "d_h": d_h, "allowable": 345e6 / 1.5}


# ----------------------------------------------------------------------------- fixtures

def test_fixture_b_matches_the_closed_form_sensitivity_and_strain(proto_b):
    """The fixture's k_i and eps_1 equal eq. 7 and eq. 3 with I_s = b(h^3 - d_h^3)/12."""
    cf = prototype_b_closed_form()
    pred = proto_b["predicted"]
    assert pred["sensitivity"] == pytest.approx([cf["k"], cf["k"]], rel=1e-9)
    eps_1 = cf["F"][1] * (cf["x"][1] - cf["d"][0]) * cf["y_g"] / (cf["E"] * cf["I_s"])
    assert pred["gauge_strain"][0] == pytest.approx(eps_1, rel=1e-9)
    assert pred["noise_voltage"] == pytest.approx(cf["sigma_v"], rel=1e-12)


def test_fixture_c_matches_the_tube_closed_form(proto_c):
    """Prototype C: I = pi (D^4 - (D - 2t)^4)/64, y_g = D/2, E = 68.9 GPa (MODEL.md section 2)."""
    D, t, E = 0.0127, 0.00165, 68.9e9
    I = math.pi * (D ** 4 - (D - 2 * t) ** 4) / 64
    k = 5.0 * 2.0 * 1000.0 * 2 * (D / 2) / (4 * E * I)
    assert proto_c["design"]["axes"] == 2
    assert proto_c["predicted"]["sensitivity"] == pytest.approx([k, k], rel=1e-9)


# ----------------------------------------------------------------------------- operating region

def test_operating_region_corners_equal_the_papers_closed_forms(proto_b):
    """Upper corner from the strain limit (eqs. 13-14), lower from the smallest signal (eqs. 15-17),
    force ratio by eq. 21 and by eq. 22 in the paper's a, L, delta."""
    cf = prototype_b_closed_form()
    region = plots.operating_region(proto_b)
    (d1, d2), (x_min, x_max) = cf["d"], cf["x"]
    m_max = cf["eps_max"] * cf["E"] * cf["I_s"] / cf["y_g"]   # eq. 13 with I at the gauge
    m_min = cf["min_snr"] * cf["sigma_v"] / cf["k"]           # eqs. 15-16: V_min = k M_min
    assert region.governing.name == "gauge_strain"
    assert region.moment_max == pytest.approx(m_max, rel=1e-8)
    assert region.moment_min == pytest.approx(m_min, rel=1e-8)
    assert region.force_max_allowed == pytest.approx(m_max / (x_max - d1), rel=1e-8)   # eq. 14
    assert region.force_min_allowed == pytest.approx(m_min / (x_min - d2), rel=1e-8)   # eq. 16
    a, L, delta = x_min - d2, x_max - x_min, d2 - d1
    r_eps = m_max / m_min                                                             # eq. 20
    assert region.strain_ratio == pytest.approx(r_eps, rel=1e-8)
    assert region.force_ratio == pytest.approx(r_eps * (x_min - d2) / (x_max - d1), rel=1e-8)  # eq. 21
    assert region.force_ratio == pytest.approx(r_eps * a / (a + L + delta), rel=1e-8)           # eq. 22
    assert region.force_ratio == pytest.approx(region.force_max_allowed / region.force_min_allowed, rel=1e-12)
    # by hand: 21.76 N m / 0.43 m = 50.6 N; 0.01886 N m / 0.05 m = 0.377 N; R_F = 134
    assert region.force_max_allowed == pytest.approx(50.6, rel=2e-3)
    assert region.force_min_allowed == pytest.approx(0.377, rel=2e-3)
    assert region.force_ratio == pytest.approx(134.2, rel=2e-3)


def test_stress_isolines_equal_the_beam_formula(proto_b):
    """Root: sigma = F x (h/2)/I; hole edge at d1 - d_h/2: sigma = F (x - s)(h/2)/I_s (MODEL.md 4)."""
    cf = prototype_b_closed_form()
    region = plots.operating_region(proto_b)
    limits = {lim.name: lim for lim in region.upper}
    x = np.array([0.15, 0.3, 0.45])
    root = cf["allowable"] * cf["I"] / (cf["y_g"] * x)
    edge = cf["d"][0] - cf["d_h"] / 2
    hole = cf["allowable"] * cf["I_s"] / (cf["y_g"] * (x - edge))
    np.testing.assert_allclose(limits["stress_root"].force(x), root, rtol=1e-8)
    np.testing.assert_allclose(limits["stress_feature"].force(x), hole, rtol=1e-8)


def test_error_map_equals_the_two_station_closed_form(proto_b):
    """MODEL.md section 3: sigma_F = sqrt(2) sigma_V/(k delta), sigma_x = sigma_V
    sqrt((x-d1)^2 + (x-d2)^2)/(k delta F) for two equal stations (the paper's eqs. 24, 35, 36)."""
    cf = prototype_b_closed_form()
    m = plots.error_map(proto_b, n=9)
    k, (d1, d2), sv = cf["k"], cf["d"], cf["sigma_v"]
    delta = d2 - d1
    f, x = np.meshgrid(m.force, m.position, indexing="ij")
    np.testing.assert_allclose(m.force_error, math.sqrt(2) * sv / (k * delta) / f, rtol=1e-9)
    np.testing.assert_allclose(m.position_error, sv * np.sqrt((x - d1) ** 2 + (x - d2) ** 2) / (k * delta * f),
                               rtol=1e-9)
    np.testing.assert_allclose(m.relative_position_error, m.position_error / x, rtol=1e-12)
    assert m.force[0] == pytest.approx(cf["F"][0]) and m.force[-1] == pytest.approx(cf["F"][1])
    assert m.position[0] == pytest.approx(cf["x"][0]) and m.position[-1] == pytest.approx(cf["x"][1])


def test_error_map_matches_the_papers_figures_16_and_17_qualitatively(proto_b):
    """Paper section 5.6: force error is independent of position and falls with load (Fig. 16);
    position error rises (weakly) with position and falls with load (Fig. 17)."""
    m = plots.error_map(proto_b, n=15)
    fe, pe, rel = m.force_error, m.position_error, m.relative_position_error
    assert np.ptp(fe, axis=1) == pytest.approx(0.0, abs=1e-15)      # independent of x
    assert np.all(np.diff(fe, axis=0) < 0)                           # falls with load
    assert np.all(np.diff(pe, axis=1) > 0)                           # rises with position
    assert np.all(np.diff(rel, axis=1) > 0)                          # also as % of x
    assert np.all(np.diff(pe, axis=0) < 0)                           # falls with load
    # "weakly": across the region position changes sigma_x/x by far less than load does
    assert np.ptp(np.log(rel[0])) < 0.25 * np.ptp(np.log(rel[:, -1]))


def test_error_magnitudes_match_the_papers_section_5_5(proto_b):
    """Paper section 5.5 (Prototype B, delta = 8 cm): errors below 1 % for loads above 1000 g.
    The paper reports mean absolute errors: sqrt(2/pi) sigma (MODEL.md section 3)."""
    m = plots.error_map(proto_b, force=[1.0 * G0, 2.0 * G0], position=np.linspace(0.15, 0.45, 7))
    mean_abs = math.sqrt(2 / math.pi)
    assert np.all(mean_abs * m.force_error < 0.01)
    assert np.all(mean_abs * m.relative_position_error < 0.01)
    # and a few per cent at 200 g, the smallest load of the Monte Carlo grid (paper Fig. 14)
    low = plots.error_map(proto_b, force=[0.2 * G0], position=[0.45])
    assert 0.01 < low.force_error[0, 0] < 0.05


def test_wider_gauge_spacing_lowers_both_errors(proto_b):
    """Paper Figs. 13, 16, 17: delta = 8 cm beats delta = 4 cm everywhere in the region."""
    inner = copy.deepcopy(proto_b)
    inner["design"]["stations"] = [0.02, 0.06]
    outer_map, inner_map = plots.error_map(proto_b, n=7), plots.error_map(inner, n=7)
    assert np.all(outer_map.force_error < inner_map.force_error)
    assert np.all(outer_map.position_error < inner_map.position_error)


def test_voltage_isolines_cross_at_the_example_load(proto_b):
    """Fig. 2: the isolines through the example load's readings meet at that load (eqs. 11-12)."""
    s = plots.SensorData.from_design(proto_b)
    x_e, f_e = plots.example_load(proto_b)
    assert s.position_min <= x_e <= s.position_max and s.force_min <= f_e <= s.force_max
    v_e = estimator.bridge_voltages(s.sensitivity, s.stations, s.offsets, f_e, x_e)
    f_hat, x_hat = estimator.estimate(v_e, s.sensitivity, s.stations, s.offsets)
    assert (f_hat, x_hat) == (pytest.approx(f_e, rel=1e-12), pytest.approx(x_e, rel=1e-12))
    grid = plots.bridge_map(proto_b, [f_e], [x_e])
    cf = prototype_b_closed_form()
    np.testing.assert_allclose(grid[0, 0], [cf["k"] * f_e * (x_e - d) for d in cf["d"]], rtol=1e-9)  # eq. 6

    fig = plots.plot_voltage_isolines(proto_b)
    ax = fig.axes[0]
    single = sorted(float(c.levels[0]) for c in ax.collections if hasattr(c, "levels") and len(c.levels) == 1)
    np.testing.assert_allclose(single, sorted(v_e * 1e3), rtol=1e-12)   # drawn in mV
    legend = " ".join(t.get_text() for t in ax.get_legend().get_texts())
    assert f"V1 = {common.fmt_number(v_e[0] * 1e3)} mV" in legend and "V2" in legend
    assert "(mm)" in ax.get_xlabel() and "(N)" in ax.get_ylabel()
