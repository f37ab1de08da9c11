"""The designs ``optimize`` reports hold in 3-D (docs/model.md §7 and §11).

Reference: 3-D linear elasticity, ``fpdesign verify``'s own check (checks.fea) on the coarse mesh,
of the design that ``optimize`` reports for an example without ``--verify``: every limit holds
with the 3-D figures, the gauge strains agree within benchmarks/bench_3d.py's 2 %, and the
deflection and the peak stress at the features are at most that benchmark's 3 % and 10 % above
the model's. Below it they may lie by up to the shifts that put the extra length and K_t on
their safe side where the study cannot fit them closer (docs/model.md §7: up to 6 % of the
deflection here; for the peak, the K_t fit's own shift and left-out error, from the shipped
table). The benchmark prints the same figures for every example and the bench suite on the
normal mesh."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
STRAIN, DEFLECTION, STRESS = 0.02, 0.03, 0.10
SAFE_DEFLECTION = 0.06     # how far below the model the extra length's safe-side shift may put it


@pytest.mark.slow
@pytest.mark.parametrize("example", ["gripper-finger", "probe"])
def test_the_design_optimize_reports_holds_in_3d(example):
    from designer.spec.reader import load_spec

    spec = load_spec(ROOT / "examples" / f"{example}.yaml")
    result = _designed(spec)
    _holds_in_3d(result, spec)


# The weigh-bar at half its force range, on tube stock with gauge flats: a tube's flat is at least
# its diameter long (docs/model.md section 1), so under the 3 mm grid of BF350-3AA a tube over
# Ø12 mm needs a flat over 4 grid lengths, which the pocket study did not sample; a tube's flat
# may be 8 (docs/model.md section 7), and this spec's design is a Ø22 x 3 mm tube with flats
# 7.4 grids long (within 4 no tube met every limit: the least infeasible one missed the
# deflection and force error).
MEDIUM_TUBE = (ROOT / "examples" / "weigh-bar.yaml").read_text().replace(
    "force: [5 N, 200 N]", "force: [2.5 N, 100 N]") + "search: {sections: [tube], feature: pocket}\n"


@pytest.mark.slow
def test_a_tube_whose_flats_are_many_gauge_grids_long_holds_in_3d():
    from designer.model import corrections, domain
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(MEDIUM_TUBE, source="medium-tube")
    result = _designed(spec)
    g = result.evaluation.design.geometry
    assert g.section == "tube" and result.evaluation.design.stock is not None
    lp_grid = g.pocket_length / g.grid_length
    assert domain.LP_GRID_BOX[1] < lp_grid <= domain.lp_grid_top(corrections.family(g)) * (1 + 1e-9)
    _holds_in_3d(result, spec)


def _designed(spec):
    """The design ``optimize`` reports for ``spec`` (without the trade-off fronts): optimal."""
    from designer.result.pipeline import DesignOptions, design

    result = design(spec, DesignOptions(tradeoff=False))
    assert result.status == "optimal"
    return result


def _holds_in_3d(result, spec):
    """The checks above on ``result``'s design; its 3-D check returned."""
    from designer.checks.fea import verify_design
    from designer.model import corrections

    v = verify_design(result.record, mesh="coarse")
    assert [c.name for c in v.limits if not c.satisfied] == []
    # the model keeps room under the gauge's rating (docs/model.md §4); 3-D is held to the rating
    strain = next(c for c in v.limits if c.name == "gauge_strain")
    assert strain.limit == spec.gauge.max_strain and strain.model_value < spec.gauge.max_strain
    assert all(abs(r - 1) <= STRAIN for r in v.ratios), v.ratios
    assert 1 - SAFE_DEFLECTION <= v.deflection_fea / v.deflection_model <= 1 + DEFLECTION
    # the peak at the pockets' or flats' ends against the model's K_t x nominal stress, down to
    # what the K_t fit's shift and its left-out error allow (a plain bar has no feature)
    kt = corrections.load().fit(corrections.family(result.evaluation.design.geometry), "stress")
    if kt is not None:
        lowest = 1 / ((1 + kt.margin) * (1 + kt.loo_max))
        assert lowest <= v.stress_feature_fea / v.stress_feature_model <= 1 + STRESS
    return v


# A long beam under a light load, its deflection the objective: a blade 3.5 mm wide (the gauge's
# backing) and about 27 mm high. The clamp fit was studied on bars wider than high; near the
# clamp face a tall bar reads less than beam theory over about its height (2.4 % at 0.3 heights,
# benchmarks/plain_clamp_check.md), so its first station is kept 0.65 heights out
# (docs/model.md §7; at the clamp clearance's 8.45 mm, 0.32 heights, this design broke its force
# error in 3-D).
TALL_BLADE = """\
name: tall-blade
load: {force: [0.6 N, 13.35 N], position: [400 mm, 672 mm]}
electronics: {excitation: 3.3 V, gain: 64, noise_rti: 805 nV}
gauge: BF350-3AA
bridge: full
stations: 2
limits: {width: [1.6 mm, 36 mm], height: [1.6 mm, 29 mm]}
targets: {force_error: 2.46 %, position_error: 13 mm}
search: {materials: [2024-T3], sections: [rectangle], feature: none}
objective: deflection
"""


@pytest.mark.slow
def test_a_tall_plain_bar_holds_in_3d_with_its_first_station_near_the_clamp():
    from designer.model import domain
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(TALL_BLADE, source="tall-blade")
    result = _designed(spec)
    g = result.evaluation.design.geometry
    assert g.height > 5 * g.width     # the case in point: a blade bent about its strong axis
    # the bound is what places the first station (the search wants it at the clamp clearance)
    assert g.stations[0] == pytest.approx(domain.PLAIN_STATION_MIN * g.height, abs=1e-5)
    v = _holds_in_3d(result, spec)
    # closer than the 2 % agreement: inside the bound the series reads the model within 0.52 %
    assert all(abs(r - 1) <= 0.01 for r in v.ratios), v.ratios
    assert abs(v.deflection_fea / v.deflection_model - 1) <= DEFLECTION


# The bench suite's 011-loose-limits (seed 2) on its own material and section: a wide thin
# Ti-6Al-4V bar with a 5.5 mm slot over each gauge, the first within half a width of the clamp
# face, where a plain bar of that width loses 6 % of its strain to the clamp's plate effect. The
# slot's floor sees only a share of that loss (docs/model.md §7, `C_n` of a slot): with the plain
# bar's loss the design read 1.033 of the model at its first gauge in 3-D and broke the gauge's
# rating.
WIDE_SLOTTED_BAR = """\
name: wide-slotted-bar
load: {force: [3.729 N, 58.17 N], position: [58.63 mm, 156.8 mm]}
electronics: {excitation: 2.5 V, gain: 1.0, noise_rti: 30.65 nV}
gauge: BF120-3AA
bridge: half
stations: 2
limits: {width: [1.062 mm, 29.16 mm], height: [1.062 mm, 24.92 mm], min_pocket_depth: 0.5 mm, min_wall: 1 mm,
         fatigue: false}
targets: {force_error: 1.18 %, position_error: 2.055 mm}
search: {materials: [Ti-6Al-4V], sections: [rectangle], feature: pocket}
objective: error
tolerances: {class: none}
"""


@pytest.mark.slow
def test_a_slot_near_the_clamp_of_a_wide_bar_holds_in_3d():
    from designer.model import corrections
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(WIDE_SLOTTED_BAR, source="wide-slotted-bar")
    result = _designed(spec)
    g = result.evaluation.design.geometry
    table = corrections.load()
    # the case in point: a bar several times as wide as high, its first slot within a width of the
    # clamp face, where the plain bar's loss to the clamp is over 3 %
    u = corrections.station_width_ratios(g)[0]
    assert g.width > 4 * g.height and u < 1
    assert 1 - corrections.clamp_fit(table)(g.width / g.height, u) > 0.03
    v = _holds_in_3d(result, spec)
    assert v.ratios[0] == pytest.approx(1, abs=STRAIN)


# The weigh-bar with a deflection limit of 1.162 mm, not 2 mm (found by running the examples' specs with
# their figures moved at random): a Ø30 mm 17-7PH-RH950 bar with flats a quarter of its diameter
# deep, the first 0.17 diameters from the clamp face, the second 2.8 diameters out and 0.31 m from
# the load, which bends it nearly as much as the first. The round flats' extra length was taken
# for both flats with the first one's nearness to the clamp, which stiffens only the first: the
# second counted 0.04 diameters too little, and the design the search reported deflected in 3-D
# 2.4 % more than the model and broke the limit (docs/model.md section 7).
LOOSER_WEIGH_BAR = (ROOT / "examples" / "weigh-bar.yaml").read_text().replace(
    "max_deflection: 2 mm", "max_deflection: 1.162 mm") + "search: {materials: [17-7PH-RH950], sections: [round]}\n"


@pytest.mark.slow
def test_a_round_bar_whose_far_flat_bends_it_as_much_as_the_near_one_holds_in_3d():
    from designer.model import corrections
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(LOOSER_WEIGH_BAR, source="looser-weigh-bar")
    result = _designed(spec)
    g = result.evaluation.design.geometry
    table = corrections.load()
    # the case in point: the first flat near the clamp, the second far from it, the deflection
    # limit binding
    near, far = corrections.clamp_ratios(g)
    assert g.section == "round" and g.feature == "pocket" and near < 0.3 and far > 2
    deflection = next(lim for lim in result.evaluation.tolerance.limits if lim.name == "deflection")
    assert spec.limits.max_deflection == pytest.approx(1.162e-3) and -float(deflection.normalised) < 0.01
    v = _holds_in_3d(result, spec)
    # and the model's room under the limit covers what 3-D adds (docs/model.md section 4)
    assert v.deflection_fea / v.deflection_model <= 1 + corrections.deflection_allowance(g, table)
    # each flat has its own extra length, the far one's at least 0.03 diameters more
    deltas = [((b - a) - g.feature_length) / g.size for a, b in corrections.widened(g, table).reduced_spans]
    assert deltas[1] - deltas[0] > 0.03, deltas
