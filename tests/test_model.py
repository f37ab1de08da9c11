"""The beam model (MODEL.md sections 2-4) against closed forms and numerical integration,
and the estimator (section 3) against the paper's eqs. 11-12.

References:
- Cantilever tip deflection and root stress: Gere & Goodno, Mechanics of Materials, 8th ed.,
  Appendix H (Table H-1, case 1 and case 5) -- w_tip = F L^3/(3EI); for a load at x on a
  beam of length l, w(l) = F x^2 (3l - x)/(6EI); sigma = M c/I, so eps_root = 6 F L/(E b h^2).
- Clamped-free natural frequency: the first root of 1 + cos(b) cosh(b) = 0 (Euler-Bernoulli;
  Blevins, Formulas for Natural Frequency and Mode Shape, Table 8-1).
- Section properties: integrated numerically over the reduced cross-section (below).
- Estimation: Noh et al. 2025 eqs. 11-12 (shared/reference), written out literally below.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from designer.model import estimator
from designer import model
from designer.model import Geometry, MaterialParams
from designer.spec.reader import parse_spec

MM = 1e-3
E_AL = 70e9      # Pa, a round number: the closed forms hold for any E
RHO_AL = 2700.0  # kg/m^3


def make_spec(**overrides):
    raw = {
        "load": {"force": ["1 N", "20 N"], "position": ["100 mm", "300 mm"]},
        "electronics": {"excitation": "5 V", "gain": 500, "noise": "1 mV"},
        "bridge": "half",
    }
    raw.update(overrides)
    return parse_spec(raw)


def material(E=E_AL):
    return MaterialParams(E=E, allowable=100e6, density=RHO_AL)


def rectangle(b, h, feature="none", stations=(0.02, 0.08), length=0.4, **kw):
    return Geometry(section="rectangle", feature=feature, stations=stations, length=length,
                    width=b, height=h, gauge_length=6.9 * MM, pocket_length=8.9 * MM,
                    pocket_width=kw.pop("pocket_width", 5.5 * MM), **kw)


def circular(kind, D, feature="none", wall=None, stations=(0.02, 0.08), length=0.4, **kw):
    return Geometry(section=kind, feature=feature, stations=stations, length=length, diameter=D, wall=wall,
                    gauge_length=6.9 * MM, pocket_length=8.9 * MM, pocket_width=5.5 * MM, **kw)


# ----------------------------------------------------------------- closed-form beam results

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
    w_x, theta_x = force * x ** 3 / (3 * E_AL * I), force * x ** 2 / (2 * E_AL * I)
    expected = force * x ** 2 * (3 * ell - x) / (6 * E_AL * I)
    assert w_x + theta_x * (ell - x) == pytest.approx(expected, rel=1e-12)
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
    a = model.analyse(g, material(), spec)
    f, x = spec.load.force_max, spec.load.position_max
    assert a.stress_root / E_AL == pytest.approx(6 * f * x / (E_AL * b * h ** 2), rel=1e-12)
    for strain, d in zip(a.gauge_strain, g.stations):
        assert strain == pytest.approx(6 * f * (x - d) / (E_AL * b * h ** 2), rel=1e-12)


def test_bridge_sensitivity_is_the_papers_eq_7_and_turns_strain_into_volts():
    # Noh et al. eq. 7: k = V_s G g n y / (4 E I); eq. 4: V = V_s g G n eps / 4.
    spec = make_spec()
    g = rectangle(25 * MM, 5 * MM, stations=(0.03, 0.07), length=0.305)
    a = model.analyse(g, material(), spec)
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


# ----------------------------------------------------------------- section properties by integration
#
# Each reduced section is described only by where material is: the outer outline, the bore
# and the cut-outs (slots, flats, the hole's plane). At each height z the material is a set
# of intervals in y, whose length and int y^2 dy are exact; these are then integrated over z
# with adaptive quadrature (scipy.integrate.quad) broken at every kink of the outline. None
# of the closed forms of MODEL.md section 2 (segment areas, parallel-axis terms) is used.


def _measure(z, outline, cuts):
    """(length, int y^2 dy, largest |y|) of the material at height z."""
    material, removed = outline(z), [c for cut in cuts for c in cut(z)]
    points = sorted({p for iv in material + removed for p in iv})
    length = second = 0.0
    reach = -1.0
    for lo, hi in zip(points, points[1:]):
        mid = (lo + hi) / 2
        if any(a < mid < b for a, b in material) and not any(a < mid < b for a, b in removed):
            length += hi - lo
            second += (hi ** 3 - lo ** 3) / 3
            reach = max(reach, abs(lo), abs(hi))
    return length, second, reach


def _box(half_width, half_height):
    return lambda z: [(-half_width, half_width)] if abs(z) < half_height else []


def _disc(R):
    return lambda z: [(-math.sqrt(R * R - z * z), math.sqrt(R * R - z * z))] if abs(z) < R else []


def _above(level, y0=-1.0, y1=1.0):
    """Everything with |z| > level (a flat or the floor of a slot spanning y0..y1)."""
    return lambda z: [(y0, y1)] if abs(z) > level else []


def _sides(level, half_height=1.0):
    """Everything with |y| > level where |z| < half_height (side slots and side flats)."""
    return lambda z: [(-1.0, -level), (level, 1.0)] if abs(z) < half_height else []


def integrate_section(outline, cuts, size, kinks):
    """A, int z^2 dA, int y^2 dA, and the largest |z| and radius of the section."""
    pts = sorted({k for k in kinks if -size / 2 < k < size / 2})
    opts = dict(points=pts, limit=400, epsabs=0.0, epsrel=1e-12)
    A, errA = integrate.quad(lambda z: _measure(z, outline, cuts)[0], -size / 2, size / 2, **opts)
    Iz, errIz = integrate.quad(lambda z: z * z * _measure(z, outline, cuts)[0], -size / 2, size / 2, **opts)
    Iy, errIy = integrate.quad(lambda z: _measure(z, outline, cuts)[1], -size / 2, size / 2, **opts)
    assert errA < 1e-9 * A and errIz < 1e-9 * Iz and errIy < 1e-9 * Iy  # the quadrature converged
    zs = np.linspace(0.0, size / 2, 4001)
    rows = [(z, _measure(z, outline, cuts)) for z in zs]
    z_extreme = max(z for z, m in rows if m[0] > 0)
    r_extreme = max(math.hypot(z, m[2]) for z, m in rows if m[0] > 0)
    return A, Iz, Iy, z_extreme, r_extreme


def _cases():
    b, h = 12.0 * MM, 8.0 * MM
    sq = 12.0 * MM
    w, p = 5.5 * MM, 1.2 * MM
    D, R = 12.0 * MM, 6.0 * MM
    Dt, Rt, t = 12.7 * MM, 6.35 * MM, 2.0 * MM
    pf = 1.0 * MM          # flat depth on the round bar
    pt = 0.6 * MM          # flat depth on the tube (less than t - 1 mm)
    hole = 9.5 * MM
    chord = math.sqrt(R * R - (R - pf) ** 2)
    chord_t = math.sqrt(Rt * Rt - (Rt - pt) ** 2)
    bore = _disc(Rt - t)
    return {
        # name: (geometry, outline, cuts at the plain section, cuts at the station, size, kinks)
        "rectangle plain": (rectangle(b, h), _box(b / 2, h / 2), [], [], h, []),
        "rectangle pocket": (rectangle(b, h, "pocket", depth=p, pocket_width=w), _box(b / 2, h / 2), [],
                             [_above(h / 2 - p, -w / 2, w / 2)], h, [h / 2 - p, p - h / 2]),
        "rectangle hole": (rectangle(sq, sq, "hole", hole=hole), _box(sq / 2, sq / 2), [],
                           [lambda z: [(-1.0, 1.0)] if abs(z) < hole / 2 else []], sq, [hole / 2, -hole / 2]),
        "round plain": (circular("round", D), _disc(R), [], [], D, []),
        "round flat": (circular("round", D, "pocket", depth=pf), _disc(R), [], [_above(R - pf)], D,
                       [R - pf, pf - R]),
        "tube plain": (circular("tube", Dt, wall=t), _disc(Rt), [bore], [bore], Dt, [Rt - t, t - Rt]),
        "tube flat": (circular("tube", Dt, "pocket", wall=t, depth=pt), _disc(Rt), [bore], [bore, _above(Rt - pt)],
                      Dt, [Rt - t, t - Rt, Rt - pt, pt - Rt]),
        "biaxial square plain": (rectangle(sq, sq, axes=2), _box(sq / 2, sq / 2), [], [], sq, []),
        "biaxial square pocket": (rectangle(sq, sq, "pocket", depth=p, pocket_width=w, axes=2),
                                  _box(sq / 2, sq / 2), [],
                                  [_above(sq / 2 - p, -w / 2, w / 2), _sides(sq / 2 - p, w / 2)], sq,
                                  [sq / 2 - p, p - sq / 2, w / 2, -w / 2]),
        "biaxial round plain": (circular("round", D, axes=2), _disc(R), [], [], D, []),
        "biaxial round flat": (circular("round", D, "pocket", depth=pf, axes=2), _disc(R), [],
                               [_above(R - pf), _sides(R - pf, chord)], D, [R - pf, pf - R, chord, -chord]),
        "biaxial tube flat": (circular("tube", Dt, "pocket", wall=t, depth=pt, axes=2), _disc(Rt), [bore],
                              [bore, _above(Rt - pt), _sides(Rt - pt, chord_t)], Dt,
                              [Rt - t, t - Rt, Rt - pt, pt - Rt, chord_t, -chord_t]),
    }


CASES = _cases()


@pytest.mark.parametrize("name", list(CASES))
def test_section_properties_match_numerical_integration(name):
    # Tolerance rel 1e-7: the quadrature's own error is below 1e-9 (asserted), so any larger
    # difference is an error in the closed forms; 1e-7 is 10^4 tighter than sectionproperties'
    # own validation tolerance (1e-3) and still far above floating-point rounding.
    g, outline, plain_cuts, station_cuts, size, kinks = CASES[name]
    sp = model.section_properties(g)
    A, I, _, z_plain, r_plain = integrate_section(outline, plain_cuts, size, kinks)
    A_s, I_s, Iy_s, z_station, r_station = integrate_section(outline, station_cuts, size, kinks)
    assert sp.A == pytest.approx(A, rel=1e-7)
    assert sp.I == pytest.approx(I, rel=1e-7)
    assert sp.A_s == pytest.approx(A_s, rel=1e-7)
    assert sp.I_s == pytest.approx(I_s, rel=1e-7)
    if g.feature != "none":
        assert sp.A_s < sp.A * (1 - 1e-3)  # the cut-out is really there
    # The extreme fibre the stress check uses: the largest |z| (one axis), or the largest
    # radius (two axes: the load may point anywhere). Sampled on a 4001-point grid in z that
    # stops short of a boundary by up to one step (size/8000), hence 1.5 steps (2 on a radius).
    step = size / 8000
    if g.axes == 2:
        # Four-fold symmetry: the second moment is the same about every axis, which is what
        # lets the model use one I for any load angle.
        assert Iy_s == pytest.approx(I_s, rel=1e-7)
        assert sp.y_root == pytest.approx(r_plain, abs=2 * step)
        assert sp.y_e == pytest.approx(r_station, abs=2 * step)
    else:
        assert sp.y_root == pytest.approx(z_plain, abs=1.5 * step)
        assert sp.y_e == pytest.approx(z_station, abs=1.5 * step)


def test_flat_segment_formulas_at_their_limits():
    # MODEL.md section 2: a half disc (alpha = pi/2) has area pi R^2/2 and second moment
    # pi R^4/8 about the diameter, along its normal and across it; a full disc (alpha = pi)
    # has pi R^2 and pi R^4/4. Exact up to rounding.
    R = 0.01
    assert model.segment_area(R, math.pi / 2) == pytest.approx(math.pi * R ** 2 / 2, rel=1e-12)
    assert model.segment_inertia_normal(R, math.pi / 2) == pytest.approx(math.pi * R ** 4 / 8, rel=1e-12)
    assert model.segment_inertia_across(R, math.pi / 2) == pytest.approx(math.pi * R ** 4 / 8, rel=1e-12)
    assert model.segment_area(R, math.pi) == pytest.approx(math.pi * R ** 2, rel=1e-12)
    assert model.segment_inertia_normal(R, math.pi) == pytest.approx(math.pi * R ** 4 / 4, rel=1e-12)
    assert model.flat_half_angle(R, R) == pytest.approx(math.pi / 2, rel=1e-12)


# ----------------------------------------------------------------- symbolic and numeric agree

@pytest.mark.parametrize("name", ["rectangle pocket", "rectangle hole", "tube flat", "biaxial round flat",
                                  "biaxial square pocket"])
def test_casadi_expressions_equal_the_numeric_model(name):
    # The optimiser builds its graph from the same functions over casadi's Ops (STYLE.md
    # habit 4). Evaluated at the same point the graph must give the numeric answers; both
    # are double-precision evaluations of the same expressions, so rel 1e-10.
    casadi = pytest.importorskip("casadi")
    g = CASES[name][0]
    spec = make_spec(axes=g.axes)
    sizes = {k: getattr(g, k) for k in ("width", "height", "diameter", "wall", "depth", "hole")
             if getattr(g, k) not in (None, 0.0)}
    symbols = {k: casadi.SX.sym(k) for k in sizes}
    from dataclasses import replace

    ops = model.casadi_ops()
    sym_g = replace(g, **symbols)
    a_sym = model.analyse(sym_g, material(), spec, ops)
    lims_sym = model.limits(sym_g, a_sym, material(), spec, ops=ops)
    a_num = model.analyse(g, material(), spec)
    lims_num = model.limits(g, a_num, material(), spec)
    names = ["force_error", "position_error", "stress_root", "stress_feature", "min_signal_snr", "deflection",
             "natural_frequency", "mass", "sensitivity"]
    exprs = [getattr(a_sym, n) for n in names] + [lim.normalised for lim in lims_sym]
    f = casadi.Function("f", list(symbols.values()), [casadi.vertcat(*[casadi.SX(e) for e in exprs])])
    values = np.array(f(*sizes.values())).ravel()
    expected = [float(getattr(a_num, n)) for n in names] + [float(lim.normalised) for lim in lims_num]
    assert [lim.name for lim in lims_sym] == [lim.name for lim in lims_num]
    np.testing.assert_allclose(values, expected, rtol=1e-10, atol=1e-12)


# ----------------------------------------------------------------- estimation (MODEL.md section 3)

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


def test_predicted_sigma_for_two_equal_stations():
    # MODEL.md section 3 (compare the paper's eqs. 24, 35, 36): sigma_F = sqrt(2) sigma_V/(k delta),
    # sigma_x = sigma_V sqrt((x-d1)^2 + (x-d2)^2)/(k delta F). Exact algebra: rel 1e-12.
    k, d, sigma_v = 0.3446, (0.02, 0.10), 1.3e-3
    delta = d[1] - d[0]
    assert estimator.sigma_force([k, k], d, sigma_v) == pytest.approx(math.sqrt(2) * sigma_v / (k * delta), rel=1e-12)
    for force, x in [(1.96, 0.15), (19.6, 0.45)]:
        expected = sigma_v * math.hypot(x - d[0], x - d[1]) / (k * delta * force)
        assert estimator.sigma_position([k, k], d, sigma_v, force, x) == pytest.approx(expected, rel=1e-12)


def test_predicted_covariance_is_sigma_squared_times_inverse_normal_matrix():
    # GUM linear propagation: Cov(z) = sigma_V^2 (A^T A)^-1; sigma_x from the gradient of
    # x = z1/z2, [1/F, -x/F]. Compared with numpy's inverse at rel 1e-10.
    k, d, sigma_v, force, x = (0.3, 0.33, 0.35), (0.02, 0.06, 0.10), 1e-3, 3.0, 0.3
    A = np.column_stack([k, -np.multiply(k, d)])
    cov = sigma_v ** 2 * np.linalg.inv(A.T @ A)
    grad = np.array([1 / force, -x / force])
    assert estimator.sigma_force(k, d, sigma_v) == pytest.approx(math.sqrt(cov[1, 1]), rel=1e-10)
    assert estimator.sigma_position(k, d, sigma_v, force, x) == pytest.approx(math.sqrt(grad @ cov @ grad), rel=1e-10)


def test_prototype_b_strains_through_eq_4_then_eqs_11_12_give_the_load_back(examples):
    # The whole forward chain of the package for Prototype B (Table 1): gauge strains from the
    # beam model (eq. 3) at F_max, x_max, turned into volts by eq. 4 (V = V_s g G n eps / 4),
    # then eqs. 11-12 with the model's k (eq. 7) and balanced bridges: F and x to rel 1e-9.
    from designer.result.evaluation import evaluate, fixed_design
    from designer.spec.reader import load_spec

    spec = load_spec(examples / "prototype-b.yaml")
    ev = evaluate(fixed_design(spec).rounded(), spec)
    a, e = ev.analysis, spec.electronics
    V1, V2 = (e.excitation * e.gain * spec.gauge.factor * spec.bridge_factor * eps / 4 for eps in a.gauge_strain)
    d1, d2 = ev.design.geometry.stations
    k = a.sensitivity
    assert eq_12_force(V1, V2, k, k, d1, d2, 0.0, 0.0) == pytest.approx(spec.load.force_max, rel=1e-9)
    assert eq_11_position(V1, V2, k, k, d1, d2, 0.0, 0.0) == pytest.approx(spec.load.position_max, rel=1e-9)


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
