"""The beam model's section properties (MODEL.md section 2) against numerical integration of
each reduced cross-section, and the casadi graph of the model against its numeric evaluation.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from designer import model
from shared_inputs import MM, circular, make_spec, material, rectangle


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


def test_a_flats_width_and_its_depth_are_each_others_inverse():
    # the chord of a circle: a flat p deep on radius R is 2 sqrt(R^2 - (R - p)^2) wide. With R = 5
    # and the 3-4-5 right triangle, a flat 2 deep is 8 wide; a flat as wide as the diameter is
    # R deep (a half disc), and one of no width is no depth.
    from designer.model.sections import flat_depth, flat_half_chord

    assert 2 * flat_half_chord(5.0, 2.0) == pytest.approx(8.0, rel=1e-12)
    assert flat_depth(5.0, 8.0) == pytest.approx(2.0, rel=1e-12)
    assert flat_depth(5.0, 10.0) == pytest.approx(5.0, rel=1e-12)
    assert flat_depth(5.0, 12.0) == pytest.approx(5.0, rel=1e-12)
    assert flat_depth(5.0, 0.0) == 0.0


# ----------------------------------------------------------------- symbolic and numeric agree

# casadi 3.7 warns (FutureWarning) where a numpy function meets a casadi value, which later
# releases are to stop evaluating: with the sizes symbolic and the stations numbers, a feature's
# nearness to the clamp was np.exp of an expression.
@pytest.mark.filterwarnings("error::FutureWarning")
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


def test_the_grid_arc_factor_is_the_mean_height_of_the_round_surface_under_the_grid():
    # Reference: the mean of sqrt(R^2 - s^2) / R over |s| <= w/2, by the trapezoid rule; 1 on a
    # flat face (rectangles, flats) and for a grid of no width
    from designer import model

    for d, w in ((5e-3, 2.2e-3), (10e-3, 4.57e-3), (30e-3, 2.2e-3)):
        g = circular("round", d, grid_width=w)
        s = np.linspace(-w / 2, w / 2, 200001)
        mean = np.trapezoid(np.sqrt((d / 2) ** 2 - s ** 2), s) / w / (d / 2)
        assert float(model.grid_arc_factor(g)) == pytest.approx(mean, rel=1e-9)
        assert float(model.grid_arc_factor(circular("tube", d, wall=d / 4, grid_width=w))) == pytest.approx(mean, rel=1e-9)
    assert model.grid_arc_factor(circular("round", 5e-3, feature="pocket", grid_width=2.2e-3, depth=1e-3)) is None
    assert model.grid_arc_factor(rectangle(5e-3, 5e-3, grid_width=2.2e-3)) is None
    assert model.grid_arc_factor(circular("round", 5e-3)) is None


def test_the_gauge_backing_must_fit_the_face_it_reads():
    # The default gauge's backing is 3.5 mm wide (BF120-3AA, materials/gauges.yaml): a 1.72 mm
    # wide bar with holes (a bench-suite design whose gauge overhung both edges, so that the 3-D
    # check found no surface under its grid) breaks gauge_face by 1 - 1.72/3.5; a 4 mm bar and a
    # Ø4 mm round bar meet it; a slot's own side-wall limit covers pockets
    from designer.model.limits import section_limits

    spec = make_spec()
    assert spec.gauge.width == pytest.approx(3.5 * MM)

    def face(g):
        return {lim.name: lim for lim in section_limits(g, spec)}.get("gauge_face")

    narrow = face(rectangle(1.72 * MM, 15.6 * MM, feature="hole", hole=4.7 * MM))
    assert float(narrow.normalised) == pytest.approx(1 - 1.72 / 3.5)
    assert float(face(rectangle(4 * MM, 4 * MM)).normalised) < 0
    assert float(face(circular("round", 4 * MM)).normalised) < 0
    assert face(rectangle(10 * MM, 5 * MM, feature="pocket", depth=1 * MM)) is None


@pytest.mark.parametrize("stations, length, l_f, key", [
    ((0.020, 0.060), 0.310, 0.0089, None),
    ((0.020, 0.0285), 0.310, 0.0089, "stations[1]"),    # 8.5 mm apart: the 8.9 mm pockets overlap
    ((0.020, 0.0290), 0.310, 0.0089, None),
    ((0.004, 0.060), 0.310, 0.0089, "stations[0]"),     # half the pocket over the clamp face
    ((0.020, 0.120), 0.800, 0.150, "stations[0]"),      # 150 mm pockets at 20 and 120 mm
    ((0.080, 0.200), 0.800, 0.150, "stations[1]"),      # they overlap by 30 mm
    ((0.020, 0.306), 0.310, 0.0089, "stations[1]"),     # past the free end
])
def test_each_feature_needs_its_own_length_of_beam(stations, length, l_f, key):
    # reference: the intervals (d - l_f/2, d + l_f/2) must lie inside (0, L) and be disjoint,
    # checked here by sampling the beam on a 0.1 mm grid and counting the features over each point
    x = np.arange(-0.05, length + 0.05, 1e-4)
    over = sum((np.abs(x - d) < l_f / 2).astype(int) for d in stations)
    fits = over.max() <= 1 and not over[(x <= 0) | (x >= length)].any()
    problem = model.features_apart(stations, length, l_f, "pocket")
    assert (problem is None) == fits
    assert (problem and problem[0]) == key


def test_where_a_square_root_meets_zero_the_model_and_its_derivatives_stay_numbers():
    # IPOPT stops at a start point whose derivatives are no number (Invalid_Number_Detected): the
    # bench suite's millinewton specs start round bars thinner than their gauge's grid (a = w/D > 1)
    # and thinner than the flat's wire channel (no round surface beside it). Each value is held at
    # its closed form's edge there, its derivative a number:
    # - a grid at least as wide as the bar averages (a sqrt(1 - a^2) + asin a)/(2a) at a = 1: pi/4;
    # - beside a channel wider than the bar the flat keeps no shoulder but the channel's floor:
    #   shoulder_ratio = (p - t_c)/p.
    casadi = pytest.importorskip("casadi")
    from dataclasses import replace

    ops = model.casadi_ops()
    d, p = casadi.SX.sym("d"), casadi.SX.sym("p")
    narrow = circular("round", 0.8 * MM, grid_width=1.2 * MM)
    arc = casadi.Function("arc", [d], [model.grid_arc_factor(replace(narrow, diameter=d), ops)])
    assert float(arc(0.8 * MM)) == pytest.approx(math.pi / 4, rel=1e-5)
    assert math.isfinite(float(casadi.Function("da", [d], [casadi.jacobian(arc(d), d)])(0.8 * MM)))
    assert float(model.grid_arc_factor(narrow)) == pytest.approx(math.pi / 4, rel=1e-5)

    flat = circular("round", 0.5 * MM, feature="pocket", depth=0.1 * MM, channel_width=1.0 * MM,
                    channel_depth=0.04 * MM, floor_radius=0.05 * MM)
    sym = replace(flat, diameter=d, depth=p)
    assert float(model.shoulder_ratio(flat)) == pytest.approx((0.1 - 0.04) / 0.1, rel=1e-6)
    spec = make_spec()
    rows = [lim.normalised for lim in model.limits(sym, model.analyse(sym, material(), spec, ops), material(), spec,
                                                   ops=ops)]
    jac = casadi.Function("j", [d, p], [casadi.jacobian(casadi.vertcat(model.shoulder_ratio(sym), *rows),
                                                        casadi.vertcat(d, p))])
    assert np.isfinite(np.array(jac(0.5 * MM, 0.1 * MM))).all()
    # a flat cut to no depth (a tolerance corner's pocket, depth held at 0): its chord's derivative
    chord = casadi.Function("c", [p], [casadi.jacobian(
        {lim.name: lim.normalised for lim in model.limits(replace(flat, depth=p), model.analyse(flat, material(), spec),
                                                          material(), spec, ops=ops)}["flat_chord"], p)])
    assert math.isfinite(float(chord(0.0)))
