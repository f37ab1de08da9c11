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
