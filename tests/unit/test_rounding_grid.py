"""Rounding that breaks a limit (designer.search.ongrid.back_off): the grid around the answer searched
with the numeric model (_nearby_on_the_grid), the section held at its neighbouring 0.01 mm sizes and
the rest solved again (_on_the_grid), and the last resort."""

import itertools

import numpy as np
import pytest


def test_when_rounding_breaks_a_limit_the_best_grid_section_is_found():
    """The bench suite's 013-kilonewton (seed 2) in a 17-7PH-RH950 plain rectangle: IPOPT's answer
    (6.400 x 24.110 mm) rounded to 0.01 mm breaks the gauge-strain limit, so the section is held at
    its neighbouring grid sizes with the rest solved again. Reference: a wider search than the
    method's own, every section within 0.03 mm of the answer on the 0.01 mm grid (7 x 7) with the
    rest solved again, rounded and checked; the method's design must equal its best within the
    0.1 % tie band, meet every limit, sit on the grid, and cost little over the continuous answer
    (a lower bound). The grid's best point: 6.40 x 24.12 mm with the stations solved again,
    0.459247, 0.04 % over the continuous answer. (The case was 018-long-beam of seed 0, a bar with
    holes, until the holes' refit of docs/model.md §7 left its rounded answer meeting every limit.)"""
    from designer.bench.suite import _generate
    from designer.model import TIE_TOLERANCE
    from designer.search import in_nlp_units, material_params
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import round_and_check
    from designer.search.run import solve_candidate
    from designer.spec import catalogue

    made = _generate(12, "kilonewton", 2)      # the suite's 13th spec, as generate_suite(50, 2) makes it
    assert made.name == "013-kilonewton"
    spec = made.spec
    problem = FamilyProblem(spec, Family("rectangle", "none"))
    material = catalogue.material("17-7PH-RH950")
    params = material_params(material, spec)
    candidate = solve_candidate(problem, material, "ipopt")
    first = candidate.solves[0]
    assert first.success and not round_and_check(problem.design(first.x, material), spec).feasible
    assert any("rounding broke a limit; the section held at its neighbouring 0.01 mm sizes" in f
               for f in candidate.fallbacks)
    # the answer before rounding meets every limit, and the report says rounding broke it
    from designer.result.evaluation import evaluate
    assert evaluate(problem.design(first.x, material), spec).feasible
    assert any("its answer meets every limit, but rounding it to the manufacturing grid breaks" in f
               for f in candidate.fallbacks)
    ev = candidate.evaluation
    assert ev.feasible
    g = ev.design.geometry
    for size in (g.width, g.height):
        assert size / 1e-5 == pytest.approx(round(size / 1e-5), abs=1e-6)

    index = [problem.names.index("width"), problem.names.index("height")]
    centre = [round(first.x[i] * 100) / 100 for i in index]           # mm, on the grid
    best = np.inf
    for steps in itertools.product(range(-3, 4), repeat=2):
        fixed = {i: c + 0.01 * k for i, c, k in zip(index, centre, steps)}
        s = problem.solve_ipopt(params, first.x, fixed=fixed)
        if not s.success:
            continue
        trial = round_and_check(problem.design(s.x, material), spec)
        if trial is not None and trial.feasible:
            best = min(best, trial.objective)
    assert np.isfinite(best)
    assert ev.objective <= best * (1 + TIE_TOLERANCE)
    continuous = float(problem.functions(first.x, params)[0])
    assert continuous <= in_nlp_units(ev.objective, spec.objective) <= continuous * 1.005   # measured +0.04 %


def test_the_last_resort_tightens_only_the_limits_rounding_broke(monkeypatch):
    """The bench suite's 024-kilonewton (seed 0) on a 2024-T3 bar with slots, the grid searches and
    the depth-held re-solve made to find nothing: the back-off solves again with only the broken
    limits (one or two of them; the fatigue limit at the slot with the model of docs/model.md §7)
    tightened. Reference: the back-off it replaced, the same re-solve with every limit tightened by
    the same margin, or by a multiple of it until its rounded design meets every limit; tightening
    only the broken limits leaves more room, so the answer is no worse than that one's, meets every
    limit, and costs at most 2 % over the continuous answer (a lower bound)."""
    from designer.bench.suite import _generate
    from designer.search import in_nlp_units, material_params
    from designer.search import ongrid, run
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import round_and_check
    from designer.spec import catalogue

    spec = _generate(23, "kilonewton", 0).spec
    problem = FamilyProblem(spec, Family("rectangle", spec.search.feature))
    material = catalogue.material("2024-T3")
    params = material_params(material, spec)
    monkeypatch.setattr(ongrid, "_on_the_grid", lambda *args, **kwargs: None)
    monkeypatch.setattr(ongrid, "_nearby_on_the_grid", lambda *args: None)
    monkeypatch.setattr(ongrid, "_depth_held", lambda *args: None)
    candidate = run.solve_candidate(problem, material, "ipopt")
    note = next(f for f in candidate.fallbacks if "tightened by" in f)
    first = candidate.solves[int(note.split("start ")[1].split(":")[0]) - 1]    # the start rounding broke
    broken = round_and_check(problem.design(first.x, material), spec)
    names = sorted(v.name for v in broken.violations)
    assert 0 < len(names) <= 2 < len(broken.limits)    # not every limit: the test's premise
    assert f"re-solved with {', '.join(names)} tightened by" in note
    margin = float(note.split("tightened by ")[1].split(";")[0])
    ev = candidate.evaluation
    assert ev.feasible
    for k in range(1, 11):
        every = problem.solve_ipopt(params, first.x, margin=k * margin)
        reference = round_and_check(problem.design(every.x, material), spec)
        if reference.feasible:
            break
    assert reference.feasible
    assert ev.objective <= reference.objective * (1 + 1e-9)
    continuous = float(problem.functions(first.x, params)[0])
    # the last resort is not free (the limit is held the margin inside its bound): the grid searches
    # above are what keep rounding within the tie band; measured +0.13 % (every limit tightened: 1 % more)
    assert continuous <= in_nlp_units(ev.objective, spec.objective) <= continuous * 1.02


@pytest.mark.parametrize("material", ["17-4PH-H900", "2024-T3"])
def test_rounding_finds_the_best_design_of_a_wider_grid(material):
    """The gripper finger's tube, whose IPOPT answer rounding breaks (the flat's chord, and for
    2024-T3 also its fatigue limit and the wall ratio the corrections were fitted for); the flat's
    depth moves to its 0.05 mm grid, which the numeric box of 0.02 mm around the sizes cannot make
    up, so the depth is held at its grid values and the rest solved again (``ongrid._depth_held``).
    Reference: brute force over a wider box of the grid than the method searches, every
    combination of the diameter and wall from 5 steps of 0.01 mm below their rounded-down to 5
    above their rounded-up value, the flat depth 3 steps of 0.05 mm either way, and the stations
    rounded down or up, each judged on its own by the evaluator; the method's design must meet
    every limit, lie on the grid and be the box's best within the 0.1 % tie band."""
    from dataclasses import replace

    from designer.model import TIE_TOLERANCE
    from designer.result.evaluation import evaluate
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import floor_ceil, round_and_check
    from designer.search.run import solve_candidate
    from designer.spec import catalogue
    from designer.spec.reader import load_spec
    from pathlib import Path

    from designer.spec.tolerances import Tolerances

    spec = replace(load_spec(Path(__file__).resolve().parents[2] / "examples" / "gripper-finger.yaml"),
                   tolerances=Tolerances("none"))  # the answer's rounding, at nominal sizes
    problem = FamilyProblem(spec, Family("tube", spec.search.feature))
    mat = catalogue.material(material)
    candidate = solve_candidate(problem, mat, "ipopt")
    design = problem.design(candidate.solves[0].x, mat)
    assert not round_and_check(design, spec).feasible, "rounding breaks a limit"
    found = candidate.evaluation
    assert found is not None and found.feasible
    g = found.design.geometry
    for size in (g.diameter, g.wall, *g.stations):
        assert size / 1e-5 == pytest.approx(round(size / 1e-5), abs=1e-6)
    assert g.depth / 5e-5 == pytest.approx(round(g.depth / 5e-5), abs=1e-6)   # depths to 0.05 mm

    g0 = design.geometry
    best = np.inf
    for d, t, h, *st in itertools.product(floor_ceil(g0.diameter, 5), floor_ceil(g0.wall, 5), floor_ceil(g0.depth, 3, 5e-5),
                                          *[floor_ceil(s) for s in g0.stations]):
        trial = replace(design, geometry=replace(g0, diameter=d, wall=t, depth=h, stations=tuple(st)))
        ev = evaluate(trial.rounded(spec.cad), spec)
        if ev.feasible:
            best = min(best, ev.objective)
    assert np.isfinite(best)
    assert found.objective <= best * (1 + TIE_TOLERANCE)


def test_a_rounding_that_costs_more_than_the_tie_band_searches_the_grid_around_the_answer():
    """Prototype B's round bars: where rounding IPOPT's answer down or up meets every limit but
    costs more than the 0.1 % tie band against the continuous answer, the grid around it is
    searched. Reference: brute force over the grid from 3 steps below the rounded-down to 3 above
    the rounded-up diameter (0.01 mm) and flat depth (0.05 mm), the stations rounded down or up, each judged
    on its own by the evaluator; the reported design is that box's best within the tie band, and
    on at least one material better than the plain rounding by more than the tie band."""
    from dataclasses import replace

    from designer.model import TIE_TOLERANCE
    from designer.result.evaluation import evaluate
    from designer.search import in_nlp_units
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import floor_ceil, round_and_check
    from designer.search.run import solve_candidate
    from designer.spec import catalogue
    from designer.spec.reader import load_spec
    from pathlib import Path

    from designer.spec.tolerances import Tolerances

    spec = replace(load_spec(Path(__file__).resolve().parents[2] / "examples" / "prototype-b-optimized.yaml"),
                   tolerances=Tolerances("none"))  # the answer's rounding, at nominal sizes
    problem = FamilyProblem(spec, Family("round", spec.search.feature))
    costly, gains = 0, []
    for name in ("2024-T3", "Ti-6Al-4V", "7075-T6", "6061-T6"):
        mat = catalogue.material(name)
        candidate = solve_candidate(problem, mat, "ipopt")
        first = candidate.solves[0]
        design = problem.design(first.x, mat)
        rounded = round_and_check(design, spec)
        continuous = float(problem.functions(first.x, problem.params(mat))[0])
        if not (rounded.feasible and in_nlp_units(rounded.objective, spec.objective) > continuous * (1 + TIE_TOLERANCE)):
            continue
        costly += 1
        g0 = design.geometry
        best = np.inf
        for d, h, *st in itertools.product(floor_ceil(g0.diameter, 3), floor_ceil(g0.depth, 3, 5e-5),
                                           *[floor_ceil(s) for s in g0.stations]):
            ev = evaluate(replace(design, geometry=replace(g0, diameter=d, depth=h, stations=tuple(st))).rounded(spec.cad),
                          spec)
            if ev.feasible:
                best = min(best, ev.objective)
        found = candidate.evaluation
        assert found.feasible and found.objective <= best * (1 + TIE_TOLERANCE), name
        gains.append(rounded.objective / found.objective - 1)
    assert costly >= 2
    assert max(gains) > TIE_TOLERANCE


@pytest.mark.slow
def test_the_grid_search_walks_past_steps_that_gain_less_than_the_tie_band():
    """The bench suite's 022-loose-limits, 2024-T3 rectangle without a feature: rounding the height
    up to 1.71 mm moves the best width 0.07 mm below the continuous one, each 0.01 mm step of it
    gaining under the 0.1 % tie band. Reference: brute force over widths from 12 steps below the
    rounded-down to 3 above the rounded-up value, heights 3 steps either way, the stations rounded
    down or up, each judged by the evaluator; the search's design is that box's best within the
    tie band."""
    from dataclasses import replace

    from designer.bench.suite import generate_suite
    from designer.model import TIE_TOLERANCE
    from designer.result.evaluation import evaluate
    from designer.search.ongrid import _nearby_on_the_grid
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import floor_ceil
    from designer.spec import catalogue

    spec = next(m.spec for m in generate_suite(50, 0) if m.name == "022-loose-limits")
    problem = FamilyProblem(spec, Family("rectangle", spec.search.feature))
    mat = catalogue.material("2024-T3")
    s = problem.solve_ipopt(problem.params(mat), problem.starts()[0])
    found = _nearby_on_the_grid(problem, mat, s)
    design = problem.design(s.x, mat)
    g0 = design.geometry
    widths = [round(g0.width - k * 1e-5, 8) for k in range(1, 13)] + list(floor_ceil(g0.width, 3))
    best = np.inf
    for b, h, *st in itertools.product(widths, floor_ceil(g0.height, 3), *[floor_ceil(x) for x in g0.stations]):
        ev = evaluate(replace(design, geometry=replace(g0, width=b, height=h, stations=tuple(st))).rounded(spec.cad),
                      spec)
        if ev.feasible:
            best = min(best, ev.objective)
    assert found is not None and found.feasible and found.objective <= best * (1 + TIE_TOLERANCE)


@pytest.mark.parametrize("name, step", [("gripper-finger", None), ("probe", None), ("weigh-bar", 2e-4)])
def test_the_search_reports_pocket_depths_a_shop_can_set(name, step):
    """The machining rule (docs/model.md §5): pocket and flat depths to 0.05 mm (or the spec's
    ``cad.depth_step``), the other lengths to 0.01 mm. The reported design lies on those grids
    and meets every limit when judged afresh from its numbers by the evaluator (not the search's
    own record)."""
    from dataclasses import replace
    from pathlib import Path

    from designer.result.evaluation import evaluate
    from designer.search import optimize
    from designer.spec.reader import load_spec

    spec = load_spec(Path(__file__).resolve().parents[2] / "examples" / f"{name}.yaml")
    if step is not None:
        spec = replace(spec, cad=replace(spec.cad, depth_step=step))
    found = optimize(spec)
    g = found.best.design.geometry
    assert g.feature == "pocket"
    grid = 5e-5 if step is None else step
    assert g.depth / grid == pytest.approx(round(g.depth / grid), abs=1e-6)
    for size in (g.width, g.height, g.diameter, *g.stations):
        if size is not None:
            assert size / 1e-5 == pytest.approx(round(size / 1e-5), abs=1e-6)
    assert evaluate(found.best.design, spec).feasible


@pytest.mark.slow
def test_when_nothing_near_holds_a_wider_box_is_searched_before_any_limit_is_tightened():
    """The bench suite's 024-kilonewton (seed 2), a 301-full-hard bar with holes of continuous
    sizes: rounding IPOPT's answer breaks the gauge strain, the deflection and the hole's domain
    limit, and neither the numeric box two steps wide nor the re-solve with the section held finds
    a design that meets every limit, so a box eight steps wide is searched (before any limit is
    tightened: on an earlier model's 040-long-beam, a bar with a hole, tightening the broken limit
    gave a design 6 % worse than the wider box's). Reference: brute force, every width, height and
    hole from 8 steps below their rounded-down to 8 above their rounded-up value, every station
    rounded down or up, each judged on its own by the evaluator; the candidate's design must meet
    every limit and be that box's best within the 0.1 % tie band. (An earlier model's seed-0
    002-kilonewton, a 7075-T6 tube, had shown the same before the tubes' near-clamp fit was fitted
    again.)"""
    from dataclasses import replace

    from designer.bench.suite import generate_suite
    from designer.errors import InputError
    from designer.model import TIE_TOLERANCE
    from designer.result.evaluation import evaluate
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import floor_ceil, round_and_check
    from designer.search.run import solve_candidate
    from designer.spec import catalogue

    spec = next(m.spec for m in generate_suite(50, 2) if m.name == "024-kilonewton")
    problem = FamilyProblem(spec, Family("rectangle", "hole"))
    mat = catalogue.material("301-full-hard")
    candidate = solve_candidate(problem, mat, "ipopt")
    first = candidate.solves[0]
    design = problem.design(first.x, mat)
    assert first.success and not round_and_check(design, spec).feasible, "rounding breaks a limit"
    assert any("rounding broke a limit; the best design on a wider grid" in f for f in candidate.fallbacks)
    found = candidate.evaluation
    assert found is not None and found.feasible

    g0 = design.geometry
    best = np.inf
    for width, height, hole, *st in itertools.product(floor_ceil(g0.width, 8), floor_ceil(g0.height, 8),
                                                      floor_ceil(g0.hole, 8), *[floor_ceil(x) for x in g0.stations]):
        try:
            ev = evaluate(replace(design, geometry=replace(g0, width=width, height=height, hole=hole,
                                                           stations=tuple(st))).rounded(spec.cad), spec)
        except InputError:  # a hole wider than the bar: no bar
            continue
        if ev.feasible:
            best = min(best, ev.objective)
    assert np.isfinite(best)
    assert found.objective <= best * (1 + TIE_TOLERANCE)


def test_a_depth_held_on_its_grid_holds_the_section_on_its_grid_too():
    """The held-out suite's 009-tight-limits (seed 1; bench_3d_seed1.md), a 17-7PH-RH950 round bar
    with flats and its mass the objective, where rounding is hard: 0.01 mm of diameter moves the
    force error 0.3 %, the fatigue limit binds, and the stations are only rounded. IPOPT's answer
    breaks a limit on the grid; the depth held at its grid value (``cad.depth_step`` 0.05 mm) and
    the rest solved again finds the design (without that solve the search reports one 2.7 % heavier).
    Reference: every design of the 0.01 mm grid round it (diameter 11.33-11.53 mm, first station
    20.50-23.50 mm, flats 0.70, 0.75 or 0.80 mm deep, the last station as found) judged by the
    numeric model: the search's design is at least as light as the best of them that meets every
    limit, within the tie band. (With the K_t fits before the study refined its floor radii whole,
    the search had reported Ø11.42 mm, 4.4 % heavier than a design built by hand, and 2.7 % heavier
    than ISRES's design on `fpdesign bench --seed 1`.)"""
    from dataclasses import replace

    from designer.bench.suite import _generate
    from designer.model import TIE_TOLERANCE
    from designer.result.evaluation import evaluate
    from designer.search import optimize

    made = _generate(8, "tight-limits", 1)
    assert made.name == "009-tight-limits" and made.spec.objective == "mass"
    found = optimize(made.spec)
    assert found.success and found.best.feasible
    design = found.best.design
    g0 = design.geometry
    best = np.inf
    for depth, d, first in itertools.product((0.70, 0.75, 0.80), np.arange(1133, 1154), np.arange(2050, 2351)):
        g = replace(g0, diameter=d * 1e-5, depth=depth * 1e-3, stations=(first * 1e-5, g0.stations[1]))
        ev = evaluate(replace(design, geometry=g).rounded(made.spec.cad), made.spec)
        if ev.feasible:
            best = min(best, ev.objective)
    assert np.isfinite(best)
    assert float(found.best.objective) <= best * (1 + TIE_TOLERANCE)


def test_a_run_that_reported_success_is_said_to_be_broken_by_its_answer_or_by_its_rounding(monkeypatch):
    """The report's solver notes tell the two apart: the answer itself breaking a limit (the
    solver's success flag is not trusted) and an answer that meets every limit whose grid
    neighbours do not. The gripper finger's Ti-6Al-4V round bar: its IPOPT answer meets every
    limit; held at Ø16.8 mm it breaks diameter_max, which the spec's limits.width [4 mm, 16 mm]
    puts at 16 mm, by 16.8 / 16 - 1 = 5 %."""
    from dataclasses import replace
    from pathlib import Path

    from designer.result.evaluation import evaluate
    from designer.search import material_params
    from designer.search.methods import solve
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import what_broke
    from designer.spec import catalogue
    from designer.spec.reader import load_spec

    spec = load_spec(Path(__file__).parents[2] / "examples" / "gripper-finger.yaml")
    problem = FamilyProblem(spec, Family("round", spec.search.feature))
    material = catalogue.material("Ti-6Al-4V")
    answer = solve(problem, "ipopt", material_params(material, spec), problem.starts()[0], 0.0)
    assert answer.success and evaluate(problem.design(answer.x, material), spec).feasible
    wide = answer.x.copy()
    wide[problem.names.index("diameter")] = 16.8
    too_wide = evaluate(problem.design(wide, material), spec)

    broken_answer = what_broke(problem, material, replace(answer, x=wide), too_wide)
    assert broken_answer.startswith("reported success but its answer violates ")
    assert "diameter_max (by 5 % of its bound)" in broken_answer

    broken_rounding = what_broke(problem, material, answer, too_wide)
    assert broken_rounding.startswith("its answer meets every limit, but rounding it to the manufacturing grid ")
    assert "diameter_max (by 5 % of its bound)" in broken_rounding

    # an answer the model gives no number at is said so, not raised out of the search
    from designer.errors import InputError
    from designer.search import rounding

    def unjudged(*_):
        raise InputError("the design cannot be evaluated")

    monkeypatch.setattr(rounding, "evaluate", unjudged)
    not_judged = what_broke(problem, material, answer, too_wide)
    assert "an answer the model cannot judge" in not_judged and "diameter_max (by 5 % of its bound)" in not_judged
