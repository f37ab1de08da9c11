"""The closest design of a spec no design meets (designer.search.closest), and the diagnosis
that reasons from it (designer.search.diagnosis): the design keeps the geometry's own rules,
and the force the advice names is one at which that design meets every limit, checked by
beam theory's scaling and by the exhaustive reference search (which shares no code with casadi).
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import pytest

from designer import model, search
from designer.result.evaluation import evaluate
from designer.search import reference
from designer.search.closest import meets_rules
from designer.spec import catalogue
from designer.spec.reader import load_spec

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ADVICE = re.compile(r"every limit it breaks grows with the largest force: at load\.force\[1\] = ([0-9.]+) N")


def _overloaded():
    """The gripper finger under 5-300 N (not 0.5-20 N) on 6061-T6 alone: its stress limits and the fatigue limit
    at its pockets (the most broken: K_f 1.4 times the nominal stress against 46 MPa) cannot all
    be met within the 16 x 16 mm section the spec allows, with two stations between the clamp
    clearance and the load region."""
    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    return replace(spec, load=replace(spec.load, force_min=5.0, force_max=300.0),
                   search=replace(spec.search, materials=("6061-T6",)))


def _at(spec, force_max: float):
    return replace(spec, load=replace(spec.load, force_max=force_max))


def test_the_closest_design_keeps_the_geometry_s_rules_and_meets_every_limit_at_the_force_it_names():
    # Before, the reported design was IPOPT's restoration point (a 16.01 x 13 mm bar with pockets
    # 0.45 mm deep, under the 0.5 mm least, and stations closer than their gap), and the advice,
    # "lower load.force[1] to 187.2 N", came from the root stress alone: the spec had no design at 130 N.
    spec = _overloaded()
    found = search.optimize(spec)
    assert not found.success
    best = found.best
    rules = [lim.name for lim in best.judged if lim.name not in model.DUTY_LIMITS
             and float(lim.normalised) > model.FEASIBILITY_TOLERANCE]
    assert not rules, rules
    assert {v.name for v in best.violations} <= {"stress_root", "stress_feature", "fatigue_feature"}
    [said] = [m for m in found.messages if ADVICE.match(m)]
    advised = float(ADVICE.match(said).group(1))
    # every broken limit is a stress, which beam theory makes proportional to the force
    # (sigma = M c / I, M = F x): the same design meets every limit at the advised force (rounded
    # down to 4 digits), and breaks one 0.2 % above it
    assert evaluate(best.design, _at(spec, advised)).feasible
    assert not evaluate(best.design, _at(spec, advised * 1.002)).feasible
    # the advice is followed: the search finds a design there
    assert search.optimize(_at(spec, advised)).success
    # the fatigue limit, the most broken, is named with the force it alone allows
    fatigue = max((v for v in best.violations if v.name == "fatigue_feature"), key=lambda v: float(v.value))
    [told] = [m for m in found.messages if m.startswith("fatigue_feature:")]
    alone = float(re.search(r"lower load\.force\[1\] to ([0-9.]+) N", told).group(1))
    assert 300.0 * float(fatigue.limit) / float(fatigue.value) * (1 - 1e-3) <= alone <= advised * (1 + 1e-3)


def test_infeasible_candidates_rank_the_ones_keeping_the_geometry_s_rules_first():
    spec = _overloaded()
    found = search.optimize(spec)
    keys = [(not meets_rules(c.evaluation), c.evaluation.worst_violation)
            for c in found.candidates if c.evaluation is not None]
    assert keys == sorted(keys) and len(keys) >= 2
    assert not keys[0][0]


@pytest.mark.slow
def test_no_design_bears_three_percent_more_than_the_advised_force():
    # The exhaustive reference search (a dense grid polished by SLSQP on the numeric model) finds
    # no rectangular or round 6061-T6 bar that meets every limit 3 % above the force the diagnosis
    # names (the tubes come from stock and miss by far more): the closest design found is within
    # 3 % of the best any bar could do
    spec = _overloaded()
    found = search.optimize(spec)
    [said] = [m for m in found.messages if ADVICE.match(m)]
    above = _at(spec, float(ADVICE.match(said).group(1)) * 1.03)
    for family in search.families(above):
        if family.section in ("rectangle", "round"):
            ev = reference.reference_search(above, family, catalogue.material("6061-T6"), levels=5)
            assert ev is not None and not ev.feasible, family.label


def test_the_deflection_advice_after_a_clearance_message_still_says_where_the_section_stands():
    # Prototype B's fixed design (docs/spec.md §6: stations at 20 and 100 mm, 9.5 mm holes) with
    # its load from 90 mm, inside its second station, and a 1 µm deflection limit: the clearance
    # message had taken over the name that held the section's place, and the deflection advice read
    # "exceeds limits.max_deflection = 0.0009878 mm 0.09; allow ..." (the load region's start, in m)
    from designer.result.evaluation import fixed_design
    from designer.search.diagnosis import diagnose

    spec = load_spec(EXAMPLES / "prototype-b.yaml")
    spec = replace(spec, load=replace(spec.load, position_min=0.090),
                   limits=replace(spec.limits, max_deflection=1e-6))
    ev = evaluate(fixed_design(spec), spec)
    said = diagnose(spec, ev, [])
    assert any(m.startswith("load_clearance: the closest design's stations") for m in said)
    [deflection] = [m for m in said if m.startswith("deflection:")]
    assert "at the closest design's 12.7 × 12.7 mm section (limits.width allows up to 50 mm" in deflection, deflection


def test_a_spec_too_noisy_for_its_targets_reports_a_design_meeting_every_other_limit_and_a_noise_that_holds():
    # The bench suite's 025-infeasible-noise (fpdesign bench, seed 0: noise of 1.03 µε at the strain
    # input, a level its force target cannot be met at): the closest design reported had been one
    # breaking the stress and gauge-strain limits by up to 2.3 times for a better error ratio, and so
    # the noise it named (1.03 mV) was one at which no design meets every limit. Now the closest design
    # meets every limit but the targets, and the errors scaling as the noise at the output (the
    # paper's sigma_F = sigma_V / k ...), that design meets every limit at the noise the advice names
    from designer.bench.suite import generate_suite
    from designer.spec.reader import parse_spec_text

    [suite] = [s for s in generate_suite(25) if s.name == "025-infeasible-noise"]
    found = search.optimize(suite.spec)
    assert not found.success
    assert {v.name for v in found.best.violations} == set(model.TARGET_LIMITS)
    [said] = [m for m in found.messages if m.startswith("the accuracy targets are out of reach")]
    noise = re.search(r"electronics noise of at most ([0-9.e+-]+) mV at the output", said).group(1)
    quieter = parse_spec_text(suite.text.replace("noise_strain: 1.027 ue", f"noise: {noise} mV"))
    assert evaluate(found.best.design, quieter).feasible
    louder = parse_spec_text(suite.text.replace("noise_strain: 1.027 ue", f"noise: {float(noise) * 1.01} mV"))
    assert not evaluate(found.best.design, louder).feasible


def test_with_an_error_budget_the_noise_advice_leaves_room_for_the_terms_that_do_not_fall_with_it():
    # The gripper finger over 0-40 °C, tared, with 400 nV of input noise (not 50): the noise and the
    # calibration fit are 76 % of the force error's variance at F_min, x_max; span drift and the
    # others stay whatever the noise (docs/model.md §13, JCGM 100's root sum of squares). The
    # advice had divided the noise by the error ratio (0.0133 mV), at which the targets are still
    # missed; now s^2 N + O <= target^2 at every load of the budget. And a spec whose other terms
    # alone break a target (span drift against a 0.3 % force target) is told no noise would do
    from designer.spec.reader import parse_spec_text

    text = (EXAMPLES / "gripper-finger.yaml").read_text().replace("noise_rti: 50 nV", "noise_rti: 400 nV")
    text = text.replace("materials: all", "materials: [Ti-6Al-4V]").replace("[rectangle, round, tube]", "[round]")
    env = "environment: {temperature: [0 °C, 40 °C], calibrated_at: 23 °C, hold: 30 min, tare: true}\n"
    spec = parse_spec_text(text + env)
    found = search.optimize(spec)
    assert {v.name for v in found.best.violations} <= set(model.TARGET_LIMITS)
    [said] = [m for m in found.messages if m.startswith("the accuracy targets are out of reach")]
    noise = float(re.search(r"electronics noise of at most ([0-9.e+-]+) mV at the output", said).group(1)) * 1e-3
    assert "load.force[0] of at least" not in said   # the budget's other terms do not fall as 1/F_min

    def at(sigma_v):
        return replace(spec, electronics=replace(spec.electronics, noise=sigma_v, noise_rti=None))

    assert at(noise).sigma_v == pytest.approx(noise, rel=1e-12)
    assert evaluate(found.best.design, at(noise)).feasible
    assert not evaluate(found.best.design, at(noise * 1.01)).feasible
    assert noise < spec.sigma_v / found.best.error_ratio * 0.9   # the noise alone scaled: not enough

    drift = parse_spec_text(text.replace("noise_rti: 400 nV", "noise_rti: 50 nV")
                            .replace("force_error: 1 %", "force_error: 0.3 %") + env)
    [said] = [m for m in search.optimize(drift).messages if m.startswith("the accuracy targets are out of reach")]
    assert "no electronics noise alone would meet them" in said and "electronics noise of at most" not in said


FLAT = re.compile(r"flat_chord: .* takes a bar of at least ([0-9.]+) mm")
FACE = re.compile(r"gauge_face: the gauge's backing, ([0-9.]+) mm wide .* overhangs the ([0-9.]+) mm face")


def _widened(spec, size: float):
    lim = spec.limits
    return replace(spec, limits=replace(lim, width=(lim.width[0], size), height=(lim.height[0], size)))


def test_where_the_gauge_fits_no_allowed_section_the_closest_design_stays_within_its_sizes_and_the_advice_holds():
    # The bench suite's 045-millinewton (generate_suite(50, 0)): a 1.2 mm wide gauge, its pocket 1.6 mm
    # wide, on round bars with flats at most 0.3 D deep on a 0.05 mm grid, at most 0.9546 mm across:
    # no bar allowed holds the pocket. The closest design breaks no more of the geometry's rules
    # than it must (its flat's width and the fit's shoulder, not its diameter's limit). The bar the
    # advice names is the least on the 0.01 mm grid with a grid depth p <= 0.3 D whose flat,
    # 2 sqrt(p (D - p)) wide, holds the pocket (counted here point by point), and with the sizes
    # allowed a grid step past it (at 1.78 mm a 0.5 mm flat is exactly 1.6 mm wide) the search
    # finds a design keeping every rule of the geometry.
    from designer.bench.suite import _generate

    spec = _generate(44, "millinewton", 0).spec
    found = search.optimize(spec)
    broken = {v.name for v in found.best.violations}
    assert "flat_chord" in broken and not broken & {"diameter_max", "pocket_depth_max"}
    # 020-tight-limits: its closest design had been a bar past its largest diameter when that broke
    # fewer rules (the flat's width and its fit's length) than one within it
    broken = {v.name for v in search.optimize(_generate(19, "tight-limits", 0).spec).best.violations}
    assert "flat_chord" in broken and not broken & set(model.SIZE_LIMITS)
    need = float(FLAT.search(" ".join(found.messages)).group(1))
    least = next(d / 100 for d in range(90, 300) for p in (k * 0.05 for k in range(1, 60))
                 if p <= 0.3 * d / 100 + 1e-12 and 2 * (p * (d / 100 - p)) ** 0.5 >= 1.6 - 1e-12)
    assert need == pytest.approx(least, abs=1e-9) and least == pytest.approx(1.78)
    assert meets_rules(search.optimize(_widened(spec, (need + 0.01) * 1e-3)).best)

    # 023-millinewton: the same gauge on round bars without flats, at most 0.9546 mm across: the
    # gauge overhangs the widest (0.95 mm on the 0.01 mm grid below the limit)
    spec = _generate(22, "millinewton", 0).spec
    found = search.optimize(spec)
    backing, face = (float(v) for v in FACE.search(" ".join(found.messages)).groups())
    assert backing == pytest.approx(1.2) and face == pytest.approx(0.95)
    assert meets_rules(search.optimize(_widened(spec, backing * 1e-3)).best)


def test_a_tube_s_flat_too_narrow_for_its_pocket_is_told_the_depth_that_holds_it_and_the_wall_that_would_leave_it():
    # The bench suite's 036-infeasible-noise (generate_suite(50, 1)), its tubes at most 8 mm across
    # and limits.min_wall 2 mm: the closest is a Ø8 mm tube with a 2 mm wall (the thickest Ø8 tube in
    # stock; the thinner ones leave less), its flat too shallow for its 5.5 mm pocket. Its tube is
    # large enough (a flat 2 sqrt(p (D - p)) wide holds the pocket from
    # p = (D - sqrt(D^2 - 5.5^2))/2 = 1.095 mm, on the 0.05 mm grid 1.1 mm), but its wall leaves no
    # flat that deep (flat_wall: p <= t - min_wall). (With its own limits a Ø12 x 2 mm tube keeps
    # every rule of the geometry, and the closest design is that.)
    from designer.bench.suite import _generate

    spec = _generate(35, "infeasible-noise", 1).spec
    spec = replace(spec, limits=replace(spec.limits, width=(spec.limits.width[0], 8e-3),
                                        height=(spec.limits.height[0], 8e-3), min_wall=2e-3))
    found = search.optimize(spec)
    g = found.best.design.geometry
    text = next(m for m in found.messages if m.startswith("flat_chord"))
    depth, wall = (float(v) * 1e-3 for v in re.search(r"a flat ([0-9.]+) mm deep holds it, which its ([0-9.]+) mm "
                                                       r"wall", text).groups())
    D, pocket, step = float(g.diameter), spec.pocket_size()[1], spec.cad.depth_step
    assert wall == pytest.approx(float(g.wall)) and depth > wall - spec.limits.min_wall
    assert 2 * (depth * (D - depth)) ** 0.5 >= pocket > 2 * ((depth - step) * (D - depth + step)) ** 0.5
    assert depth == pytest.approx(1.1e-3) and D == pytest.approx(8e-3)
    # that flat in a wall as thick as it needs keeps both rules
    deeper = replace(found.best.design, geometry=replace(g, depth=depth, wall=depth + spec.limits.min_wall))
    assert not {v.name for v in evaluate(deeper, spec).violations} & {"flat_chord", "flat_wall"}


def test_with_no_room_for_the_stations_the_diagnosis_names_that_alone():
    # The bench suite's 030-infeasible-room (generate_suite(50, 0)): 3 stations of 8.9 mm pockets,
    # 5 mm clamp clearance and the gauge gaps need 35.7 mm before the 5 mm load clearance, and the
    # load region starts at 26.6 mm (docs/model.md §1): no section has room. The closest design's
    # stations do not fit, and its figures resolve nothing (its smallest signal was 4e-14 noise
    # levels, and the advice a noise of 5e-18 mV): the diagnosis names the room alone.
    from designer.bench.suite import _generate

    found = search.optimize(_generate(29, "infeasible-room", 0).spec)
    assert found.status == "infeasible" and len(found.messages) == 2
    assert re.match(r"load.position: no room for 3 gauge stations .* need 35.7 mm .* at least 40.7 mm",
                    found.messages[1])


LOOSER = re.compile(r"with limits\.max_deflection = ([0-9.]+) mm a (\S+) (round|rectangle|tube) .* meets every limit")


def test_a_deflection_limit_too_tight_for_the_targets_is_told_the_deflection_at_which_a_design_meets_every_limit():
    # The bench suite's 021-infeasible-deflection (generate_suite(50, 0)): 17-4PH-H900 and others,
    # a 0.01646 mm deflection limit. Its closest design, the stiffest bar allowed, deflects 0.0357
    # mm and misses its targets 31 times over: allowing that deflection alone leaves the spec without
    # a design. The advice names a limit at which one of its material and family meets every limit,
    # which the exhaustive reference search (a grid polished by SLSQP on the numeric model, no casadi)
    # confirms.
    from designer.bench.suite import _generate

    spec = _generate(20, "infeasible-deflection", 0).spec
    found = search.optimize(spec)
    # the noise that would meet the targets meets them alone: the deflection stays broken, and
    # the message says so
    [targets] = [m for m in found.messages if m.startswith("the accuracy targets are out of reach")]
    assert targets.endswith("; any of these meets the targets only: deflection stays broken")
    [said] = [m for m in found.messages if m.startswith("deflection:")]
    level, material, section = LOOSER.search(said).groups()
    least = float(re.search(r"allow at least ([0-9.]+) mm", said).group(1))
    assert not search.optimize(replace(spec, limits=replace(spec.limits, max_deflection=least * 1.01e-3))).success
    at = replace(spec, limits=replace(spec.limits, max_deflection=float(level) * 1e-3))
    family = next(f for f in search.families(at) if f.section == section and f.feature == "none")
    ref = reference.reference_search(at, family, catalogue.material(material), levels=5)
    assert ref is not None and ref.feasible


def test_a_frequency_limit_too_high_for_the_targets_is_told_the_frequency_at_which_a_design_meets_every_limit():
    # The gripper finger with limits.min_frequency = 3 kHz: its stiffest, lightest bar reaches about
    # 860 Hz and then misses its targets, so lowering the limit to that leaves it without a design;
    # the advice names a lower limit at which one of the closest design's material and family meets
    # every limit, which the exhaustive reference search confirms.
    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    spec = replace(spec, limits=replace(spec.limits, min_frequency=3000.0))
    found = search.optimize(spec)
    [said] = [m for m in found.messages if m.startswith("natural_frequency:")]
    reached = float(re.search(r"lower it to ([0-9.]+) Hz", said).group(1))
    level, material = re.search(r"with limits\.min_frequency = ([0-9.]+) Hz a (\S+) ", said).groups()
    assert float(level) < reached
    assert not search.optimize(replace(spec, limits=replace(spec.limits, min_frequency=reached * 0.99))).success
    at = replace(spec, limits=replace(spec.limits, min_frequency=float(level)))
    g = found.candidates[0].evaluation.design.geometry
    family = next(f for f in search.families(at) if (f.section, f.feature) == (g.section, g.feature))
    ref = reference.reference_search(at, family, catalogue.material(material), levels=5)
    assert ref is not None and ref.feasible


GRID = re.compile(r"domain_grid_ratio_max: the closest design's grid_ratio \(the gauge's grid length over the height\) "
                  r"is ([0-9.]+), above 0\.375, the largest of "
                  r"the 3-D study its rectangle \+ hole corrections were fitted on .*: its gauge's 3 mm grid needs a "
                  r"section at least ([0-9.]+) mm high, which limits\.height \(up to ([0-9.]+) mm\) does not allow, "
                  r"or on ([0-9.]+) mm a gauge whose grid is at most ([0-9.]+) mm long")


def test_a_gauge_grid_too_long_for_every_allowed_section_is_told_the_section_and_the_grid_that_would_do():
    # The held-out suite's 004-imperial (seed 12): BF120-3AA's 3 mm grid on rectangles with a hole at
    # most 0.278 in (7.061 mm) high. The holes' corrections were fitted on grids up to 0.375 h
    # (docs/model.md §7, its table of fits' domains), so no allowed section is inside: a section at
    # least 3 / 0.375 = 8 mm high is, or on the closest design's height a grid 0.375 h long. With
    # limits.height reaching 8 mm the closest design (the spec's targets stay out of reach) no longer
    # breaks the rule.
    from designer.bench.suite import _generate

    spec = _generate(3, "imperial", 12).spec
    found = search.optimize(spec)
    said = GRID.search(" ".join(found.messages))
    assert said is not None, found.messages
    ratio, need, top, height, grid = (float(x) for x in said.groups())
    g = found.best.design.geometry
    assert ratio == pytest.approx(3e-3 / g.height, abs=5e-4) and height == pytest.approx(g.height * 1e3, abs=1e-3)
    assert need == pytest.approx(3 / 0.375) and top == pytest.approx(0.278 * 25.4, abs=1e-3)
    assert grid == pytest.approx(0.375 * height, abs=1e-3) and grid <= 0.375 * height
    taller = replace(spec, limits=replace(spec.limits, height=(spec.limits.height[0], need * 1e-3)))
    assert "domain_grid_ratio_max" not in {v.name for v in search.optimize(taller).best.violations}


def test_a_closest_design_from_stock_keeps_the_clearances_its_grid_allows():
    # The held-out suite's 015-imperial (seed 12): stock tubes that miss only their targets. IPOPT's
    # answer put the stations at 8.45 mm and 51.4178 mm, both clearances' edges (5 mm from the clamp
    # face past the 6.9 mm gauge, 5 mm before the load at 59.8678 mm); of their grid points rounding
    # had kept 8.44 and 51.42 mm for an error ratio 1e-3 lower, 0.01 mm and 2.2 µm into the clearances,
    # and the diagnosis then told the load region to start "from 59.87 mm", where it starts. 8.45 and
    # 51.41 mm keep both (8.45 - 3.45 = 5, 59.8678 - 51.41 - 3.45 = 5.0078 mm).
    from designer.bench.suite import _generate

    found = search.optimize(_generate(14, "imperial", 12).spec)
    assert found.best.design.stock is not None and meets_rules(found.best)
    assert {v.name for v in found.best.violations} == set(model.TARGET_LIMITS)
    assert found.best.design.geometry.stations == pytest.approx((8.45e-3, 51.41e-3), abs=1e-9)
    assert not [m for m in found.messages if "past load.position" in m]


def test_where_only_the_targets_are_missed_a_binding_load_clearance_is_told_to_spread_the_stations():
    # The held-out suite's 026-imperial (seed 12): 2024-T3 round bars with flats miss only the accuracy
    # targets, both clearances binding. The room before the load region holds the stations together
    # (sigma_F grows as 1 / (d_2 - d_1) on two bridges, MODEL.md section 3), not the section: a larger
    # one lowers the strain and raises the errors, as the advice had said it would allow. Followed,
    # with the load region 5 and then 10 mm farther out the best error ratio falls each time.
    from designer.bench.suite import _generate

    spec = _generate(25, "imperial", 12).spec
    found = search.optimize(spec)
    assert {v.name for v in found.best.violations} == {"force_error"}
    [said] = [m for m in found.messages if m.startswith("load_clearance binds")]
    assert said.endswith("would let the stations lie farther apart, which lowers both errors")
    assert "larger one" not in said
    ratios = [found.best.error_ratio]
    for farther in (5e-3, 10e-3):
        moved = replace(spec, load=replace(spec.load, position_min=spec.load.position_min + farther))
        ratios.append(search.optimize(moved).best.error_ratio)
    assert ratios[0] > ratios[1] > ratios[2]


def test_a_slot_leaving_walls_thinner_than_allowed_is_told_the_bar_that_keeps_them():
    # The held-out suite's 049-short-beam (seed 12): a slot 1 mm wide (the 0.8 mm gauge and 0.1 mm
    # margins) on bars at most 1.182 mm wide leaves walls of (1.18 - 1) / 2 = 0.09 mm, under the
    # 0.1 mm least; the advice had only said "pocket_side_wall stays broken". 1 + 2 x 0.1 = 1.2 mm
    # keeps them, and with limits.width reaching that the closest design breaks no rule.
    from designer.bench.suite import _generate

    spec = _generate(48, "short-beam", 12).spec
    found = search.optimize(spec)
    [said] = [m for m in found.messages if m.startswith("pocket_side_wall:")]
    wall, bar, least, need, top = (float(x) for x in re.search(
        r"leaves walls of ([0-9.]+) mm on the closest design's ([0-9.]+) mm wide bar, under limits\.min_wall = "
        r"([0-9.]+) mm; a bar at least ([0-9.]+) mm wide, which limits\.width \(up to ([0-9.]+) mm\)", said).groups())
    assert wall == pytest.approx((bar - 1.0) / 2) and least == pytest.approx(0.1)
    assert need == pytest.approx(1.0 + 2 * 0.1) and top == pytest.approx(1.182)
    wider = replace(spec, limits=replace(spec.limits, width=(spec.limits.width[0], need * 1e-3)))
    assert meets_rules(search.optimize(wider).best)


def test_a_closest_design_on_a_depth_grid_step_is_solved_again_and_the_advice_says_what_holds_its_section():
    # The held-out suite's 036-infeasible-noise (seed 13): a Ti-6Al-4V round bar whose flat's fatigue
    # stress and smallest signal pull its diameter opposite ways. The continuous least violation of
    # the duty's limits (IPOPT, a bound on every grid design) balances them at 13.2 %; its flat,
    # 1.057 mm deep, goes to 1.1 mm on the depth's 0.05 mm grid, and the closest design had kept the
    # diameter that balanced the shallower flat: 16.0 %, where 0.05 mm more diameter gives 13.7 %.
    # The depth is now held on its grid and the rest solved again. The advice had told the stress
    # "at the closest design's Ø8.22 mm section (up to 13.24 mm)" as if a larger one were free.
    from designer.bench.suite import _generate
    from designer.search.closest import BEARING, closeness
    from designer.search.problem import FamilyProblem, start_from

    spec = _generate(35, "infeasible-noise", 13).spec
    found = search.optimize(spec)
    best, cand = found.best, found.candidates[0]
    problem = FamilyProblem(spec, cand.family)
    params = problem.params(catalogue.material(cand.material))
    _, bound = problem.least_violation(params, start_from(problem, best), soft=BEARING, free=model.TARGET_LIMITS)
    worst = closeness(best)[3]
    assert bound == pytest.approx(0.132, abs=2e-3)
    assert 1 + bound - 1e-6 <= 1 + worst <= (1 + bound) * 1.01
    [said] = [m for m in found.messages if m.startswith("fatigue_feature:")]
    assert "which the signal holds there: a larger section lowers the stress and the signal" in said
    # followed: 1 % more or less diameter (the second station moved out by the gap the rule adds)
    g = best.design.geometry
    moved = {}
    for f in (0.99, 1.01):
        D = round(float(g.diameter) * f, 5)
        stations = (g.stations[0], g.stations[1] + max(0.0, (D - float(g.diameter)) / 2))
        moved[f] = evaluate(replace(best.design, geometry=replace(g, diameter=D, stations=stations)), spec)
        assert meets_rules(moved[f]) and closeness(moved[f])[3] > worst
    normalised = {f: {lim.name: float(lim.normalised) for lim in ev.limits} for f, ev in moved.items()}
    ours = {lim.name: float(lim.normalised) for lim in best.limits}
    assert normalised[1.01]["fatigue_feature"] < ours["fatigue_feature"] < normalised[0.99]["fatigue_feature"]
    assert normalised[1.01]["min_signal_snr"] > ours["min_signal_snr"] > normalised[0.99]["min_signal_snr"]


def test_a_spec_whose_pocket_fits_no_section_allowed_is_told_the_plain_bar_that_meets_every_limit():
    # The bench suite's seed 14 023-millinewton: 2024-T3 or Ti-6Al-4V, rectangles and round bars
    # up to 1.424 mm wide and 1.324 mm high, a gauge 1.2 mm wide with 0.2 mm pocket margins: a 1.6 mm
    # pocket. No pocket fits (closed forms): a slot that wide leaves no side walls in a bar at most
    # 1.424 mm wide, and a flat p <= 0.3 D deep is at most 2 sqrt(0.3 x 0.7) D = 0.917 D wide, 1.21
    # mm on the largest round bar (Ø1.324 mm). The diagnosis had told only the flat's least bar;
    # the plain bar, its gauges bonded on its own faces, meets every limit, and the diagnosis names
    # it. Followed, the search gives that design.
    from designer.bench.suite import _generate

    spec = _generate(22, "millinewton", 14).spec
    pocket = spec.gauge.width + 2 * spec.limits.pocket_margin
    largest = min(spec.limits.width[1], spec.limits.height[1])
    f = spec.limits.max_pocket_fraction
    assert pocket == pytest.approx(1.6e-3) and spec.limits.width[1] < pocket
    assert 2 * (f * (1 - f)) ** 0.5 * largest < pocket
    found = search.optimize(spec)
    assert not found.success and spec.search.feature == "pocket"
    [said] = [m for m in found.messages if m.startswith("with search.feature: none")]
    told = re.fullmatch(r"with search\.feature: none \(the gauges bonded on the bar's own faces, not recessed in "
                        r"pockets\) "
                        r"a (\S+) rectangle ([0-9.]+) × ([0-9.]+) mm meets every limit", said)
    assert told, said
    plain = replace(spec, search=replace(spec.search, feature="none", materials=(told.group(1),)))
    followed = search.optimize(plain)
    g = followed.best.design.geometry
    assert followed.success and g.feature == "none"
    assert (g.width * 1e3, g.height * 1e3) == (pytest.approx(float(told.group(2))),
                                              pytest.approx(float(told.group(3))))



def test_a_design_outside_the_3d_study_is_told_what_the_study_s_parameter_measures():
    # The bench suite's seed 14 034-millinewton: a 1.2 mm gauge with 0.2 mm margins, a 1.6 mm slot,
    # in bars at most 1.611 mm wide. Its closest design is outside the slot study (docs/model.md §7):
    # pocket_width_ratio = w_p/b and side_wall_ratio = (b - w_p)/h, each worked out here from its
    # sizes; the message had named the parameters alone, which a user cannot look up in the spec
    from designer.bench.suite import _generate

    found = search.optimize(_generate(33, "millinewton", 14).spec)
    g = found.best.design.geometry
    assert g.section == "rectangle" and g.feature == "pocket"
    said = {m.split(":")[0]: m for m in found.messages}
    share = f"{g.pocket_width / g.width:.3g}"
    walls = f"{(g.width - g.pocket_width) / g.height:.3g}"
    assert (f"the closest design's pocket_width_ratio (the slot's width over the bar's) is {share}, above 0.865"
            in said["domain_pocket_width_ratio_max"])
    assert (f"the closest design's side_wall_ratio (the width its slot leaves, both side walls, over the height) "
            f"is {walls}, below 0.153" in said["domain_side_wall_ratio_min"])


def test_a_signal_a_hair_below_its_limit_is_told_a_force_and_a_noise_that_differ_from_the_spec_s():
    # The bench suite's seed 12 032-infeasible-deflection: its closest design's smallest signal was
    # 0.01 % below min_snr (its deflection 82 % over). The advice had read "raise load.force[0] to
    # 1.343 N" with load.force[0] at 1.343 N. The signal grows as F_min / sigma_V (docs/model.md §4):
    # at the force named (rounded up) or the noise named (rounded down) the same design meets it.
    # Where the least violation lands the signal below the deflection's violation is IPOPT's choice,
    # so here min_snr is set to leave the closest design's signal that hair below its limit.
    from designer.bench.suite import _generate
    from designer.search.diagnosis import diagnose

    spec = _generate(31, "infeasible-deflection", 12).spec
    found = search.optimize(spec)
    snr = next(lim for lim in found.best.limits if lim.name == "min_signal_snr")
    room = float(snr.limit) / spec.limits.min_snr          # the limit is min_snr (1 + u), docs/model.md §4
    spec = replace(spec, limits=replace(spec.limits, min_snr=float(snr.value) * 1.0001 / room))
    best = evaluate(found.best.design, spec)
    [said] = [m for m in diagnose(spec, best, found.candidates) if m.startswith("min_signal_snr")]
    told = re.search(r"lower the noise to ([0-9.e-]+) mV \(now ([0-9.e-]+) mV\) or raise load\.force\[0\] to "
                     r"([0-9.]+) N \(now ([0-9.]+) N\)", said)
    assert told, said
    noise, noise_now, force, force_now = told.groups()
    assert noise != noise_now and force != force_now
    snr = next(lim for lim in best.limits if lim.name == "min_signal_snr")
    assert float(snr.value) < float(snr.limit) < float(snr.value) * 1.001   # a hair below
    assert float(force) / spec.load.force_min * float(snr.value) >= float(snr.limit)
    assert spec.sigma_v / (float(noise) * 1e-3) * float(snr.value) >= float(snr.limit)
    at = replace(spec, load=replace(spec.load, force_min=float(force)))
    assert not any(v.name == "min_signal_snr" for v in evaluate(found.best.design, at).violations)


def test_a_limit_kept_inside_its_rating_is_told_with_the_rating_it_comes_from():
    # The gauge-strain and the fatigue limits keep room for the model's own uncertainty
    # (docs/model.md §4, §7): seed 13's 035-kilonewton was told its gauge allows 1181 µε, where
    # the gauge's max_strain is 1200 µε; seed 14's 009-tight-limits its 7075-T6 flats' fatigue
    # allowable as 50.48 MPa, where MODEL.md §4's min(yield, fatigue) / safety_factor is 53 MPa.
    from designer.bench.suite import _generate

    spec = _generate(34, "kilonewton", 13).spec
    [said] = [m for m in search.optimize(spec).messages if m.startswith("gauge_strain")]
    told = re.search(r"exceeds ([0-9]+) µε, the gauge's ([0-9]+) µε less the room kept for the model's "
                     "gauge-strain uncertainty,", said)
    assert told, said
    assert int(told.group(2)) == round(spec.gauge.max_strain * 1e6) == 1200 and int(told.group(1)) < 1200
    spec = _generate(8, "tight-limits", 14).spec
    found = search.optimize(spec)
    [said] = [m for m in found.messages if m.startswith("fatigue_feature")]
    m = found.best.design.material
    allowable = min(m.yield_strength, m.fatigue) / spec.limits.safety_factor
    assert f"({allowable / 1e6:.4g} MPa less the room kept for the model's stress uncertainty)" in said
