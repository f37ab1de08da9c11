"""The tool catalogue (materials/tools.yaml, designer.spec.tools): the end mills behind
cad.corner_radius and the CAD's slots and flats."""

import pytest

from designer.spec import catalogue


def test_the_default_corner_radius_is_on_every_metric_end_mill_of_1_to_12_mm():
    """docs/spec.md 2.8: R0.2 mm, the default, is ground on every metric end mill of 1-12 mm the
    catalogue lists, so that a slot or flat of any size this tool designs has one."""
    tools = catalogue.end_mills()
    metric = sorted({t.diameter for t in tools.end_mills if t.system == "metric" and t.diameter >= 1e-3 - 1e-12})
    assert metric[0] == pytest.approx(1e-3) and metric[-1] == pytest.approx(12e-3)
    assert tools.diameters(0.2e-3, "metric") == pytest.approx(metric)
    assert all(t.corner_radius < t.diameter / 2 for t in tools.end_mills)


def test_imperial_end_mills_are_read_in_exact_inches_and_named_as_sold():
    """1/8 in is 3.175 mm exactly, 0.010 in 0.254 mm; the designation keeps the table's unit."""
    tool = catalogue.end_mills().tool(3.175e-3, 0.254e-3, "imperial")
    assert tool is not None and tool.system == "imperial"
    assert tool.label == "end mill Ø1/8 R0.010 in"
    assert catalogue.end_mills().tool(3.175e-3, 0.254e-3, "metric") is tool   # one tool, whichever system first


def test_a_slot_made_longer_is_cut_with_the_end_mill_of_the_gauges_own_pocket():
    """outputs.cad.mills: a slot's end mill is chosen for the gauge's pocket (its backing and the
    spec's pocket margin), and a slot the search makes longer (search.problem.pocket_as_needed) is
    cut with the same one, whose radius the model's K_t at the rim reads (docs/model.md §7). By
    hand: BF350-3AA (6.9 x 3.5 mm) with 0.5 mm margins is a 7.9 x 4.5 mm pocket; 0.6 of 4.5 mm
    allows Ø2.5, whose R1.25 corner arc (centre 2.70, 1.00 mm from the pocket's centre) passes
    1.06 mm from the backing's corner (3.45, 1.75), more than 1.25 - 0.2 mm from it: it would cut
    into the gauge's flat floor, so Ø2 (0.71 mm <= 0.8 mm). Three times as long, Ø2.5 would fit."""
    from dataclasses import replace

    from designer.outputs.cad.mills import END_MILL_FRACTION, end_mill, pocket_tool, slot_end_mill
    from designer.result.evaluation import fixed_design
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text("""
name: small margins
load: {force: [1 N, 20 N], position: [60 mm, 100 mm]}
limits: {max_deflection: 1 mm, pocket_margin: 0.5 mm}
electronics: {excitation: 5 V, gain: 128, noise_rti: 50 nV}
gauge: BF350-3AA
bridge: half
design: {material: 6061-T6, section: {kind: rectangle, width: 12 mm, height: 6 mm},
         stations: [12 mm, 40 mm], feature: {kind: pocket, depth: 1 mm}}
""")
    lp, wp = spec.pocket_size()
    assert (lp, wp) == pytest.approx((7.9e-3, 4.5e-3)) and END_MILL_FRACTION * wp >= 2.5e-3
    assert slot_end_mill(spec) == pytest.approx(2e-3)
    assert end_mill(None, 3 * lp, wp, 6.9e-3, 3.5e-3, 0.2e-3) == pytest.approx(2.5e-3)
    g = fixed_design(spec).geometry
    longer = replace(g, pocket_length=3 * lp)
    assert pocket_tool(spec, longer).diameter == pytest.approx(2e-3)
    assert g.plan_radius == pytest.approx(1e-3)
