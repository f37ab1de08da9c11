"""Tolerances (docs/model.md §14): a design is judged at every corner of its toleranced sizes,
and the search finds designs whose corners all meet the limits."""

from __future__ import annotations

import itertools
import json
import math
import re
from dataclasses import replace

import numpy as np
import pytest
from pathlib import Path

from designer import model
from designer.errors import SpecError
from designer.model import tolerance
from designer.result.evaluation import channelled, evaluate, fixed_design
from designer.bench.suite import generate_suite
from designer.result.record import build_record
from designer.search import optimize, reference
from designer.search.problem import families
from designer.spec import catalogue
from designer.spec.reader import load_spec, parse_spec
from designer.spec.tolerances import Tolerances

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
LOAD = {"force": ["1 N", "10 N"], "position": ["40 mm", "80 mm"]}
ELECTRONICS = {"excitation": "5 V", "gain": 128, "noise_rti": "50 nV"}
ROUND_BAR = {"material": "6061-T6", "section": {"kind": "round", "diameter": "8 mm"},
             "stations": ["10 mm", "25 mm"], "feature": {"kind": "none"}}


@pytest.mark.parametrize("grade, size_mm, deviation_mm", [
    # ISO 2768-1:1989, Table 1 (linear dimensions): "0.5 up to 3", "over 3 up to 6", "over 6 up to 30",
    # "over 30 up to 120"; a range's upper end belongs to it
    ("f", 2.0, 0.05), ("f", 6.0, 0.05), ("f", 6.01, 0.1), ("f", 40.0, 0.15),
    ("m", 0.5, 0.1), ("m", 3.0, 0.1), ("m", 3.01, 0.1), ("m", 10.0, 0.2), ("m", 30.0, 0.2), ("m", 50.0, 0.3),
    ("c", 3.0, 0.2), ("c", 5.0, 0.3), ("c", 25.0, 0.5), ("v", 10.0, 1.0),
])
def test_deviations_are_iso_2768_1_table_1(grade, size_mm, deviation_mm):
    assert float(Tolerances(grade).deviation(size_mm * 1e-3, "section")) == pytest.approx(deviation_mm * 1e-3)


def _fixed(**tolerances):
    return parse_spec({"load": LOAD, "electronics": ELECTRONICS, "design": ROUND_BAR, "tolerances": tolerances})


def test_a_round_bars_root_stress_at_its_thin_corner_follows_32_m_over_pi_d_cubed():
    # sigma = M c / I = 32 M / (pi D^3) for a solid round bar (Roark, Table 8.1 case 1 with
    # I = pi D^4 / 64): at D - t the stress is (D / (D - t))^3 times the nominal's
    spec = _fixed(section="0.3 mm")
    ev = evaluate(fixed_design(spec), spec)
    nominal = next(lim for lim in ev.limits if lim.name == "stress_root")
    corner = next(lim for lim in ev.tolerance.limits if lim.name == "stress_root")
    assert ev.tolerance.corners[ev.tolerance.limits.index(corner)] == "D min"
    m = 10.0 * 0.080
    assert float(nominal.value) == pytest.approx(32 * m / (math.pi * 0.008 ** 3), rel=1e-9)
    assert float(corner.value) == pytest.approx(32 * m / (math.pi * 0.0077 ** 3), rel=1e-9)
    # the stiffer corner moves the tip less: the deflection's worst corner is the thin one as well
    assert ev.tolerance.count == 2 and ev.tolerance.deviations == (("diameter", pytest.approx(0.0003)),)


def _corner_values(ev, spec) -> tuple[list, dict]:
    """Each corner's signs (one per toleranced size) and each CORNER_LIMITS limit's normalised value
    at every corner, each corner built on its own (a Geometry per corner, not the vectorised
    corners of ``tolerance.check``; the wire channel follows the built depth) and judged."""
    g = ev.design.geometry
    fields = tolerance.toleranced(g)
    params = ev.design.material_params(spec)
    corners, values = [], {}
    for signs in itertools.product((-1.0, 1.0), repeat=len(fields)):
        sizes = {name: max(float(getattr(g, name)) + s * float(spec.tolerances.deviation(getattr(g, name), part)),
                           tolerance.LEAST[part]) for (name, part), s in zip(fields, signs)}
        built = channelled(replace(g, **sizes), spec.cad)
        a = model.analyse(built, params, spec, adjust=ev.design.adjustment)
        corners.append(signs)
        for lim in model.limits(built, a, params, spec):
            if lim.name in tolerance.CORNER_LIMITS:
                values.setdefault(lim.name, []).append(float(lim.normalised))
    return corners, values


def _each_corner(ev, spec):
    """Every corner of ``ev``'s design evaluated on its own (a Geometry per corner, not the
    vectorised corners of ``tolerance.check``): the largest normalised CORNER_LIMITS value."""
    _, values = _corner_values(ev, spec)
    return max(max(at) for at in values.values())


def test_a_design_that_passes_nominally_fails_at_a_corner_and_the_search_avoids_it():
    toleranced = load_spec(EXAMPLES / "gripper-finger.yaml")
    assert toleranced.tolerances == Tolerances("m")  # the default: the drawing's general tolerances
    plain = replace(toleranced, tolerances=Tolerances("none"))
    nominal = optimize(plain).best
    assert nominal.feasible
    # the nominal optimum, built to ISO 2768-m: every limit holds at its nominal sizes, and a
    # corner breaks one (its fatigue and deflection limits bind)
    judged = evaluate(nominal.design, toleranced)
    assert all(float(lim.normalised) <= model.FEASIBILITY_TOLERANCE for lim in judged.limits)
    assert not judged.feasible and _each_corner(judged, toleranced) > 0.05
    # searched with the tolerances, the reported design meets every limit at every corner,
    # each corner built and judged on its own
    held = optimize(toleranced)
    assert held.success and held.best.feasible
    assert _each_corner(held.best, toleranced) <= model.FEASIBILITY_TOLERANCE
    assert held.best.objective > nominal.objective  # the room for the tolerances costs accuracy


def test_with_class_none_the_record_says_which_limits_break_at_the_drawings_general_tolerances():
    # The gripper's optimum with `tolerances: {class: none}`: the search judged nominal sizes only,
    # while its drawing asks for ISO 2768-m. design.json's general_tolerances and report.md say so,
    # with each broken limit at its worst corner. Reference: every corner built and judged on its
    # own (_each_corner).
    from designer.outputs.report import markdown, summary_rows

    drawn = load_spec(EXAMPLES / "gripper-finger.yaml")
    plain = replace(drawn, tolerances=Tolerances("none"))
    nominal = optimize(plain).best
    record = json.loads(json.dumps(build_record("optimal", plain, nominal)))
    assert "tolerances" not in record
    general = record["general_tolerances"]
    assert general["label"] == "ISO 2768-m" and general["checked"] is False and general["corners"] == 4
    broken = [c for c in general["constraints"] if not c["satisfied"]]
    assert {c["name"] for c in broken} >= {"fatigue_feature"}
    reference = _each_corner(nominal, drawn)
    assert reference > 0.05
    limits = {lim.name: lim for lim in evaluate(nominal.design, drawn).tolerance.limits}
    assert max(float(limits[c["name"]].normalised) for c in broken) == pytest.approx(reference, rel=1e-9)
    text = markdown(record)
    assert "Not checked (the spec's `tolerances: {class: none}`)" in text and "ISO 2768-m" in text
    assert all(f"| {c['name']} | {c['corner']} |" in text for c in broken)
    rows = dict(summary_rows(record))  # the terminal's summary names them too
    assert rows["tolerances"].startswith("not checked") and all(c["name"] in rows["tolerances"] for c in broken)
    # with the tolerances checked, the record carries them instead
    held = optimize(drawn).best
    assert "general_tolerances" not in build_record("optimal", drawn, held)


@pytest.mark.parametrize("tolerances, key, allowed", [
    ({"class": "H7"}, "tolerances.class", "f, m, c, v"),
    ({"section": "-0.1 mm"}, "tolerances.section", "0 to 5 mm"),
    ({"feature": "2 V"}, "tolerances.feature", "length"),
    ({"grade": "m"}, "tolerances.grade", "class"),
])
def test_bad_tolerances_name_the_key_the_value_and_what_is_allowed(tolerances, key, allowed):
    with pytest.raises(SpecError) as err:
        _fixed(**tolerances)
    assert str(err.value).startswith(key) and allowed in str(err.value) and "\n" not in str(err.value)


def test_a_deviation_larger_than_the_pocket_leaves_no_pocket_at_that_corner_and_a_finite_record():
    # ISO 2768-m on a 0.05 mm deep flat: ±0.1 mm, so its corners are no flat at all and 0.15 mm.
    # Every figure stays a number that design.json can hold.
    bar = dict(ROUND_BAR, feature={"kind": "pocket", "depth": "0.05 mm"})
    spec = parse_spec({"load": LOAD, "electronics": ELECTRONICS, "design": bar, "tolerances": {"class": "m"},
                       "limits": {"min_pocket_depth": "0.05 mm"}})
    ev = evaluate(fixed_design(spec), spec)
    built = tolerance.corners(ev.design.geometry, spec.tolerances, spec.cad)
    assert sorted(set(np.round(np.ravel(built.depth) * 1e3, 6))) == [0.0, 0.05, 0.15]
    record = build_record("feasible", spec, ev)
    json.dumps(record, allow_nan=False)
    assert record["tolerances"]["deviations"] == {"diameter": pytest.approx(2e-4), "depth": pytest.approx(1e-4)}


@pytest.mark.parametrize("section, feature, tolerances, lost", [
    # an 8 mm round bar with a 2 mm flat, ±1 mm on the bar and ±2.5 mm on the flat: at p max the
    # flat is 4.5 mm deep, past the centre of the 7 mm bar (D min) and at the centre of the 9 mm
    # one (D max); at p min it is not cut (a plain bar, docs/model.md §14)
    ({"kind": "round", "diameter": "8 mm"}, {"kind": "pocket", "depth": "2 mm"}, {"section": "1 mm", "feature": "2.5 mm"},
     {"D min, p max", "D max, p max"}),
    # a 10 x 4 mm bar with a 2 mm hole, ±0.75 mm on the bar and ±1.5 mm on the hole: at h min and
    # d_h max a 3.5 mm hole in a 3.25 mm height; at h max it leaves 4.75 - 3.5 mm
    ({"kind": "rectangle", "width": "10 mm", "height": "4 mm"}, {"kind": "hole", "diameter": "2 mm"},
     {"section": "0.75 mm", "feature": "1.5 mm"}, {"b min, h min, d_h max", "b max, h min, d_h max"}),
])
def test_a_corner_whose_feature_cuts_through_the_section_is_no_beam_whatever_the_model_gives(section, feature,
                                                                                            tolerances, lost):
    """sections.unbuildable's rules at each corner: a flat as deep as half the bar, a hole as wide
    as the section. The beam model gave such corners finite figures (a flat past the centre of a
    round bar: the smallest signal -3739 noise levels, stresses below the nominal design's), and
    designs were reported to hold at every corner."""
    design = dict(ROUND_BAR, section=section, feature=feature)
    spec = parse_spec({"load": LOAD, "electronics": ELECTRONICS, "design": design, "tolerances": tolerances,
                       "limits": {"min_pocket_depth": "0.05 mm"}})
    ev = evaluate(fixed_design(spec), spec)
    assert model.unbuildable(ev.design.geometry) is None   # the nominal design is a beam
    broken = [(lim.name, at) for lim, at in zip(ev.tolerance.limits, ev.tolerance.corners) if float(lim.normalised) > 0]
    assert broken[-1][0] == tolerance.UNBUILDABLE and broken[-1][1] in lost and not ev.feasible
    # the search's and rounding's judge too: the design breaks its corners by the whole limit
    params = ev.design.material_params(spec)
    assert np.ravel(tolerance.worst(ev.design.geometry, params, spec)).tolist() == [1.0]


def test_a_search_that_the_tolerances_make_infeasible_says_so_and_at_which_corner():
    # a bench-suite millinewton beam: ISO 2768-m's ±0.1 mm on its height and pocket leaves no
    # design that meets every limit at its thin, deep corners (the fatigue limit at the slots, at
    # b min, h min, p max; seed 0's 049-short-beam, which had broken it there, is met at every
    # corner since the slot study took in narrower slots, docs/model.md §7): the message names the
    # limit and the corner
    spec = next(m.spec for m in generate_suite(50, 1) if m.name == "045-millinewton")
    assert optimize(replace(spec, tolerances=Tolerances("none"))).success
    result = optimize(replace(spec, tolerances=Tolerances("m")))
    assert not result.success
    said = [m for m in result.messages if m.startswith("at the corners of its tolerances (ISO 2768-m")]
    assert said and re.search(r"it breaks [a-z_]+ at b (min|max), h min, p max", said[0]), said


@pytest.mark.slow
def test_the_search_under_a_class_finds_the_reference_searchs_best_across_its_size_ranges():
    # prototype-b-optimized's 6061-T6 rectangle under ISO 2768-m: the best height lies in the
    # 3-6 mm range (±0.1 mm) although a start at 35 % or 70 % of the range lies in 6-30 mm
    # (±0.2 mm). The reference search (designer/search/reference.py: a grid over every variable
    # judged at the corners with the numeric model, then scipy's SLSQP) is the yardstick.
    spec = load_spec(EXAMPLES / "prototype-b-optimized.yaml")
    spec = replace(spec, tolerances=Tolerances("m"),
                   search=replace(spec.search, materials=("6061-T6",), sections=("rectangle",)))
    found = optimize(spec).best
    yardstick = reference.reference_search(spec, families(spec)[0], catalogue.material("6061-T6"), levels=7)
    assert found.feasible and yardstick.feasible
    assert found.objective <= yardstick.objective * (1 + model.TIE_TOLERANCE)
    assert found.design.geometry.height <= 0.006  # in the smaller range


def test_the_reference_search_of_a_family_without_stock_rows_under_tolerances_is_none():
    """A tube is a tube stock row (docs/model.md §5) and titanium tube is not stocked
    (materials/stock.yaml): the reference search has no point to judge, and says so, also when
    the tolerance corners are judged (it once failed on the empty grid there)."""
    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    spec = replace(spec, tolerances=Tolerances("m"))
    tube = next(f for f in families(spec) if f.section == "tube")
    assert reference.reference_search(spec, tube, catalogue.material("Ti-6Al-4V"), levels=3) is None


@pytest.mark.parametrize("name, grade", [("gripper-finger", "m"), ("probe", "f"), ("prototype-b-optimized", "m"),
                                         ("weigh-bar", "c"), ("prototype-b", "m"), ("prototype-c", "m")])
def test_the_corners_the_search_holds_its_limits_at_are_each_limits_worst(name, grade):
    """The search's NLP holds each corner-checked limit at the corners ``searched_corners`` gives
    (the section's sizes at their least, or at their greatest for the signal's lower limit; the
    feature's depth or hole at both ends) rather than at all of them. Reference: every corner of
    the example's design (its optimum, or the fixed design) built and judged on its own; each
    limit's worst over them is its worst over the searched corners. The depth is why the feature
    takes both ends: on prototype-b's narrow pocket the gauge strain is largest at the shallowest
    pocket (a deeper floor lies nearer the neutral axis), on the gripper's flat at the deepest."""
    spec = replace(load_spec(EXAMPLES / f"{name}.yaml"), tolerances=Tolerances(grade))
    ev = evaluate(fixed_design(spec), spec) if spec.design is not None else optimize(spec).best
    corners, values = _corner_values(ev, spec)
    parts = [part for _, part in tolerance.toleranced(ev.design.geometry)]
    searched = tolerance.searched_corners(parts)
    assert len(searched) == 2 * 2 ** parts.count("feature")   # each limit at 1 or 2 corners, of 2 to 8
    for limit, at in values.items():
        weak = limit not in tolerance.STRONG_CORNER_LIMITS
        held = [at[corners.index(signs)] for w, signs in searched if w == weak]
        assert max(held) == pytest.approx(max(at), rel=1e-12, abs=1e-12), limit


def test_the_summary_lists_the_limits_that_bind_at_a_tolerance_corner():
    """The gripper finger under the default ISO 2768-m: its fatigue limit at the flat binds at the
    thin bar with the deep flats, not at the nominal sizes; the terminal's table of binding limits
    names it with that corner. Reference: every corner built
    and judged on its own (``_corner_values``): the named corner's value is the limit's worst."""
    import io

    from rich.console import Console

    from designer.outputs.report import binding_limits, print_summary

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    best = optimize(spec).best
    record = json.loads(json.dumps(build_record("optimal", spec, best)))
    at_corner = {c["name"]: c for c in binding_limits(record) if "corner" in c}
    assert "fatigue_feature" in at_corner
    nominal = {c["name"]: c for c in record["constraints"]}
    corners, values = _corner_values(best, spec)
    for name, c in at_corner.items():
        assert not nominal[name]["active"] and c["active"]
        assert c["corner"] == "D min, p max" and c["satisfied"]
        assert max(values[name]) == values[name][corners.index((-1.0, 1.0))]  # the thin, deep corner
        assert values[name][corners.index((-1.0, 1.0))] > -model.ACTIVE_TOLERANCE
    out = io.StringIO()
    print_summary(record, Console(file=out, width=120))
    assert "fatigue_feature at D min, p max" in out.getvalue()


def test_the_nlp_s_corner_rows_are_the_corners_the_check_builds():
    """The NLP holds each corner-checked limit at its corners as rows of its own; a corner is the
    part as drawn, built at the corner's sizes: the flat as long as the nominal design's (a drawn
    length), not as long as the corner's own sizes would need. Reference: every corner of IPOPT's
    answer (the gripper finger's Ti-6Al-4V bar with flats, under its ISO 2768-m) built and judged
    on its own (``_corner_values``): each row equals that corner's value. (When the rows took the
    corner's own flat length, they read up to 2e-5 below the check at the answer, which then broke
    a limit the NLP held: the answer was repaired where it should have been judged as it is.)"""
    from designer.search.problem import FamilyProblem
    from designer.search.problem import Family

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    problem = FamilyProblem(spec, Family("round", spec.search.feature))
    material = catalogue.material("Ti-6Al-4V")
    params = problem.params(material)
    s = problem.solve_ipopt(params, problem.starts()[0])
    assert s.success
    ev = evaluate(problem.design(s.x, material), spec)
    corners, values = _corner_values(ev, spec)
    rows = np.asarray(problem.functions(s.x, params)[2]).ravel()
    parts = [part for _, part in tolerance.toleranced(ev.design.geometry)]
    compared = 0
    for name, at in values.items():
        weak = name not in tolerance.STRONG_CORNER_LIMITS
        held = [at[corners.index(signs)] for w, signs in tolerance.searched_corners(parts) if w == weak]
        nlp = [float(r) for r, n in zip(rows, problem.limit_names) if n == name][1:]   # the first is nominal
        assert nlp == pytest.approx(held, rel=1e-9, abs=1e-12), name
        compared += len(held)
    assert compared >= 10
    assert max(values["fatigue_feature"]) == pytest.approx(0.0, abs=1e-8)   # the answer holds it at a corner


def test_the_record_names_each_limit_it_breaks_once():
    """A station inside the load range gives a negative signal at the nominal sizes and at its
    tolerance corners: design.json's message named min_signal_snr twice."""
    from designer.result.pipeline import evaluate_fixed

    design = {"material": "7075-T6", "section": {"kind": "rectangle", "width": "10 mm", "height": "6 mm"},
              "stations": ["20 mm", "70 mm"], "feature": {"kind": "pocket", "depth": "1 mm"}, "length": "200 mm"}
    spec = parse_spec({"load": {"force": ["1 N", "20 N"], "position": ["60 mm", "120 mm"]},
                       "electronics": ELECTRONICS, "design": design})
    result = evaluate_fixed(spec)
    broken = [lim.name for lim in result.evaluation.violations]
    assert broken.count("min_signal_snr") == 2          # nominal and at a corner
    said = [m for m in result.record["messages"] if m.startswith("the design violates: ")]
    names = said[0].removeprefix("the design violates: ").split(", ")
    assert len(names) == len(set(names)) and set(names) == set(broken)
