"""The optimiser (issue 3) in the library: its answers measured against an exhaustive
reference search that shares no code with casadi or nlopt, the ranking rule of MODEL.md
section 5, every search method, and the casadi graph against the numeric model.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from designer.spec import catalogue
from designer.result import designfile
from designer.outputs import report
from designer import model, search
from designer.result.record import search_record
from designer.search import reference
from designer.search.diagnosis import diagnose
from designer.errors import SpecError
from designer.result.evaluation import evaluate, fixed_design
from designer.spec.reader import load_spec, parse_spec_text
from designer.spec.tolerances import Tolerances
from shared_inputs import optimize_spec_text as _spec_text

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


# The acceptance bound of issue 3: the reported objective within 0.5 % of the reference.
REFERENCE_GAP = 5e-3


def _reduced(spec, materials, sections):
    """The same spec restricted to a few materials and families, to keep the test fast."""
    return replace(spec, search=replace(spec.search, materials=tuple(materials), sections=tuple(sections)))


@pytest.mark.slow
@pytest.mark.parametrize("name, materials, sections", [
    ("gripper-finger", ["7075-T6", "Ti-6Al-4V"], ["rectangle", "tube"]),
    ("weigh-bar", ["Ti-6Al-4V", "17-4PH-H900"], ["round", "tube"]),
    ("probe", ["7075-T6", "6061-T6"], ["rectangle", "round"]),
    ("prototype-b-optimized", ["2024-T3", "7075-T6"], ["rectangle", "round"]),
])
def test_objective_within_half_a_percent_of_reference_search(name, materials, sections):
    # Reference: reference.reference_best, a dense grid over every variable polished by scipy
    # SLSQP on the numeric model; it shares no code with casadi or nlopt.
    spec = _reduced(load_spec(EXAMPLES / f"{name}.yaml"), materials, sections)
    outcome = search.optimize(spec)
    ref = reference.reference_best(spec, levels=6)
    assert outcome.success and ref.feasible
    assert outcome.best.feasible
    assert outcome.best.objective <= ref.objective * (1 + REFERENCE_GAP)


@pytest.mark.slow
def test_the_reference_search_holds_a_flat_s_depth_on_its_grid_and_meets_the_optimiser():
    # The reference search (grid + SLSQP on the numeric model, no casadi) is the optimiser's
    # yardstick. A flat's depth is drawn on a 0.05 mm grid (cad.depth_step): rounded alone from
    # its polished answer (the gripper finger's Ti-6Al-4V bar: 7.971 mm, flats 1.632 mm deep) the
    # design cost 2.3 % (0.40885 against 0.39959 before rounding). Polished again with the depth
    # held at 1.60 and 1.65 mm, it is within the tie band of IPOPT's design, found independently.
    spec = _reduced(load_spec(EXAMPLES / "gripper-finger.yaml"), ["Ti-6Al-4V"], ["round"])
    ours = search.optimize(spec).best
    (family,) = search.families(spec)
    ref = reference.reference_search(spec, family, catalogue.material("Ti-6Al-4V"), levels=5)
    assert ours.feasible and ref.feasible
    assert abs(float(ref.objective) / float(ours.objective) - 1) <= model.TIE_TOLERANCE


def test_infeasible_and_ranked_least_infeasible_first():
    # docs/model.md §5: a beam first, then a design keeping the geometry's own rules, then the
    # least worst violation of the duty's limits but the targets, then of the targets
    from designer.search.closest import closeness

    spec = parse_spec_text(_spec_text(limits="  max_deflection: 0.001 mm"))
    outcome = search.optimize(spec)
    keys = [closeness(c.evaluation) for c in outcome.candidates if c.evaluation is not None]
    assert keys == sorted(keys)
    assert outcome.x.material.name == outcome.candidates[0].material
    # a 1 µm deflection limit leaves a beam too stiff for its signal: the closest design keeps
    # every rule of the geometry, and breaks only limits of its duty
    best = outcome.candidates[0].evaluation
    broken = {v.name for v in best.violations}
    assert "deflection" in broken and broken <= set(model.DUTY_LIMITS)


def test_a_group_of_materials_proved_infeasible_is_infeasible_in_each():
    # The weigh-bar narrowed to 14 mm, on plain bars (a slot in a rectangle that tall would be more
    # than 4 gauge grids long, outside the pocket study, docs/model.md §7; the design reported
    # before, 30.5 mm slots under a 3 mm grid, read 0.982 of the model in 3-D): no round bar or
    # tube that thin meets its limits. In both
    # families the first material's first start ends in an infeasibility verdict, and the NLP with
    # the material's properties free between the least and the greatest of every material's has no
    # feasible design either, so no other material is solved; the rectangles (a bar 14 mm wide but
    # taller) are. Reference: each round bar's material solved on its own from every start
    # (solve_candidate, as the search did before): none is feasible.
    spec = load_spec(EXAMPLES / "weigh-bar.yaml")
    spec = replace(spec, limits=replace(spec.limits, width=(0.010, 0.014)), search=replace(spec.search, feature="none"))
    found = search.optimize(spec)
    assert found.success and found.best.design.geometry.section == "rectangle"
    began = [c for c in found.candidates if any(f.startswith("its other starts not run") for f in c.fallbacks)]
    proved = [c for c in found.candidates if any(f.startswith("not solved: infeasible") for f in c.fallbacks)]
    assert {(c.family.label, c.material) for c in began} == {(f, "6061-T6") for f in ("tube", "round")}
    assert len(proved) == 2 * (len(spec.search.materials) - 1)
    assert {c.family.label for c in proved} == {"tube", "round"}
    for cand in began + proved:  # a tube's continuous answer, as its stock rows were not tried
        assert cand.status == "infeasible" and not (cand.evaluation or cand.continuous).feasible
    problem = search.FamilyProblem(spec, search.Family("round", spec.search.feature))
    for cand in [c for c in began + proved if c.family.label == "round"]:
        alone = search.solve_candidate(problem, catalogue.material(cand.material), "ipopt", all_starts=True)
        assert alone.evaluation is None or not alone.evaluation.feasible, cand.material


def test_a_family_tries_first_the_start_that_served_its_last_material():
    # The probe's rectangles: from the first usual start (sections at 35 % of their range) IPOPT
    # ends most materials in a local infeasibility verdict, from the second it succeeds. Once a
    # material has succeeded from the second, the next ones start there: one solve each instead
    # of two for at least three of them (five measured), and the same designs (reference: each
    # material solved from the usual order alone).
    spec = load_spec(EXAMPLES / "probe.yaml")
    fam = search.Family("rectangle", spec.search.feature)
    found = search.optimize(spec)
    problem = search.FamilyProblem(spec, fam)
    rects = [c for c in found.candidates if c.family == fam]
    helped = []
    for cand in rects[1:]:
        alone = search.solve_candidate(problem, catalogue.material(cand.material), "ipopt")
        if alone.solves[0].message == "Infeasible_Problem_Detected" and cand.solves[0].message == "Solve_Succeeded":
            helped.append(cand.material)
            assert cand.evaluation.objective == pytest.approx(alone.evaluation.objective, rel=model.TIE_TOLERANCE)
    assert len(helped) >= 3, [c.material for c in rects]


def test_with_no_feasible_family_every_candidate_is_solved_on_its_own(monkeypatch):
    # When nothing is feasible, the least-infeasible design (and the diagnosis built on it) must
    # be each candidate's own solve, not a design at a relaxation's answer.
    proofs = []
    relax = search.FamilyProblem.infeasible_for_every

    def spy(self, materials, starts=None):
        out = relax(self, materials, starts)
        proofs.append(out[0])
        return out

    monkeypatch.setattr(search.FamilyProblem, "infeasible_for_every", spy)
    weigh_bar = load_spec(EXAMPLES / "weigh-bar.yaml")
    spec = replace(weigh_bar, limits=replace(weigh_bar.limits, max_deflection=1e-6))
    outcome = search.optimize(spec)
    assert not outcome.success
    assert any(proofs), "a group of materials was proved infeasible"
    for cand in outcome.candidates:
        assert not any(f.startswith(("not solved: infeasible", "its other starts not run")) for f in cand.fallbacks)
        # every start of its own: the relaxation's solves come first where they are kept
        assert len([s for s in cand.solves if s.x.size and s.method == "ipopt"]) >= 2


class _Fake:
    """The parts of an Evaluation that ranking reads."""

    def __init__(self, objective, deflection, mass):
        self.objective = objective
        self.analysis = type("A", (), {"deflection": deflection, "mass": mass})()
        self.feasible = True


def test_ties_within_a_tenth_of_a_percent_rank_by_deflection_then_mass():
    # MODEL.md section 5: objectives within 0.1 % rank by lower deflection, then lower mass.
    a = _Fake(1.0000, 2e-3, 0.5)
    b = _Fake(1.0008, 1e-3, 0.9)   # ties with a, stiffer: first
    c = _Fake(1.0005, 1e-3, 0.3)   # ties with a and b, as stiff as b and lighter: before b
    d = _Fake(0.9950, 5e-3, 1.0)   # 0.5 % better: first of all, whatever its deflection
    assert model.rank([a, b, c, d]) == [d, c, b, a]
    assert model.rank([b, a]) == model.rank([a, b])


def test_materials_that_tie_rank_deterministically():
    # A strain-limited design has a material-independent sensitivity k = V G g n eps/(4 F (x - d1)),
    # so several materials tie within 0.1 %; the answer must not depend on the catalogue order.
    spec = load_spec(EXAMPLES / "prototype-b-optimized.yaml")
    spec = _reduced(spec, ["2024-T3", "7075-T6", "6061-T6"], ["round"])
    first = search.optimize(spec)
    again = search.optimize(replace(spec, search=replace(spec.search, materials=tuple(reversed(spec.search.materials)))))
    assert first.x.material.name == again.x.material.name


@pytest.mark.parametrize("method", ["slsqp", "mma", "cobyla", "direct", "grid"])
def test_every_method_returns_a_verified_result(method):
    spec = _reduced(load_spec(EXAMPLES / "gripper-finger.yaml"), ["7075-T6"], ["rectangle", "round"])
    outcome = search.optimize(spec, method=method)
    assert outcome.solver["method"] == method
    # Whatever the method said, what is reported meets the limits. From design.json's numbers
    # alone, without the model: the root stress F x c/I of the plain section (Gere & Goodno,
    # sigma = M c/I) within min(yield, fatigue)/safety factor, and the free-end deflection of the
    # plain beam, F x^2 (3l - x)/(6EI), which the pockets only increase, within max_deflection.
    # Then the whole design, rebuilt from the record, evaluated afresh.
    record = json.loads(json.dumps(search_record(spec, outcome)))
    d, limits = record["design"], spec.limits
    section, props = d["section"], d["material_properties"]
    if section["kind"] == "rectangle":
        inertia, fibre = section["width"] * section["height"] ** 3 / 12, section["height"] / 2
    else:
        bore = section["diameter"] - 2 * section["wall"] if section["kind"] == "tube" else 0.0
        inertia, fibre = math.pi * (section["diameter"] ** 4 - bore ** 4) / 64, section["diameter"] / 2
    force, x, ell = spec.load.force_max, spec.load.position_max, d["length"]
    strength = min(props["yield"], props["fatigue"]) if limits.fatigue else props["yield"]
    assert force * x * fibre / inertia <= strength / limits.safety_factor * (1 + 1e-9)
    assert force * x ** 2 * (3 * ell - x) / (6 * props["E"] * inertia) <= limits.max_deflection * (1 + 1e-9)
    rebuilt_spec, design = designfile.rebuild(record)
    assert evaluate(design, rebuilt_spec).feasible
    assert outcome.success
    if method in ("slsqp", "mma", "cobyla"):
        # local methods from the same start points reach IPOPT's answer or fall back to it;
        # the global ones (DIRECT, grid) are measured, not bounded, by `fpdesign bench`
        ref = search.optimize(spec).best.objective
        assert outcome.best.objective <= ref * 1.01


def test_the_derivative_free_method_finishes_where_the_sharpness_bound_is_near():
    """nlopt's COBYLA can loop for good inside its own linear programs, whatever its evaluation and
    time budgets (nlopt issue #370): with the sharpness bound written as a ratio to the least of
    the hull's lines, the bench suite's first spec (seed 0: a titanium slot near the bound) kept
    it past 7 minutes. With one linear row per hull line it finishes in about a second; run in
    its own process so that a relapse fails instead of hanging the tests."""
    import subprocess
    import sys

    from designer.bench.suite import generate_suite

    code = ("from designer.bench.suite import generate_suite\n"
            "from designer.search import optimize\n"
            "item = generate_suite(50, 0)[0]\n"
            "out = optimize(item.spec, 'cobyla')\n"
            "print(item.name, out.status, out.best.objective)\n")
    try:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.fail("--method cobyla did not finish the bench suite's first spec in 120 s")
    assert done.returncode == 0, done.stderr
    name, status, objective = done.stdout.split()
    assert name == "001-millinewton" and status == "optimal"
    assert float(objective) <= search.optimize(generate_suite(50, 0)[0].spec).best.objective * 1.01


def test_a_non_finite_answer_is_a_failed_run_not_a_crash(monkeypatch):
    """nlopt's SLSQP can end on NaN and report success ("maxeval reached"; nlopt issue #28): on
    the bench suite's 043-infeasible-deflection (seed 1) its first start once did, and rounding that
    answer raised ValueError, so ``optimize`` failed. An nlopt run made to end so (issue #370's
    problem, the one the watchdog's tests solve) is recorded as a failed run at its finite start,
    as a run nlopt ends by raising is (on today's model that spec's SLSQP runs end so, roundoff-
    limited, and the search calls it infeasible, as IPOPT does)."""
    import nlopt

    from designer.search import nlopt_adapter

    real = nlopt.opt

    class EndsOnNaN:
        def __init__(self, *args):
            self._opt = real(*args)

        def __getattr__(self, name):
            return getattr(self._opt, name)

        def optimize(self, x):
            return np.full_like(np.asarray(self._opt.optimize(x), dtype=float), np.nan)

    class Issue370:
        epigraph = False
        size = 2
        n_constraints = 0

        def bounds(self):
            return np.full(2, -10.0), np.full(2, 10.0)

        def functions(self, x, params):
            u = 2 - np.cos(x[0]) + x[1] ** 2
            return np.array([[u * u]]), np.array([2 * u * np.sin(x[0]), 4 * u * x[1]]), np.zeros(0), np.zeros((0, 2))

    assert nlopt_adapter._nlopt_run(Issue370(), "slsqp", None, [0.5, 0.5]).success    # as nlopt ends it
    monkeypatch.setattr(nlopt, "opt", EndsOnNaN)
    run = nlopt_adapter._nlopt_run(Issue370(), "slsqp", None, [0.5, 0.5])
    assert not run.success and "at a non-finite point" in run.message
    assert list(run.x) == [0.5, 0.5]


def test_a_family_on_stock_keeps_no_other_out_of_the_contenders():
    """The bench suite's 011-loose-limits (seed 0, the mass objective): IPOPT's first start gives the
    2024-T3 rectangles a local optimum 6.4 % heavier (a 1.14 mm deep pocket) than the one from the
    next start (0.5 mm); the tubes' continuous answer, which their stock rows do not reach, had
    kept the rectangles out of the contenders that are solved from every start. The reference
    search (``reference.reference_best``, exhaustive grid and SLSQP polish, neither IPOPT nor the
    pipeline) finds 0.035353 kg: the default is within the tie band of it (the local optimum's figures
    are of an earlier model, whose reference was 0.035296 kg)."""
    from designer.bench.suite import generate_suite

    spec = next(i for i in generate_suite(50, 0) if i.name == "011-loose-limits").spec
    ref = reference.reference_best(spec, levels=5)
    assert ref.feasible and float(ref.objective) == pytest.approx(0.035353, rel=1e-4)
    best = search.optimize(spec).best
    assert best.feasible and model.ties(best.objective, ref.objective)


def test_the_tie_rule_keeps_a_design_inside_the_band_of_a_lower_one():
    """The bench suite's 033-loose-limits (seed 0, the error objective): a 2024-T3 round bar with
    flats whose rounding breaks the flat's chord. The design below (Ø6.09 mm, flats 1.80 mm deep,
    gauges at 9.45 and 81.59 mm, as CCSAQ and COBYLA found it) meets every limit; the default's
    answer is within the 0.1 % tie band of it: the depth held at 1.80 mm as well as at the nearer
    1.75 mm, and the tie rule's re-solve kept within half the band of the best (at the whole band
    it chose a stiffer bar 0.103 % above this one)."""
    from designer.bench.suite import generate_suite

    spec = next(i for i in generate_suite(50, 0) if i.name == "033-loose-limits").spec
    best = search.optimize(spec).best
    g = replace(best.design.geometry, diameter=6.09e-3, depth=1.80e-3, stations=(9.45e-3, 81.59e-3))
    known = evaluate(replace(best.design, geometry=g, material=catalogue.material("2024-T3")), spec)
    assert known.feasible
    assert best.feasible and best.objective <= known.objective * (1 + model.TIE_TOLERANCE)


def test_casadi_graph_and_numeric_model_agree_at_the_optimum():
    # The physics is written once: the casadi function of the NLP and the numeric check agree
    # (at the nominal sizes; the tolerance corners' rows: test_tolerances.py).
    spec = replace(load_spec(EXAMPLES / "gripper-finger.yaml"), tolerances=Tolerances("none"))
    fam = search.Family("tube", "pocket")
    problem = search.FamilyProblem(spec, fam)
    mat = catalogue.material("7075-T6")
    params = search.material_params(mat, spec)
    x = problem.starts()[0]
    f, _, g, _ = problem.functions(x, params)
    ev = evaluate(problem.design(x, mat), spec)
    numeric = {lim.name: float(lim.normalised) for lim in ev.limits}
    for name, value in zip(problem.limit_names, np.asarray(g).ravel()):
        assert value == pytest.approx(numeric[name], rel=1e-9, abs=1e-12)
    e = max(float(ev.analysis.force_error) / spec.targets.force_error,
            float(ev.analysis.position_error) / spec.targets.position_error)
    # the epigraph rows follow the limits: force, position; then the idle tie-band cap
    g = np.asarray(g).ravel()
    assert g[-3] + x[-1] == pytest.approx(float(ev.analysis.force_error) / spec.targets.force_error)
    assert g[-2] + x[-1] == pytest.approx(float(ev.analysis.position_error) / spec.targets.position_error)
    assert e == pytest.approx(ev.error_ratio)


@pytest.mark.parametrize("key, level", [("max_deflection", 0.37e-3), ("min_frequency", 410.0)])
def test_a_swept_graph_at_a_level_is_the_numeric_model_at_that_limit(key, level):
    # A trade-off front solves every level on one graph with the swept limit as a parameter: at
    # a level, its constraints are the numeric check's of the spec with that limit set (the
    # frequency limit is not in the gripper's spec at all).
    spec = replace(load_spec(EXAMPLES / "gripper-finger.yaml"), objective="error", tolerances=Tolerances("none"))
    variant = replace(spec, limits=replace(spec.limits, **{key: level}))
    fam = search.Family("round", "pocket")
    problem = search.FamilyProblem(spec, fam, swept=key).at(variant, level)
    mat = catalogue.material("17-7PH-RH950")
    for x in problem.starts():
        _, _, g, _ = problem.functions(x, problem.params(mat))
        numeric = {lim.name: float(lim.normalised) for lim in evaluate(problem.design(x, mat), variant).limits}
        rows = dict(zip(problem.limit_names, np.asarray(g).ravel()))
        assert {"deflection", "natural_frequency"} & set(rows)
        for name, value in rows.items():
            assert value == pytest.approx(numeric[name], rel=1e-9, abs=1e-12), name


def test_a_front_skips_only_candidates_with_no_feasible_design():
    # A tighter limit leaves a subset of the designs a looser one allows, so the fronts do not
    # solve a candidate at levels beyond the first where it had no feasible design. Each point
    # so left out is checked by a full search of that candidate at that level: none is feasible.
    from designer.search.tradeoff import fronts

    spec = _reduced(load_spec(EXAMPLES / "weigh-bar.yaml"), ["Ti-6Al-4V", "6061-T6"], ["round", "tube"])
    out = search.optimize(spec)
    points = fronts(spec, out, materials=2)
    skipped = [(key, p) for key, pts in points.items() for p in pts if p["objective"] is None]
    assert skipped, "the weigh-bar's tube family has no feasible design at the tight levels"
    for key, p in skipped[::3]:
        at = replace(spec, objective="error", limits=replace(spec.limits, **{key: p["x"]}))
        found = search.optimize(at, materials=[p["material"]])
        cand = next(c for c in found.candidates if c.family.label == p["section"])
        assert cand.evaluation is None or not cand.evaluation.feasible, (key, p)


# The bench suite's 015-imperial (``bench.generate_suite()``): tubes alone, so on stock rows;
# its min_frequency front's level of 257.7 Hz has no design that meets every limit.
TUBES_ONLY = """name: 015-imperial
load: {force: [0.1193 lbf, 1.796 lbf], position: [4.257 in, 7.616 in]}
electronics: {excitation: 3.3 V, gain: 1.0, noise_rti: 143.7 nV}
gauge: BF120-3AA
bridge: quarter
stations: 3
limits: {width: [0.02628 in, 1.017 in], height: [0.02628 in, 0.6976 in], min_pocket_depth: 0.01969 in,
  min_wall: 0.03937 in, max_deflection: 0.1463 in, min_frequency: 257.7 Hz}
targets: {force_error: 1.64 %, position_error: 0.1308 in}
search: {materials: [2024-T3, 7075-T6], sections: [tube], feature: pocket}
objective: error
tolerances: {class: none}
"""


def test_a_front_s_skipped_candidate_is_not_searched_on_stock_rows_either():
    # With no design that meets every limit, every stock row is solved again so that the
    # least-infeasible one is reported; a front's candidate that a looser level left without a
    # feasible design (``skip``) has none here and is not among them (it cost 136 IPOPT runs).
    spec = parse_spec_text(TUBES_ONLY)
    tube = next(fam for fam in search.families(spec))
    found = search.optimize(spec, skip={("2024-T3", tube)}, outrank=False, tie_break=False)
    assert not any(c.evaluation is not None and c.evaluation.feasible for c in found.candidates)
    searched = next(c for c in found.candidates if c.material == "7075-T6")
    assert searched.evaluation is not None and len(searched.solves) > 20   # every row, solved again
    skipped = next(c for c in found.candidates if c.material == "2024-T3")
    assert skipped.evaluation is None and skipped.solves == ()


def test_a_front_does_not_solve_a_material_with_no_stock_row_of_the_family(monkeypatch):
    # The gripper finger's tubes come from tube stock, and the stock catalogue has no Ti-6Al-4V
    # or 17-7PH-RH950 tube (stock.stock_rows: no row at all, whatever the swept limit): those two
    # of its four leading materials have no tube design at any level, so the fronts give them an
    # empty point at every level without a solve; 7075-T6 and 2024-T3 tubes are solved.
    from designer.search import run
    from designer.search.stock import stock_rows
    from designer.search.tradeoff import LEVELS, fronts

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    found = search.optimize(spec)
    solved = []
    real = run.solve_candidate
    monkeypatch.setattr(run, "solve_candidate", lambda problem, material, *a, **k: (
        solved.append((material.name, problem.family.section)) or real(problem, material, *a, **k)))
    points = fronts(spec, found)
    tube = next(fam for fam in search.families(spec) if fam.section == "tube")
    problem = search.FamilyProblem(spec, tube)
    rowless = {m for m in ("Ti-6Al-4V", "17-7PH-RH950", "7075-T6", "2024-T3")
               if not stock_rows(problem, catalogue.material(m))[0]}
    assert rowless == {"Ti-6Al-4V", "17-7PH-RH950"}
    assert not {(m, "tube") for m in rowless} & set(solved)
    assert {("7075-T6", "tube"), ("2024-T3", "tube")} <= set(solved)
    for key in ("max_deflection", "min_frequency"):
        empty = [p for p in points[key] if p["material"] in rowless and p["section"].startswith("tube")]
        assert len(empty) == 2 * LEVELS and all(p["objective"] is None and not p["feasible"] for p in empty)


# The bench suite's 016-short-beam (``bench.generate_suite(30, 0)``), with one material.
SHORT_BEAM = """name: 016-short-beam
load: {force: [39.12 mN, 703.7 mN], position: [8.212 mm, 10.99 mm]}
electronics: {excitation: 5 V, gain: 128.0, noise_rti: 397.8 nV}
gauge: {name: miniature, factor: 2.0, length: 1 mm, width: 0.8 mm, max_strain: 1500 ue}
bridge: full
stations: 3
limits: {clamp_clearance: 0.3 mm, load_clearance: 0.3 mm, tip_margin: 0.5 mm, pocket_margin: 0.1 mm,
  gauge_gap: 0.2 mm, min_wall: 0.1 mm, min_pocket_depth: 0.02 mm, width: [0.3 mm, 2.499 mm],
  height: [0.3 mm, 2.228 mm]}
targets: {force_error: 0.79 %, position_error: 0.05005 mm}
search: {materials: [2024-T3], sections: [rectangle], feature: pocket}
objective: mass
cad: {end_mill_diameter: 0.5 mm}
"""


def test_a_rounded_design_is_judged_with_the_wire_channels_its_rounded_pocket_gets():
    # The CAD cuts each wire channel half the pocket deep (up to 0.5 mm): rounding the depth to
    # 0.01 mm moves the channels with it. A shallow slot on a sub-millimetre bar (the bench
    # suite's 016: 0.06 mm deep, 0.78 mm tall) loses ~10 % of I to them, so a channel sized for
    # the unrounded depth put the reported root stress 1.1 % under what design.json re-evaluates.
    spec = parse_spec_text(SHORT_BEAM, source="016-short-beam")
    out = search.optimize(spec)
    record = json.loads(json.dumps(search_record(spec, out), default=str))
    again = designfile.parse_design(record)
    ev = evaluate(again.design, again.spec)
    g = out.best.design.geometry
    # the channel the model counts is the one the CAD cuts: half the depth, rounded down to
    # 0.01 mm as drawn; 0.4 of the 1.0 mm slot wide (the 0.5 mm end mill leaves 0.5 mm of wall)
    assert g.channel_depth == pytest.approx(math.floor(g.depth / 2 / 1e-5 + 1e-9) * 1e-5, rel=1e-12)
    assert g.channel_width == pytest.approx(0.4e-3, rel=1e-12)
    from designer.outputs.cad.beam import resolve
    built = resolve(record).channels
    assert (built.width, built.depth) == pytest.approx((g.channel_width, g.channel_depth), rel=1e-12)
    reported = {c["name"]: c["value"] for c in record["constraints"]}
    for lim in ev.limits:
        assert float(lim.value) == pytest.approx(reported[lim.name], rel=1e-9, abs=1e-12), lim.name


def test_a_slot_no_end_mill_can_cut_is_not_searched_and_says_why():
    # A 1.5 x 1.2 mm gauge with 0.2 mm margins needs a 1.6 mm wide slot, 1.8 mm with
    # cad.corner_radius 0.3 mm (the margin is at least the radius, so that the backing lies on the
    # floor: Spec.pocket_size), and an end mill takes at most 0.6 of it (outputs/cad/mills.py): the
    # tool catalogue (materials/tools.yaml) has R0.3 mm only on end mills of 1.5 mm and up, so no
    # tool cuts it and a
    # rectangle-only pocket search is bad input; the default radius (R0.02 under the 0.05 mm
    # shallowest pocket) is on the catalogue's Ø0.8 mm micro end mill, which makes it a design
    from designer.errors import SpecError

    text = _spec_text(search="  materials: [7075-T6]\n  sections: [rectangle]\n  feature: pocket",
                              load="  force: [2 mN, 100 mN]\n  position: [8 mm, 14 mm]",
                              limits="  clamp_clearance: 1 mm\n  load_clearance: 1 mm\n  tip_margin: 1 mm\n"
                                     "  pocket_margin: 0.2 mm\n  gauge_gap: 0.5 mm\n  min_wall: 0.2 mm\n"
                                     "  min_pocket_depth: 0.05 mm\n  width: [0.3 mm, 4 mm]\n  height: [0.3 mm, 4 mm]",
                              targets="  force_error: 20 %\n  position_error: 20 %")
    text += "gauge: {name: miniature, factor: 2.0, length: 1.5 mm, width: 1.2 mm, max_strain: 1500 ue}\n"
    with pytest.raises(SpecError) as err:
        search.optimize(parse_spec_text(text + "cad: {corner_radius: 0.3 mm}\n"))
    message = str(err.value)
    assert message.startswith("search.sections: rectangle: no slot can be machined: a slot 1.8 mm wide")
    assert "cad.end_mill_diameter" in message
    spec = parse_spec_text(text)
    found = search.optimize(spec)
    assert found.best is not None and found.x.geometry.section == "rectangle"
    assert spec.cad.corner_radius == pytest.approx(0.02e-3)
    from designer.outputs.cad.mills import slot_end_mill

    assert slot_end_mill(spec) == pytest.approx(0.8e-3)


def test_a_contender_is_solved_from_every_start():
    # prototype-b-optimized's 6061-T6 slotted bar: IPOPT's first start ends in a local optimum
    # (error ratio 0.2417, a 7.8 x 9.5 mm bar); the second finds the 19 x 5 mm plate that the
    # exhaustive reference search (search.reference, no casadi; benchmarks/bench_optimize.py)
    # puts at 0.234888. A candidate within 5 % of the best is solved from every start. (The
    # reference is at nominal sizes: tolerances none.)
    spec = load_spec(EXAMPLES / "prototype-b-optimized.yaml")
    spec = replace(spec, search=replace(spec.search, materials=("6061-T6",), sections=("rectangle",)),
                   tolerances=Tolerances("none"))
    found = search.optimize(spec)
    assert found.success
    assert found.best.objective <= 0.234888 * (1 + model.TIE_TOLERANCE)
    assert len(found.candidates[0].solves) >= 2


def test_starts_that_end_at_one_answer_share_its_rounding_and_repair(monkeypatch):
    # The gripper finger's 17-7PH-RH950 slotted bar under a 0.25 mm deflection limit (the tightest
    # level of its deflection front): both of IPOPT's starts end at one optimum that misses the
    # force target, and rounding it breaks the limit (the back-off re-solves). The second start
    # takes the first one's design instead of repeating that work, and the candidate is what
    # rounding and repairing each start's answer on its own gives (SAME_ANSWER < 0: never alike).
    from designer.search import run
    from designer.search.problem import Family, FamilyProblem

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    spec = replace(spec, objective="error", limits=replace(spec.limits, max_deflection=0.25e-3))
    problem = FamilyProblem(spec, Family("rectangle", "pocket"))
    material = catalogue.material("17-7PH-RH950")
    shared = run.solve_candidate(problem, material, "ipopt")
    monkeypatch.setattr(run, "SAME_ANSWER", -1.0)
    each = run.solve_candidate(problem, material, "ipopt")
    assert any("ipopt start 2: the same answer as start 1" in f for f in shared.fallbacks)
    assert not any("the same answer" in f for f in each.fallbacks)
    a, b = shared.evaluation, each.evaluation
    assert a.design == b.design and a.objective == b.objective and not a.feasible
    assert [(v.name, v.value) for v in a.violations] == [(v.name, v.value) for v in b.violations]
    assert len(shared.solves) < len(each.solves)


def test_the_front_passes_through_the_chosen_design(monkeypatch):
    # The front's points at the spec's own deflection limit are the search's designs, taken as
    # they are (only candidates the search outranked, which have no design, are solved there):
    # the chosen design is drawn where its star is, at its own deflection, which the limit's
    # room for the deflection fits (docs/model.md §4) keeps 1-2 % below the limit. (Before,
    # the gripper's designs that the limit binds were solved again there: 3 of its 6.)
    import designer.search.tradeoff as tradeoff

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    out = search.optimize(spec)
    chosen = out.best.analysis
    taken = {}
    optimize = tradeoff.optimize

    def recorded(variant, **kwargs):
        if variant.limits.max_deflection == spec.limits.max_deflection and variant.limits.min_frequency is None:
            taken.update(kwargs["known"])
        return optimize(variant, **kwargs)

    monkeypatch.setattr(tradeoff, "optimize", recorded)
    points = tradeoff.fronts(spec, out)["max_deflection"]
    leading = {p["material"] for p in points}
    designs = {(c.material, c.family): c for c in out.candidates
               if c.material in leading and c.evaluation is not None and c.evaluation.feasible}
    assert len(designs) == 6 and set(taken) == set(designs)
    at_limit = {(p["material"], p["section"]): p for p in points if p["x"] == spec.limits.max_deflection}
    for (material, family), c in designs.items():
        assert at_limit[(material, family.label)]["objective"] == float(c.evaluation.error_ratio)
    first = out.candidates[0]   # the chosen design's candidate
    assert first.evaluation is out.best
    star = at_limit[(first.material, first.family.label)]
    assert star["objective"] == pytest.approx(float(out.best.error_ratio), rel=1e-12)
    assert star["value"] == pytest.approx(float(chosen.deflection), rel=1e-12)
    assert star["value"] < 0.995 * spec.limits.max_deflection


@pytest.mark.slow
@pytest.mark.parametrize("name", ["gripper-finger", "prototype-b-optimized"])
def test_no_front_point_is_worse_than_the_chosen_design_where_that_design_meets_the_level(name):
    # At a level of the swept limit where the chosen design meets every limit (reference: evaluate()
    # under that level), the best design there is at least as good: the front cannot pass above
    # the chosen design's star there. (Before the fronts reused designs the swept limit does not
    # bind, each level was solved again with a front's cheaper repair of rounding, and drew the
    # gripper's Ti-6Al-4V 2 % above its chosen design on the frequency sweep, prototype-b's 6061-T6
    # 3.5 % above it on the deflection sweep.)
    from designer.search.tradeoff import fronts

    spec = load_spec(EXAMPLES / f"{name}.yaml")
    out = search.optimize(spec)
    chosen = float(out.best.error_ratio)
    checked = 0
    for key, points in fronts(spec, out).items():
        for level in sorted({p["x"] for p in points}):
            at = replace(spec, objective="error", limits=replace(spec.limits, **{key: level}))
            if not evaluate(out.best.design, at).feasible:
                continue
            best = min(p["objective"] for p in points if p["x"] == level and p["feasible"])
            assert best <= chosen * (1 + 1e-9), (key, level, best, chosen)
            checked += 1
    assert checked >= 6


def test_a_front_level_whose_limit_does_not_bind_the_answer_reuses_the_design_unsolved(monkeypatch):
    # A limit that does not bind a local optimum leaves it an optimum at any level it keeps room
    # at (the KKT conditions do not see an inactive constraint). The gripper has no frequency
    # limit: its frequency sweep's levels below the chosen Ti-6Al-4V bar's own frequency do not
    # bind that answer, so their points are the search's design, judged again under each level
    # (reference: evaluate() at that level), with no IPOPT run there; the levels above it bind.
    from designer.search.tradeoff import fronts

    spec = _reduced(load_spec(EXAMPLES / "gripper-finger.yaml"), ["Ti-6Al-4V"], ["round"])
    out = search.optimize(spec)
    chosen = float(out.best.analysis.natural_frequency)
    levels = []
    solve = search.FamilyProblem._solve

    def counted(self, *args, **kwargs):
        if self.swept == "min_frequency":
            levels.append(self.extra[0])
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(search.FamilyProblem, "_solve", counted)
    points = fronts(spec, out, materials=1)["min_frequency"]
    below = [p for p in points if p["x"] < 0.99 * chosen]
    assert len(below) == 4 and levels, "four levels below the chosen frequency, and solves above it"
    assert all(level > 0.99 * chosen for level in levels)
    for p in below:
        at = replace(spec, objective="error", limits=replace(spec.limits, min_frequency=p["x"]))
        again = evaluate(out.best.design, at)
        assert p["feasible"] and again.feasible
        assert p["objective"] == pytest.approx(float(again.error_ratio), rel=1e-12)
        assert p["value"] == pytest.approx(chosen, rel=1e-12)


def test_a_warm_start_from_a_nearby_solve_reaches_the_cold_answer_in_fewer_iterations():
    # The trade-off fronts start each level from the neighbouring level's answer with that solve's
    # multipliers (IPOPT's warm start). Here the gripper's Ti-6Al-4V round bar solved, then the
    # neighbouring problem with the diameter held 0.02 mm larger: warm and cold reach the same
    # answer (reference: the cold solve), the warm one in fewer iterations.
    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    problem = search.FamilyProblem(spec, search.Family("round", spec.search.feature))
    params = problem.params(catalogue.material("Ti-6Al-4V"))
    first = problem.solve_ipopt(params, problem.starts()[0])
    assert first.success and first.multipliers is not None
    i = problem.names.index("diameter")
    held = {i: round(float(first.x[i]) + 0.02, 2)}
    cold = problem.solve_ipopt(params, first.x, fixed=held)
    warm = problem.solve_ipopt(params, first.x, fixed=held, warm=first)
    assert cold.success and warm.success
    f = lambda s: float(problem.functions(s.x, params)[0])  # noqa: E731
    assert f(warm) == pytest.approx(f(cold), rel=1e-6)
    assert warm.evaluations < cold.evaluations


@pytest.mark.parametrize("name, grade", [("weigh-bar", "none"), ("weigh-bar", None), ("gripper-finger", None)])
def test_a_candidate_far_below_the_best_before_rounding_is_outranked_not_repaired(name, grade):
    # Candidates whose first answer, before rounding, is more than CONTENDER_BAND above the best
    # design found before them, and which rounding breaks, are outranked instead of repaired.
    # Reference: the same search repairing every candidate (outrank=False): the same reported
    # design, each outranked candidate's repaired design still more than CONTENDER_BAND above the
    # best (it could have been neither chosen nor a contender), and fewer IPOPT runs. The first
    # answer is not a bound on every repair: an answer meets its limits to IPOPT's tolerance only
    # (with the K_t fits of the study before its floor radii were refined whole, the gripper
    # finger's 304 rectangle under ISO 2768-m answered 0.991 and a wider grid around it found
    # 0.959, the best design 0.401). At nominal sizes, and under the examples' own ISO 2768-m,
    # whose corners the NLP holds as the check builds them (before, the answers on a flat missed a corner by up to 2e-5 in
    # the check, so none was outranked under a tolerance class).
    from designer.search.run import CONTENDER_BAND

    spec = load_spec(EXAMPLES / f"{name}.yaml")
    if grade is not None:
        spec = replace(spec, tolerances=Tolerances(grade))
    capped = search.optimize(spec)
    full = search.optimize(spec, outrank=False)
    assert capped.best.objective == pytest.approx(full.best.objective, rel=1e-12)
    assert capped.best.design.label() == full.best.design.label()
    skipped = [c for c in capped.candidates if c.unrounded]
    assert skipped and all(c.status == "outranked" and c.evaluation is None for c in skipped)
    repaired = {(c.material, c.family): c for c in full.candidates}
    for c in skipped:
        assert c.continuous.objective > capped.best.objective * (1 + CONTENDER_BAND)
        other = repaired[(c.material, c.family)].evaluation
        assert other is None or other.objective > capped.best.objective * (1 + CONTENDER_BAND)
        assert c.record()["continuous_objective"] == c.continuous.objective
    assert capped.solver["solves"] < full.solver["solves"]
    # so the report lists each at its answer "before rounding", never as a bound ("≥") on its designs
    text = report.markdown(search_record(spec, capped))
    assert "≥" not in text
    assert all(f"| {c.continuous.objective:.4g} before rounding |" in text for c in skipped)


def test_a_design_judged_again_under_the_same_spec_is_not_analysed_again(monkeypatch):
    # A search judges many a design twice (an answer's rounding, then the same design as a
    # neighbour's start). evaluate() keeps the designs it judged lately, by design and spec
    # object. Reference: the same design judged with that memory cleared; the second answer is
    # a new object (the search tells answers apart by identity) equal in every number, and no
    # model call is made for it; another spec object (a front's level) is judged anew.
    import designer.result.evaluation as evaluation

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    design = search.optimize(_reduced(spec, ["Ti-6Al-4V"], ["round"])).best.design
    evaluation._JUDGED.clear()
    first = evaluate(design, spec)
    calls = []
    analyse = evaluation.model.analyse
    monkeypatch.setattr(evaluation.model, "analyse", lambda *a, **k: calls.append(1) or analyse(*a, **k))
    again = evaluate(design, spec)
    assert again is not first and not calls
    assert again.predicted() == first.predicted() and again.judged == first.judged
    other = replace(spec, limits=replace(spec.limits, max_deflection=spec.limits.max_deflection))
    evaluate(design, other)
    assert calls, "another spec object is judged anew"
    evaluation._JUDGED.clear()
    fresh = evaluate(design, spec)
    assert fresh.predicted() == again.predicted() and fresh.tolerance == again.tolerance


def test_an_outranked_candidate_is_listed_at_its_answer_and_the_chart_and_fronts_follow():
    # An outranked candidate (not rounded: its optimum before rounding was already more than 5 %
    # above the best) is listed at that answer: after the designs that
    # meet every limit below it, before the first above it (never before the chosen design). The
    # fronts draw the first 4 materials of that list and the candidates chart keeps it. Reference:
    # the gripper finger's previous release, which rounded every one of these candidates: its
    # 2024-T3 and 17-7PH-RH950 round bars (0.503, 0.5395) made those two materials the 3rd and 4th,
    # ahead of 301-full-hard's rectangle (0.599); listed after every verified design, the
    # outranked bars would have put 301-full-hard in the fronts instead.
    from designer.outputs.plots import candidates as chart
    from designer.outputs.plots.sensor import SensorData

    spec = load_spec(EXAMPLES / "gripper-finger.yaml")
    out = search.optimize(spec)
    listed = out.candidates
    assert not listed[0].outranked and listed[0].evaluation.feasible
    outranked = [i for i, c in enumerate(listed) if c.outranked]
    assert len(outranked) >= 6
    for i in outranked:
        bound = listed[i].continuous.objective
        before = [c.evaluation.objective for c in listed[1:i] if not c.outranked and c.evaluation is not None]
        after = [c.evaluation.objective for c in listed[i + 1:] if not c.outranked and c.evaluation is not None
                 and c.evaluation.feasible]
        assert all(v <= bound for v in before) and all(v > bound for v in after), listed[i].material
    assert list(dict.fromkeys(c.material for c in listed))[:4] == ["Ti-6Al-4V", "7075-T6", "2024-T3", "17-7PH-RH950"]
    record = json.loads(json.dumps(search_record(spec, out)))
    rows = chart._candidate_rows(record, SensorData.from_design(record))
    assert [(r["material"], r["section"]) for r in rows] == [(c["material"], c["section"]) for c in record["candidates"]]
    ax = chart.plot_candidates(record).axes[0]   # each outranked one drawn as a bar to its answer
    widths = [p.get_width() for p in ax.patches]
    assert all(any(w == pytest.approx(listed[i].continuous.objective, rel=1e-12) for w in widths) for i in outranked)


def test_an_answer_over_a_limit_by_ipopt_s_own_relaxation_still_bounds_its_designs():
    # IPOPT relaxes every bound by 1e-8 (its bound_relax_factor) before it solves, so a converged
    # answer may sit over a limit by that much, over the check's 1e-9 (the gripper finger's
    # Ti-6Al-4V tube with flats once ended 1.2e-9 over its deflection limit at a corner). It is
    # still the optimum that bounds the designs near it, so it outranks as one
    # (``outranked_before_rounding``); as a design to keep (a stock family's start, which must meet
    # every limit) it does not count. Here IPOPT's answer is made such an answer: its section a
    # hair thinner, until its worst limit is 2-8e-9 over.
    from designer.search.problem import Family, FamilyProblem
    from designer.search.rounding import ANSWER_TOLERANCE, outranked_before_rounding

    spec = replace(load_spec(EXAMPLES / "gripper-finger.yaml"), objective="error")
    problem = FamilyProblem(spec, Family("tube", spec.search.feature))
    material = catalogue.material("Ti-6Al-4V")
    solved = problem.solve_ipopt(problem.params(material), problem.starts()[0])
    assert solved.success

    def thinner(t):
        x = np.array(solved.x, dtype=float)
        x[0] *= 1 - t
        return replace(solved, x=x)

    def over(t):
        return evaluate(problem.design(thinner(t).x, material), spec).worst_violation

    lo, hi = 0.0, 1e-6
    assert over(hi) > 8e-9
    while not 2e-9 <= over(hi) <= 8e-9:
        lo, hi = (lo, (lo + hi) / 2) if over((lo + hi) / 2) >= 2e-9 else ((lo + hi) / 2, hi)
    s = thinner(hi)
    ev = evaluate(problem.design(s.x, material), spec)
    assert s.success and model.FEASIBILITY_TOLERANCE < ev.worst_violation <= ANSWER_TOLERANCE
    bound = outranked_before_rounding(problem, material, s, cap=0.0)
    assert bound is not None and bound.objective == ev.objective
    assert outranked_before_rounding(problem, material, s, 0.0, model.FEASIBILITY_TOLERANCE) is None


def test_the_diagnosis_of_a_station_under_the_nearest_load_gives_advice_not_a_division_by_zero():
    # Prototype A (the paper's Table 1) with its second station moved to load.position[0]: a load
    # there puts no moment on that station (M = F (x - d) = 0), so the smallest signal is zero
    # noise levels, and "raise the force by limit / value" has no finite answer.
    text = (EXAMPLES / "prototype-a.yaml").read_text().replace("stations: [20 mm, 120 mm]", "stations: [20 mm, 150 mm]")
    spec = parse_spec_text(text)
    ev = evaluate(fixed_design(spec), spec)
    snr = {v.name: v for v in ev.violations}["min_signal_snr"]
    assert float(snr.value) == 0.0
    messages = diagnose(spec, ev, [])
    said = [m for m in messages if m.startswith("min_signal_snr")]
    assert len(said) == 1 and "no signal from a load at load.position[0] = 150 mm" in said[0]
    assert "use fewer stations" in said[0]


WIDE_ONLY = """\
load: {{force: [50 N, 2000 N], position: [100 mm, 300 mm]}}
electronics: {{excitation: 5 V, gain: 500, noise: 1 mV}}
limits: {{width: [60 mm, 70 mm]}}
search: {{materials: [7075-T6], sections: {sections}}}
"""


def test_a_family_whose_bounds_leave_no_room_is_not_searched_and_the_others_are():
    # limits.width 60-70 mm with the default heights (at most 50 mm, docs/spec.md 2.5): a round
    # bar's diameter must be within both ranges, so round and tube have no size; rectangles do
    spec = parse_spec_text(WIDE_ONLY.format(sections="[rectangle, round, tube]"))
    assert spec.limits.height[1] < 60e-3
    found = search.optimize(spec)
    by_family = {c.family.section: c for c in found.candidates}
    assert by_family["rectangle"].solves, "rectangles searched"
    for section in ("round", "tube"):
        cand = by_family[section]
        assert cand.evaluation is None and not cand.solves and cand.status == "failed"
        assert cand.fallbacks[0].startswith("not searched: limits: the bounds leave no room for diameter")
    # the candidates chart says so for each (two families of one material), not "no design found"
    from designer.outputs.plots.candidates import plot_candidates

    texts = [t.get_text() for t in plot_candidates(search_record(spec, found)).axes[0].texts]
    assert texts.count("not searched: the limits leave it no room (report.md says why)") == 2
    # with no family left, the spec itself is the problem (exit 2), as before
    with pytest.raises(SpecError, match="no room for diameter"):
        search.optimize(parse_spec_text(WIDE_ONLY.format(sections="[round, tube]")))


NARROW = """\
load: {force: [0.5 N, 20 N], position: [40 mm, 110 mm]}
electronics: {excitation: 5 V, gain: 128, noise_rti: 50 nV}
limits: {width: [4 mm, 10 mm], height: [3 mm, 16 mm], min_pocket_depth: 3.5 mm, max_deflection: 5 mm}
targets: {force_error: 5 %, position_error: 5 mm}
search: {materials: [7075-T6], sections: [rectangle, round, tube], feature: pocket}
"""


def test_a_family_too_small_for_the_least_pocket_depth_is_not_searched_and_the_others_are():
    # a round bar is at most 10 mm across (limits.width), so its flat at most 0.3 x 10 = 3 mm deep
    # (limits.max_pocket_fraction), short of the 3.5 mm least depth; a rectangle up to 16 mm high
    # has 4.8 mm: the rectangles are searched, the round bars and tubes are not, and say why
    spec = parse_spec_text(NARROW)
    found = search.optimize(spec)
    by_family = {c.family.section: c for c in found.candidates}
    assert by_family["rectangle"].solves and by_family["rectangle"].evaluation.feasible
    assert by_family["rectangle"].evaluation.design.geometry.depth >= 3.5e-3 - 1e-12
    for section in ("round", "tube"):
        cand = by_family[section]
        assert not cand.solves and cand.status == "failed"
        why = (f"limits.min_pocket_depth: 3.5 mm leaves no room for a {section}'s pocket within "
               f"limits.max_pocket_fraction 0.3 of its largest diameter (10 mm): 3 mm; must be at most 3 mm")
        assert cand.fallbacks == (f"not searched: {why}",)


def test_stations_that_fit_no_section_before_the_load_are_bad_input_without_a_row_search(monkeypatch):
    # load at 8-15 mm: two stations with 8.9 mm pockets need 5 + 2 x 8.9 + 2 + 5 = 29.8 mm before
    # it (docs/model.md section 1), whatever the section. Tubes alone give no design there (every
    # tube is a stock row), and their every stock row was solved for a least-infeasible design
    # (2117 solves, a minute) to report what the geometry says before any solve.
    from designer.search import stocked

    rows = []
    monkeypatch.setattr(stocked, "search_stock", lambda *a, **k: rows.append(a) or None)
    text = ("load: {force: [1 N, 10 N], position: [8 mm, 15 mm]}\n"
            "electronics: {excitation: 5 V, gain: 100, noise: 1 mV}\n")
    room = r"no room for 2 gauge stations .* at least 29.8 mm"
    with pytest.raises(SpecError, match=rf"^load.position: {room}"):
        search.optimize(parse_spec_text(text + "search: {sections: [tube]}\n"))
    assert rows == []
    # where a bar gives a (least-infeasible) design, the spec is reported infeasible with the same
    # reason first among what would resolve it, and still no stock row is solved
    found = search.optimize(parse_spec_text(text))
    assert found.status == "infeasible" and re.match(f"load.position: {room}", found.messages[1]) and rows == []


def test_rounding_that_costs_more_than_the_tie_band_also_solves_again_with_the_depth_held(monkeypatch):
    """The held-out suite's 011-loose-limits (seed 1; `fpdesign bench --seed 1`) on a 7075-T6 round
    bar with flats, its force and position error the objective. IPOPT's answer rounded on the
    0.01 mm grid (its flats' depth on the 0.05 mm one) meets every limit, but the best design the
    grid around it holds has 2.25 mm flats and costs more than the tie band over the answer; with
    the depth held at 2.20 mm (its other neighbouring grid value) and the diameter and stations
    solved again, the bar meets every limit with an error 0.8 % smaller. (Before, seed 1's
    007-long-beam showed the same, until the round flats' K_t took the depth into its clamp term.)
    Reference: the same candidate solved without the depth-held solve."""
    from designer.bench.suite import _generate
    from designer.search import ongrid, run
    from designer.search.problem import Family, FamilyProblem

    made = _generate(10, "loose-limits", 1)
    assert made.name == "011-loose-limits" and made.spec.objective == "error"
    problem = FamilyProblem(made.spec, Family("round", made.spec.search.feature))
    material = catalogue.material("7075-T6")
    found = run.solve_candidate(problem, material, "ipopt")
    monkeypatch.setattr(ongrid, "_depth_held", lambda *args, **kwargs: None)
    walked = run.solve_candidate(problem, material, "ipopt")
    # rounding broke no limit: the re-solve is closer_on_the_grid's, not the back-off's
    assert not any("rounding broke" in f for f in found.fallbacks)
    found, walked = found.evaluation, walked.evaluation
    assert found.feasible and walked.feasible
    assert found.design.geometry.depth == pytest.approx(2.20e-3) and walked.design.geometry.depth == pytest.approx(2.25e-3)
    assert found.objective < walked.objective * (1 - 0.005)


def test_a_load_region_at_the_gauge_gaps_least_room_names_what_the_closest_design_needs(examples):
    """The gripper finger with its load from 29.8 mm: 5 + 2 x 8.9 + 2 + 5 mm is the least room
    the gauge gaps leave whatever the section (docs/model.md §1), but a slot's web between two
    pockets is half the bar's height (pocket_gap), so no design of a useful size fits; the report
    named only the accuracy targets. The closest design keeps every rule of the geometry: its
    stations, d_2 + l_f/2 + load_clearance, reach the load region's start exactly, and the
    message says that this room holds its section, and from where a design meets every limit."""
    import yaml

    from designer.search.closest import meets_rules
    from designer.spec.reader import parse_spec

    raw = yaml.safe_load((examples / "gripper-finger.yaml").read_text(encoding="utf-8"))
    raw["load"]["position"] = ["29.8 mm", "110 mm"]
    spec = parse_spec(raw)
    found = search.optimize(spec)
    assert found.status == "infeasible"
    assert meets_rules(found.best)
    g = found.best.design.geometry
    reach = g.stations[-1] + g.feature_length / 2 + spec.limits.load_clearance
    assert 29.8e-3 * (1 - model.ACTIVE_TOLERANCE) <= reach <= 29.8e-3 * (1 + 1e-9)
    size = f"{g.width * 1e3:.4g} × {g.height * 1e3:.4g} mm" if g.section == "rectangle" else f"Ø{g.diameter * 1e3:.4g} mm"
    [said] = [m for m in found.messages if m.startswith("load_clearance")]
    told = re.fullmatch("load_clearance binds: the closest design's stations, their features and limits.load_clearance "
                        "reach load.position\\[0\\] = 29.8 mm, and the gaps between its features grow with the section: "
                        f"that holds it at {size}; a load region farther out \\(from load.position\\[0\\] = ([0-9.]+) mm, "
                        "a (\\S+) (rectangle|round) [^)]* meets every limit\\), fewer stations, a smaller gauge or "
                        "smaller margins would allow a larger one", said)
    assert told, said
    # followed, the advice gives a design: the search finds one from there, of that material
    raw["load"]["position"] = [f"{told.group(1)} mm", "110 mm"]
    raw["search"]["materials"] = [told.group(2)]
    assert search.optimize(parse_spec(raw)).success


def test_the_clearance_limits_show_the_room_they_keep(examples):
    """The summary's load_clearance row read "40 mm <= 40 mm" (the stations' reach against x_min)
    beside clamp_clearance's "5 mm >= 5 mm": both now show the room kept, against the clearance.
    Prototype B (docs/spec.md §6's fixed design): room = x_min - (d_N + l_f/2), and before a
    groove at 140 mm, 140 mm - 0.25 mm - (d_N + l_f/2)."""
    from dataclasses import replace

    from designer.result.evaluation import evaluate, fixed_design
    from designer.spec.reader import load_spec

    spec = load_spec(examples / "prototype-b.yaml")
    spec = replace(spec, cad=replace(spec.cad, load_grooves=True, groove_positions=(0.140,)))
    ev = evaluate(fixed_design(spec), spec)
    g = ev.design.geometry
    end = g.stations[-1] + g.feature_length / 2
    rows = {c["name"]: c for c in ev.constraint_records()}
    assert rows["load_clearance"]["value"] == pytest.approx(spec.load.position_min - end, rel=1e-12)
    assert rows["groove_clearance"]["value"] == pytest.approx(0.140 - 0.25e-3 - end, rel=1e-12)
    for name in ("load_clearance", "groove_clearance", "clamp_clearance"):
        assert rows[name]["sense"] == ">=" and rows[name]["unit"] == "m"
    assert rows["load_clearance"]["limit"] == rows["groove_clearance"]["limit"] == spec.limits.load_clearance


@pytest.mark.parametrize("heights, larger", [("[2 mm, 10 mm]", "limits.width"),
                                             ("[2 mm, 3.18 mm]", "limits.width and limits.height")])
def test_the_diagnosis_of_an_overstressed_design_asks_for_the_sizes_it_is_at_the_largest_of(heights, larger):
    # Prototype A (a 50 x 3.18 mm 6061-T6 bar, plain, static: yield 276 MPa, safety factor 1) under
    # 6 kgf at up to 650 mm: at the clamp sigma = 6 F x / (b h^2) = 378 MPa (beam theory), so
    # F = 276 MPa b h^2 / (6 x) = 42.9 N meets it. Its width is limits.width's largest (50 mm); its
    # height is that of limits.height only when the range ends at 3.18 mm: a taller bar is then
    # allowed, and "the largest section allowed" would not be true
    text = (EXAMPLES / "prototype-a.yaml").read_text().replace("[250 gf, 2000 gf]", "[250 gf, 6 kgf]")
    text = text.replace("  safety_factor: 1.0", f"  safety_factor: 1.0\n  width: [10 mm, 50 mm]\n  height: {heights}\n"
                        "  max_deflection: 10 mm")
    spec = parse_spec_text(text + "tolerances: {class: none}\n")   # the figures at the nominal sizes
    ev = evaluate(fixed_design(spec), spec)
    [said] = [m for m in diagnose(spec, ev, []) if m.startswith("stress_root")]
    b, h, x = 50e-3, 3.18e-3, 0.65
    assert f"{6 * 6 * 9.80665 * x / (b * h * h) / 1e6:.4g} MPa exceeds the allowable 276 MPa" in said
    assert f"lower load.force[1] to {276e6 * b * h * h / (6 * x):.4g} N, enlarge {larger}, choose" in said
    assert ("even at the largest section allowed" in said) == (larger != "limits.width")
    assert ("50 × 3.18 mm section (limits.height allows up to 10 mm)" in said) == (larger == "limits.width")
    # and the deflection (hundreds of mm: the 10 mm limit is broken) and the gauge strain (about
    # 6000 µε at the first gauge, over the gauge's 2500 less its room) the same way
    [said] = [m for m in diagnose(spec, ev, []) if m.startswith("deflection")]
    assert said.endswith(f", or enlarge {larger}")
    assert ("even at the largest section allowed" in said) == (larger != "limits.width")
    [said] = [m for m in diagnose(spec, ev, []) if m.startswith("gauge_strain")]
    assert said.endswith(f" N, enlarge {larger} or choose a stiffer material")
    assert ("even at the largest section allowed" in said) == (larger != "limits.width")


@pytest.mark.parametrize("index, kind", [(22, "millinewton"), (44, "millinewton"), (48, "short-beam")])
def test_no_solve_of_the_search_starts_where_the_model_has_no_derivative(index, kind):
    # The bench suite's specs (seed 0) whose IPOPT solves stopped at their start point with
    # Invalid_Number_Detected: a round bar thinner than its gauge's grid (023), a round bar with a
    # flat thinner than its wire channel (045), a pocket's depth held at the 0.05 mm grid's value 0,
    # under the least depth the spec allows (049). No solve may end so: its verdict would be the
    # solver's, not the spec's (045 and 023 fell back to nlopt, whose verdicts are no proof).
    from designer.bench.suite import _generate

    spec = _generate(index, kind, 0).spec   # as generate_suite(50, 0) makes it
    found = search.optimize(spec)
    said = [s.message for c in found.candidates for s in c.solves]
    assert said and "Invalid_Number_Detected" not in said
    assert all(s.message.startswith(("Solve_", "Infeasible_Problem", "Solved_To")) for c in found.candidates
               for s in c.solves if s.method == "ipopt")
