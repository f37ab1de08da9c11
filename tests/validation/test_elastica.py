"""The elastica (designer.elastica) against known large-deflection results and linear theory.

References:
- Bisshopp, K. E. & Drucker, D. C. (1945), "Large deflection of cantilever beams", Quarterly of
  Applied Mathematics 3(3), 272-275, Table 1: a prismatic cantilever with a vertical tip
  load, alpha = F L^2/(E I). alpha = 1: vertical deflection 0.30172 L, horizontal 0.05643 L,
  tip slope 0.46135 rad; alpha = 2: 0.49346 L and 0.16064 L.
- The same problem in closed form with elliptic integrals (Frisch-Fay, "Flexible Bars", 1962,
  ch. 3; also Gere & Timoshenko, Mechanics of Materials, large deflections of cantilevers):
  with k^2 = (1 + sin(theta_0))/2 and sin(phi_1) = 1/(k sqrt 2),
  sqrt(alpha) = K(k) - F(phi_1, k), delta_v/L = 1 - (2/sqrt(alpha)) (E(k) - E(phi_1, k)),
  X_tip/L = sqrt(2 sin(theta_0)/alpha). Written out independently below with scipy.special.
- Small loads: Euler-Bernoulli (Gere & Goodno, Mechanics of Materials, Appendix H):
  delta_v/L = alpha/3; the shortening is the integral of w'^2/2, alpha^2/15 for a tip load.
- Prototype A: Noh et al. 2025 (shared/reference), Tables 1-2 and section 6: 6061-T6
  50 x 3.18 mm, 800 mm, up to 2000 g at 650 mm; the beam "deflected 26.5 % of its length".
"""

from __future__ import annotations

import json
import math

import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipeinc, ellipk, ellipkinc

from designer.checks import elastica
from designer import model
from designer.result.designfile import rebuild
from designer.result.evaluation import evaluate, fixed_design
from designer.result.record import build_record
from designer.spec.reader import load_spec

G0 = 9.80665  # m/s^2, standard gravity: the paper hangs masses


def elliptic_tip_load(alpha: float) -> tuple[float, float, float]:
    """(delta_v/L, delta_h/L, theta_0) of a prismatic cantilever with a vertical tip load."""
    def mismatch(theta0):
        m = (1 + math.sin(theta0)) / 2
        phi1 = math.asin(1 / math.sqrt(2 * m))
        return ellipk(m) - ellipkinc(phi1, m) - math.sqrt(alpha)

    theta0 = brentq(mismatch, 1e-12, math.pi / 2 - 1e-12, xtol=1e-15)
    m = (1 + math.sin(theta0)) / 2
    phi1 = math.asin(1 / math.sqrt(2 * m))
    dv = 1 - 2 / math.sqrt(alpha) * (ellipe(m) - ellipeinc(phi1, m))
    return dv, 1 - math.sqrt(2 * math.sin(theta0) / alpha), theta0


def record_from(spec_path) -> dict:
    spec = load_spec(spec_path)
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    return json.loads(json.dumps(build_record("feasible", spec, ev)))


# ----------------------------------------------------------------- prismatic cantilever

@pytest.mark.parametrize("alpha, vertical, horizontal, angle", [
    (1.0, 0.30172, 0.05643, 0.46135),   # Bisshopp & Drucker 1945, Table 1
    (2.0, 0.49346, 0.16064, None),
])
def test_bisshopp_drucker_table(alpha, vertical, horizontal, angle):
    # 0.5 % as the issue asks; the table gives 5 digits, so it is met by a wide margin.
    dv, dh, theta = elastica.prismatic_tip_load(alpha)
    assert dv == pytest.approx(vertical, rel=5e-3)
    assert dh == pytest.approx(horizontal, rel=5e-3)
    if angle is not None:
        assert theta == pytest.approx(angle, rel=5e-3)


@pytest.mark.parametrize("alpha", [0.3, 1.0, 3.0, 8.0])
def test_shooting_agrees_with_elliptic_integrals(alpha):
    # Two independent methods of the same exact problem: they agree to the integration
    # tolerance (1e-11); 1e-6 leaves room for the root finders on both sides.
    got = elastica.prismatic_tip_load(alpha)
    want = elliptic_tip_load(alpha)
    assert got == pytest.approx(want, rel=1e-6, abs=1e-9)


def test_the_elastica_is_computed_up_to_three_free_lengths_of_linear_deflection(examples, tmp_path):
    """Bisshopp & Drucker's load parameter alpha = F L^2 / EI gives linear theory's tip deflection
    alpha/3 lengths: at the reach of 3 lengths (alpha 9) the exact tip angle, by the elliptic
    integrals, is past 80 degrees (the beam hangs from its clamp) and the shooting method still
    agrees with it. Beyond, no elastica is computed: Prototype A's strip at 0.5 mm thick (linear
    theory 84 lengths) had the shooting method follow curled branches, and a modulus of 1 Pa
    integrated for hours."""
    from designer.result.pipeline import ELASTICA_REACH, evaluate_fixed

    alpha = 3 * ELASTICA_REACH
    exact = elliptic_tip_load(alpha)
    assert math.degrees(exact[2]) > 80
    assert elastica.prismatic_tip_load(alpha) == pytest.approx(exact, rel=1e-6, abs=1e-9)

    text = (examples / "prototype-a.yaml").read_text(encoding="utf-8")
    assert "height: 3.18 mm" in text
    (tmp_path / "strip.yaml").write_text(text.replace("height: 3.18 mm", "height: 0.5 mm"), encoding="utf-8")
    record = evaluate_fixed(load_spec(tmp_path / "strip.yaml")).record
    ratio = record["predicted"]["deflection"] / record["design"]["length"]
    assert ratio == pytest.approx(83.6, rel=1e-2)   # (3.18 / 0.5)^3 x Prototype A's 0.325
    assert "large_deflection" not in record
    assert any("no elastica is computed" in m for m in record["messages"])


def test_small_load_is_linear_theory():
    alpha = 1e-3
    dv, dh, theta = elastica.prismatic_tip_load(alpha)
    # Euler-Bernoulli: alpha/3 and a slope of alpha/2; the elastica differs at O(alpha^2).
    assert dv == pytest.approx(alpha / 3, rel=1e-3)
    assert theta == pytest.approx(alpha / 2, rel=1e-3)
    # second order: shortening = integral of w'^2/2 = alpha^2/15
    assert dh == pytest.approx(alpha ** 2 / 15, rel=1e-2)


def test_load_inside_the_span_with_piecewise_rigidity_matches_the_beam_model_for_small_loads():
    # A beam with two soft stretches (a quarter of EI) and the load short of the free end:
    # for a small load the elastica must give the beam model's unit-load integral (model.py).
    g = model.Geometry(section="rectangle", feature="hole", stations=(0.05, 0.15), length=0.4,
                       width=0.01, height=0.01, hole=0.008)
    props = model.section_properties(g)
    E = 70e9
    segs = model.rigidity_segments(g, props, E)
    assert [s[2] for s in segs] == pytest.approx([E * props.I, E * props.I_s, E * props.I, E * props.I_s, E * props.I])
    force, x = 1e-3, 0.3
    e = elastica.solve_elastica(force, x, g.length, segs)
    linear = model.tip_deflection(g, props, E, force, x)
    # relative nonlinearity ~ (w/L)^2 ~ 1e-10 here; 1e-6 is the integration tolerance's room
    assert e.tip_vertical == pytest.approx(float(linear), rel=1e-6)


def test_the_free_end_beyond_the_load_stays_straight():
    e = elastica.solve_elastica(2.0, 0.5, 1.0, 1.0, stations=(0.25, 0.75, 1.0))
    # beyond the load the moment is zero: the slope is the load point's, the end lies on a line
    assert e.station_angle[1] == pytest.approx(e.tip_angle, abs=1e-12)
    assert e.station_drop[2] == pytest.approx(e.tip_vertical, rel=1e-12)
    assert e.moment(1) == 0.0 and e.moment(0) > 0
    # the overhang is the tip-loaded cantilever of length 0.5 (alpha = 2 * 0.5^2 = 0.5) carried on
    dv, dh, theta = elliptic_tip_load(0.5)
    assert e.tip_vertical == pytest.approx(0.5 * dv + 0.5 * math.sin(theta), rel=1e-6)
    assert e.tip_horizontal == pytest.approx(0.5 * dh + 0.5 * (1 - math.cos(theta)), rel=1e-6)


@pytest.fixture(scope="module")
def prototype_a(examples):
    return record_from(examples / "prototype-a.yaml")


def test_prototype_a_linear_theory_elastica_and_the_paper(prototype_a):
    r = elastica.large_deflection(prototype_a)
    # Linear theory in closed form (Gere & Goodno, App. H): w(l) = F x^2 (3l - x)/(6EI)
    spec, design = rebuild(prototype_a)
    E = design.material.E
    I = 0.050 * 0.00318 ** 3 / 12
    F, x, ell = 2.0 * G0, 0.650, 0.800
    linear = F * x ** 2 * (3 * ell - x) / (6 * E * I)
    assert r.linear_deflection == pytest.approx(linear, rel=1e-9)
    assert r.linear_ratio == pytest.approx(0.327, abs=0.001)     # the issue: "about 33 %"
    # The elastica: the loaded 650 mm is a tip-loaded prismatic cantilever (no features),
    # the last 150 mm a straight overhang: exact by elliptic integrals.
    alpha = F * x ** 2 / (E * I)
    dv, dh, theta = elliptic_tip_load(alpha)
    assert r.deflection == pytest.approx(x * dv + (ell - x) * math.sin(theta), rel=1e-6)
    assert r.load_deflection == pytest.approx(x * dv, rel=1e-6)
    assert r.shortening == pytest.approx(x * dh + (ell - x) * (1 - math.cos(theta)), rel=1e-6)
    # 30.0 % at the free end: less than linear theory's 32.7 %, still above the 26.5 % measured
    assert r.ratio == pytest.approx(0.300, abs=0.001)
    assert 0.265 < r.ratio < r.linear_ratio
    assert r.applies


def test_prototype_a_nonlinearity_of_a_linear_calibration(prototype_a):
    r = elastica.large_deflection(prototype_a)
    # the moments at the gauges fall short of F (x - d) by the beam's pull-in
    assert all(0.9 < m < 1.0 for m in r.moment_ratio)
    assert r.moment_ratio[1] < r.moment_ratio[0]
    # A full bridge reads the moment only: a 2-parameter-per-bridge linear model cannot follow
    # the bending, so position errors of the order of the paper's 2.11 % (Table 4) remain.
    assert 0.005 < r.position_error_mean < 0.04
    assert r.position_error_max > r.position_error_rms > 0
    assert r.force_error_max > r.force_error_rms > 0


def test_a_stiff_beam_has_no_large_deflection_nonlinearity(prototype_a):
    stiff = json.loads(json.dumps(prototype_a))
    stiff["design"]["material_properties"]["E"] *= 1e4
    r = elastica.large_deflection(stiff)
    assert not r.applies
    # errors scale with the square of the deflection: 1e-8 of Prototype A's
    assert r.force_error_max < 1e-7
    assert r.position_error_max < 1e-7 * 0.65
    assert r.moment_ratio == pytest.approx([1.0, 1.0], abs=1e-6)


def test_summary_and_json(prototype_a):
    r = elastica.large_deflection(prototype_a)
    text = r.summary()
    assert "30.0% of the free length" in text and "linear theory 261.8 mm, 32.7%" in text
    record = r.as_dict()
    json.dumps(record, allow_nan=False)
    assert record["deflection_ratio"] == pytest.approx(r.ratio)
    assert record["applies"] is True


def test_bending_errors_past_the_targets_are_said_when_the_targets_hold_the_noise_alone(examples, tmp_path):
    """Prototype A bends 30 % of its length: calibrated linearly, the bending alone leaves
    position errors up to 20.4 mm (docs/model.md §8). Against a 10 mm target, judged on the
    noise alone without an environment, the design was reported as meeting its targets with no
    word of it; the message says so and what takes the bending in (an environment's budget)."""
    from designer.result.pipeline import evaluate_fixed

    text = (examples / "prototype-a.yaml").read_text(encoding="utf-8")
    assert "position_error: 4 %" in text and "environment" not in text
    (tmp_path / "a.yaml").write_text(text.replace("position_error: 4 %", "position_error: 10 mm"), encoding="utf-8")
    record = evaluate_fixed(load_spec(tmp_path / "a.yaml")).record
    worst = record["large_deflection"]["position_error_max"]
    assert worst == pytest.approx(20.4e-3, abs=0.1e-3)
    said = [m for m in record["messages"] if m.startswith("large deflection: the bending alone leaves")]
    assert said == [f"large deflection: the bending alone leaves position errors up to {worst * 1e3:.2f} mm against "
                    "the 10 mm target; the targets are judged on the noise alone without environment: its error "
                    "budget takes in the lever arm's shortening (docs/model.md §13); or a smaller "
                    "limits.max_deflection keeps the beam linear"]


def test_linear_theory_s_figure_takes_the_wire_channels_as_the_elastica_does(examples):
    """The summary's "linear theory" deflection and the elastica's must meet as the load falls
    (Euler-Bernoulli, Gere & Goodno App. H: the relative difference is of order (w/L)^2, here
    (0.8/115)^2 ~ 5e-5), both on the same EI(s). The gripper finger's Ø7.88 mm bar with 1.55 mm
    flats and the default wire channels: the linear figure had left the channels out, 1.7 %
    short of the elastica's own small-deflection drop."""
    import yaml

    from designer.spec.reader import parse_spec

    raw = yaml.safe_load((examples / "gripper-finger.yaml").read_text(encoding="utf-8"))
    raw["design"] = {"material": "Ti-6Al-4V", "section": {"kind": "round", "diameter": "7.88 mm"},
                     "stations": ["9.45 mm", "30.55 mm"],
                     "feature": {"kind": "pocket", "depth": "1.55 mm", "length": "8.9 mm"}, "length": "115 mm"}
    spec = parse_spec(raw)
    ev = evaluate(fixed_design(spec), spec)
    assert ev.design.geometry.channel_width > 0     # the channels are there
    r = elastica.large_deflection(json.loads(json.dumps(build_record("feasible", spec, ev))))
    assert r.deflection / 0.115 < 0.01
    assert r.linear_deflection == pytest.approx(r.deflection, rel=2e-4)
