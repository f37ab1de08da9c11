"""The stress limits of docs/model.md §4: static yield on the nominal stress, fatigue on K_f times
the nominal stress at a feature, with Peterson's notch sensitivity."""

import pytest

from designer import model
from designer.model import Geometry, MaterialParams
from designer.model.analysis import notch_sensitivity
from designer.model.corrections import Corrections, Fit
from designer.result.evaluation import fixed_design
from designer.spec import catalogue
from designer.spec.reader import parse_spec_text

MM = 1e-3

FLAT_SPEC = """\
name: flat-bar
load: {{force: [1 N, 20 N], position: [150 mm, 250 mm]}}
electronics: {{excitation: 5 V, gain: 500, noise: 1 mV}}
gauge: BF350-3AA
bridge: half
limits: {{fatigue: {fatigue}, safety_factor: 2}}
cad: {{corner_radius: 0.4 mm}}
design:
  material: 6061-T6
  section: {{kind: round, diameter: 10 mm}}
  stations: [20 mm, 60 mm]
  feature: {{kind: pocket, depth: 2 mm}}
  length: 250 mm
"""

# A made-up table: K_t = 2.5 for every round bar with flats.
KT = Corrections({"round-pocket": {"stress": Fit(("depth_ratio",), ((0,),), (2.5,), {})}})


def _analysis(fatigue=True, table=KT):
    spec = parse_spec_text(FLAT_SPEC.format(fatigue=str(fatigue).lower()))
    design = fixed_design(spec).rounded(spec.cad)
    params = design.material_params(spec)
    a = model.analyse(design.geometry, params, spec, table=table)
    return spec, design, params, a, {lim.name: lim for lim in model.limits(design.geometry, a, params, spec, table=table)}


def test_peterson_notch_sensitivity_by_hand():
    # q = 1 / (1 + a / r): a = 0.51 mm (aluminium alloys), r = 0.4 mm -> 0.4 / 0.91
    assert notch_sensitivity(0.4 * MM, 0.51 * MM) == pytest.approx(0.4 / 0.91, rel=1e-12)
    # no published constant: fully notch sensitive; no notch: no concentration to weigh
    assert notch_sensitivity(0.4 * MM, 0.0) == 1.0
    assert notch_sensitivity(0.0, 0.51 * MM) == 0.0


def test_steel_notch_lengths_follow_petersons_rule():
    # a = 0.0254 mm (2070 MPa / S_u)^1.8 (Peterson's rule for steels, as in Dowling §10.3),
    # rounded in the catalogue to 1 um
    for name in ("17-4PH-H900", "301-full-hard", "17-7PH-RH950"):
        m = catalogue.material(name)
        rule = 0.0254 * MM * (2070e6 / m.ultimate) ** 1.8
        assert m.notch_length == pytest.approx(rule, abs=0.6e-6), name
    assert catalogue.material("6061-T6").notch_length == pytest.approx(0.51 * MM)


def test_fatigue_uses_kf_times_nominal_and_static_the_nominal_against_yield():
    spec, design, params, a, lims = _analysis()
    m = design.material
    q = 0.4 / (0.4 + 0.51)
    assert float(a.stress_concentration) == pytest.approx(2.5)
    assert float(a.fatigue_factor) == pytest.approx(1 + q * 1.5, rel=1e-12)
    # static: the nominal stress at the flat's clamp-side edge against yield / safety factor
    assert float(lims["stress_feature"].value) == pytest.approx(float(a.stress_feature), rel=1e-15)
    assert float(lims["stress_feature"].limit) == pytest.approx(m.yield_strength / 2, rel=1e-15)
    # fatigue: K_f x nominal against min(yield, fatigue) / safety factor
    assert float(lims["fatigue_feature"].value) == pytest.approx((1 + q * 1.5) * float(a.stress_feature), rel=1e-12)
    assert float(lims["fatigue_feature"].limit) == pytest.approx(min(m.yield_strength, m.fatigue) / 2, rel=1e-15)
    # the peak the 3-D check compares with: K_t x nominal
    assert float(a.stress_peak) == pytest.approx(2.5 * float(a.stress_feature), rel=1e-12)
    # the root keeps its nominal stress and the combined allowable
    assert float(lims["stress_root"].limit) == pytest.approx(min(m.yield_strength, m.fatigue) / 2, rel=1e-15)


def test_no_fatigue_limit_without_fatigue_and_no_table_means_kf_one():
    *_, lims = _analysis(fatigue=False)
    assert "fatigue_feature" not in lims
    _, _, _, a, lims = _analysis(table=Corrections({}))
    assert float(a.fatigue_factor) == 1.0
    # without a K_t fit the fatigue limit is the old single stress limit at the feature
    assert float(lims["fatigue_feature"].value) == float(a.stress_feature)


def test_the_optimiser_sees_the_fatigue_limit_with_exact_derivatives():
    import casadi as ca

    spec, design, params, *_ = _analysis()
    g0 = design.geometry
    x = ca.SX.sym("x", 2)   # diameter and depth, m
    p = ca.SX.sym("p", len(MaterialParams(1.0, 1.0, 1.0).scaled()))
    g = Geometry(section="round", feature="pocket", stations=g0.stations, length=g0.length, diameter=x[0],
                 depth=x[1], pocket_length=g0.pocket_length, pocket_width=g0.pocket_width,
                 gauge_length=g0.gauge_length, grid_length=g0.grid_length, floor_radius=g0.floor_radius)
    a = model.analyse(g, MaterialParams.from_scaled(p), spec, model.casadi_ops(), table=KT)
    f = ca.Function("f", [x, p], [a.stress_fatigue])
    jac = ca.Function("j", [x, p], [ca.jacobian(a.stress_fatigue, x)])
    x0, p0 = [10 * MM, 2 * MM], params.scaled()
    h = 1e-8
    for i in range(2):
        xp, xm = list(x0), list(x0)
        xp[i] += h
        xm[i] -= h
        fd = (float(f(xp, p0)) - float(f(xm, p0))) / (2 * h)
        assert float(jac(x0, p0)[i]) == pytest.approx(fd, rel=1e-5)
    # and the same number as the numeric model
    assert float(f(x0, p0)) == pytest.approx(float(_analysis()[3].stress_fatigue), rel=1e-12)
