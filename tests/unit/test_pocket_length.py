"""A searched pocket is the gauge's backing and margins long, or as long as the feature
corrections need (docs/model.md §7): their 3-D study holds a flat on a tube only from one
diameter long, a flat on a thick round bar only where its ends are far enough from the gauge
grid. Reference: the study's domain in materials/corrections.yaml and the numeric model."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from designer.model import corrections
from designer.result.evaluation import ROUNDING, evaluate
from designer.search import optimize
from designer.spec.reader import load_spec

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _on_grid(value: float) -> bool:
    return value / ROUNDING == pytest.approx(round(value / ROUNDING), abs=1e-6)


def test_the_weigh_bars_flat_is_as_long_as_the_corrections_need_and_no_longer():
    """The weigh-bar's Ø29 mm round bar: the rule's 8.9 mm flat (BF350-3AA's 6.9 mm backing and
    1 mm margins) is shorter than the round flats' strain fit holds for (0.4 D and up, where the
    grid's ends are also far enough from the flat's for its grid-gap decays), so the reported flat
    is longer; 0.01 mm shorter it would leave the domain."""
    spec = load_spec(EXAMPLES / "weigh-bar.yaml")
    found = optimize(spec)
    ev = found.best
    g = ev.design.geometry
    rule = spec.pocket_size()[0]
    assert ev.feasible and g.section == "round" and g.pocket_length > rule + ROUNDING / 2
    assert _on_grid(g.pocket_length)
    shorter = evaluate(replace(ev.design, geometry=replace(g, pocket_length=g.pocket_length - ROUNDING)), spec)
    assert any(v.name.startswith("domain_") for v in shorter.violations)
    # the summary says why the flat is longer than the gauge's 6.9 mm backing and 1 mm margins
    from designer.outputs import report
    from designer.result.record import search_record

    feature = dict(report.summary_rows(search_record(spec, found)))["feature"]
    assert feature.endswith("longer than the gauge's 8.90 mm pocket, as the 3-D corrections need on this section "
                            "(docs/model.md §1)")


def test_a_tube_flat_is_at_least_as_long_as_the_tube_is_thick():
    """The gripper finger searched over tubes of 7075-T6 only: the tube flats' fits start at
    ``length_ratio`` 1 (docs/model.md §7 table), so the chosen stock tube's flat is at least its
    diameter long, whatever the rule's 8.9 mm says, and the design meets every limit."""
    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    spec = replace(spec, search=replace(spec.search, materials=("7075-T6",), sections=("tube",)))
    found = optimize(spec)
    g = found.best.design.geometry
    low = corrections.load().fit("tube-pocket", "strain").domain["length_ratio"][0]
    assert found.success and g.section == "tube" and g.feature == "pocket"
    assert g.pocket_length >= low * g.diameter - 1e-12 and _on_grid(g.pocket_length)
    assert g.pocket_length > spec.pocket_size()[0]


# The bench suite's 011-loose-limits (``bench.generate_suite(54, 0)``).
LOOSE_LIMITS = """name: 011-loose-limits
load: {force: [652.9 mN, 20.28 N], position: [80.08 mm, 269.7 mm]}
electronics: {excitation: 2.5 V, gain: 128.0, noise_strain: 0.007359 ue}
gauge: BF120-3AA
bridge: full
stations: 2
limits: {width: [0.8236 mm, 40.58 mm], height: [0.8236 mm, 35.42 mm], min_pocket_depth: 0.5 mm,
  min_wall: 1 mm, fatigue: false}
targets: {force_error: 1.1 %, position_error: 3.249 mm}
search: {materials: [2024-T3, Ti-6Al-4V, '304'], sections: [rectangle, round, tube], feature: pocket}
objective: mass
"""


def test_ipopt_is_not_held_at_the_kink_between_the_rule_and_the_needed_length():
    """The slot's length is the larger of the rule's and the fits' need, which have a kink where
    they cross; with a plain max() IPOPT stopped there, 4.9 % above the design COBYLA (nlopt,
    derivative-free, no gradients to stall on) finds. Reference: COBYLA's own search."""
    from designer.model import TIE_TOLERANCE
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(LOOSE_LIMITS)
    ipopt, cobyla = optimize(spec), optimize(spec, method="cobyla")
    assert ipopt.success and cobyla.success
    assert ipopt.best.objective <= cobyla.best.objective * (1 + TIE_TOLERANCE)


def test_a_pocket_of_the_rule_s_length_is_not_called_longer_and_a_given_one_is_the_design_s():
    """The gripper finger's Ø9.4 mm bar: its 8.9 mm flats are the rule's (0.95 D, inside the round
    flats' fits), and the summary says nothing of their length; a fixed design with 12 mm flats
    is longer because the design says so."""
    from designer.outputs import report
    from designer.result.pipeline import evaluate_fixed
    from designer.result.record import search_record
    from designer.spec.reader import parse_spec
    import yaml

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    feature = dict(report.summary_rows(search_record(spec, optimize(spec))))["feature"]
    assert "longer" not in feature
    raw = yaml.safe_load((EXAMPLES / "gripper-finger.yaml").read_text(encoding="utf-8"))
    raw["design"] = {"material": "Ti-6Al-4V", "section": {"kind": "round", "diameter": "9.39 mm"},
                     "stations": ["10 mm", "31 mm"], "feature": {"kind": "pocket", "depth": "2 mm", "length": "12 mm"}}
    record = evaluate_fixed(parse_spec(raw)).record
    assert dict(report.summary_rows(record))["feature"].endswith(
        "longer than the gauge's 8.90 mm pocket, as the design gives it")
