"""The beam model (MODEL.md sections 2-4) against textbook closed forms and the paper's eqs. 4 and 7.

References:
- Cantilever tip deflection and root stress: Gere & Goodno, Mechanics of Materials, 8th ed.,
  Appendix H (Table H-1, case 1 and case 5) -- w_tip = F L^3/(3EI); for a load at x on a
  beam of length l, w(l) = F x^2 (3l - x)/(6EI); sigma = M c/I, so eps_root = 6 F L/(E b h^2).
- Piecewise EI (features): w'' = M(s)/(E I(s)) integrated with scipy's ODE solver.
- Clamped-free natural frequency: the first root of 1 + cos(b) cosh(b) = 0 (Euler-Bernoulli;
  Blevins, Formulas for Natural Frequency and Mode Shape, Table 8-1).
- Bridge sensitivity and output: Noh et al. 2025 (shared/reference) eqs. 4 and 7.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from designer.model import estimator
from designer.model.corrections import Corrections
from designer import model
from shared_inputs import E_AL, MM, RHO_AL, make_spec, material, rectangle

PLAIN = Corrections({})


def test_tip_deflection_of_a_load_at_the_free_end():
    # Gere & Goodno Table H-1 case 1: w = F L^3 / (3 E I). Plain section (feature none keeps
    # I_s = I), load at x = l. Same arithmetic, so rel 1e-12 (rounding only).
    b, h, ell, force = 20 * MM, 4 * MM, 0.5, 7.0
    g = rectangle(b, h, length=ell)
    sp = model.section_properties(g)
    I = b * h ** 3 / 12
    assert sp.I == pytest.approx(I, rel=1e-12)
    assert model.tip_deflection(g, sp, E_AL, force, ell) == pytest.approx(force * ell ** 3 / (3 * E_AL * I),
                                                                           rel=1e-12)


@pytest.mark.parametrize("x_over_l", [0.1, 0.35, 0.8, 1.0])
def test_tip_deflection_of_a_load_anywhere(x_over_l):
    # Gere & Goodno Table H-1 case 5 carried to the free end: w(x) + theta(x)(l - x) with
    # w(x) = F x^3/(3EI), theta(x) = F x^2/(2EI): F x^2 (3l - x)/(6EI).
    b, h, ell, force = 20 * MM, 4 * MM, 0.5, 7.0
    x = x_over_l * ell
    g = rectangle(b, h, length=ell)
    sp = model.section_properties(g)
    I = b * h ** 3 / 12
    expected = force * x ** 2 * (3 * ell - x) / (6 * E_AL * I)
    assert model.tip_deflection(g, sp, E_AL, force, x) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("feature, extra", [("pocket", {"depth": 1.2 * MM}), ("hole", {"hole": 9.5 * MM})])
def test_tip_deflection_with_features_matches_integrating_the_curvature(feature, extra):
    # Independent check of the piecewise-EI formula: integrate w'' = M(s)/(E I(s)) from the
    # clamp (w = w' = 0) with an ODE solver, interval by interval so that every jump of I(s)
    # falls on an interval end, then carry the slope to the free end. rtol 1e-11 in the
    # solver; the comparison at 1e-8 leaves room for its accumulated error only.
    b = h = 12.7 * MM
    ell, x, force = 0.45, 0.40, 19.6
    g = rectangle(b, h, feature=feature, stations=(0.02, 0.10), length=ell, **extra)
    sp = model.section_properties(g)
    assert sp.I_s < sp.I  # the feature does soften the beam, or the test proves nothing
    half = g.feature_length / 2

    def stiffness(s):
        return E_AL * (sp.I_s if any(abs(s - d) < half for d in g.stations) else sp.I)

    edges = sorted({0.0, x, *(d - half for d in g.stations), *(d + half for d in g.stations)})
    state = np.zeros(2)  # w, theta
    for a, c in zip(edges, edges[1:]):
        mid_stiffness = stiffness((a + c) / 2)
        sol = integrate.solve_ivp(lambda s, y: [y[1], force * (x - s) / mid_stiffness], (a, c), state,
                                  rtol=1e-11, atol=1e-16, method="DOP853")
        state = sol.y[:, -1]
    w_tip = state[0] + state[1] * (ell - x)
    assert model.tip_deflection(g, sp, E_AL, force, x) == pytest.approx(w_tip, rel=1e-8)


def test_root_and_gauge_strain_of_a_plain_rectangle():
    # Gere & Goodno: sigma = M c / I with c = h/2, I = b h^3/12, so eps = 6 M/(E b h^2) with
    # M = F L at the root (L = x_max) and M = F (x - d_i) at a gauge on the plain surface
    # (MODEL.md eq. 3). The model's expressions are algebraically equal: rel 1e-12.
    spec = make_spec()
    b, h = 25 * MM, 5 * MM
    g = rectangle(b, h, stations=(0.03, 0.07), length=0.305)
    a = model.analyse(g, material(), spec, table=PLAIN)   # beam theory itself, without the 3-D corrections
    f, x = spec.load.force_max, spec.load.position_max
    assert a.stress_root / E_AL == pytest.approx(6 * f * x / (E_AL * b * h ** 2), rel=1e-12)
    for strain, d in zip(a.gauge_strain, g.stations):
        assert strain == pytest.approx(6 * f * (x - d) / (E_AL * b * h ** 2), rel=1e-12)


def test_bridge_sensitivity_is_the_papers_eq_7_and_turns_strain_into_volts():
    # Noh et al. eq. 7: k = V_s G g n y / (4 E I); eq. 4: V = V_s g G n eps / 4.
    spec = make_spec()
    g = rectangle(25 * MM, 5 * MM, stations=(0.03, 0.07), length=0.305)
    a = model.analyse(g, material(), spec, table=PLAIN)   # beam theory itself, without the 3-D corrections
    e, G, n = spec.electronics, spec.gauge.factor, 2
    y, I = 2.5 * MM, 25 * MM * (5 * MM) ** 3 / 12
    assert a.sensitivity == pytest.approx(e.excitation * G * e.gain * n * y / (4 * E_AL * I), rel=1e-12)
    f, x = spec.load.force_max, spec.load.position_max
    volts = estimator.bridge_voltages([a.sensitivity] * 2, g.stations, [0, 0], f, x)
    for v, strain in zip(volts, a.gauge_strain):
        assert v == pytest.approx(e.excitation * e.gain * G * n * strain / 4, rel=1e-12)


def test_first_natural_frequency_uses_the_clamped_free_root():
    # Blevins Table 8-1: lambda_1 = 1.87510407, the first root of 1 + cos(b) cosh(b) = 0.
    root = optimize.brentq(lambda beta: 1 + math.cos(beta) * math.cosh(beta), 1.0, 3.0, xtol=1e-14)
    assert model.CLAMPED_FREE_ROOT == pytest.approx(root, rel=1e-9)
    spec = make_spec()
    b, h, ell = 25 * MM, 5 * MM, 0.305
    a = model.analyse(rectangle(b, h, length=ell), material(), spec)
    expected = root ** 2 / (2 * math.pi) * math.sqrt(E_AL * (b * h ** 3 / 12) / (RHO_AL * b * h * ell ** 4))
    assert a.natural_frequency == pytest.approx(expected, rel=1e-9)


def test_mass_removes_every_feature():
    # MODEL.md section 4: rho (A l - volume of all features). A pocket of length l_p removes
    # (A - A_s) l_p per station; a through-hole removes pi d^2/4 times the width.
    spec = make_spec()
    b, h, ell = 12.7 * MM, 12.7 * MM, 0.45
    pocket = rectangle(b, h, feature="pocket", depth=1.0 * MM, length=ell)
    a = model.analyse(pocket, material(), spec)
    removed = (a.props.A - a.props.A_s) * pocket.pocket_length * 2
    assert a.mass == pytest.approx(RHO_AL * (b * h * ell - removed), rel=1e-12)
    hole = rectangle(b, h, feature="hole", hole=9.5 * MM, length=ell)
    a = model.analyse(hole, material(), spec)
    assert a.mass == pytest.approx(RHO_AL * (b * h * ell - 2 * math.pi * (9.5 * MM) ** 2 / 4 * b), rel=1e-12)
