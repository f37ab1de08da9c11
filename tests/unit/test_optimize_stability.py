"""The search under stress (issue 5): extreme units and scales, several limits active at once,
materials that tie, and solvers that raise. Whatever happens, what is reported was checked."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from designer.spec.tolerances import Tolerances
from designer.spec import catalogue
from designer.result import designfile
from designer import model, search
from designer.result.record import search_record
from designer.search import reference
from designer.result.evaluation import evaluate
from designer.spec.reader import parse_spec_text
from shared_inputs import SEVERAL_LIMITS_TEXT
from shared_inputs import STABILITY_SCALES as SCALES
from shared_inputs import raise_roundoff as _raise_roundoff


# The acceptance bound of issue 3: the reported objective within 0.5 % of the reference search.
REFERENCE_GAP = 5e-3


def _recheck(outcome, spec):
    """The reported design rebuilt from its design.json record alone and evaluated again."""
    record = json.loads(json.dumps(search_record(spec, outcome)))
    designfile.validate(record)
    spec, design = designfile.rebuild(record)
    return evaluate(design, spec)


def _spec(name: str):
    return parse_spec_text(SCALES[name], source=name)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SCALES))
def test_extreme_forces_and_lengths_give_verified_near_optimal_designs(name):
    spec = _spec(name)
    outcome = search.optimize(spec)
    assert outcome.success, outcome.message
    ev = _recheck(outcome, spec)
    assert ev.feasible, [v.name for v in ev.violations]
    assert ev.objective == pytest.approx(outcome.best.objective, rel=1e-12)
    # Reference: reference.reference_best, a dense grid polished by scipy SLSQP on the numeric model
    # (no casadi, no nlopt). Where several limits are active at once it may only come within a
    # small violation of them; its objective is then still a near-lower bound.
    ref = reference.reference_best(spec, levels=5)
    assert ref.worst_violation < 1e-2
    assert outcome.best.objective <= ref.objective * (1 + REFERENCE_GAP)
    # the design is in the spec's scale: stations between the clamp and the load region
    g = ev.design.geometry
    assert spec.limits.clamp_clearance <= g.stations[0] < g.stations[-1] < spec.load.position_min


# Found by `fpdesign bench` (generated spec 007-long-beam, seed 0): a hole in a thin rectangle
# puts the optimum on the root stress, the feature stress, the force target and the load
# clearance at once; every 0.01 mm neighbour of IPOPT's answer broke one of them, and the spec
# was called infeasible.
SEVERAL_LIMITS = parse_spec_text(SEVERAL_LIMITS_TEXT)


@pytest.mark.slow
def test_optimum_on_several_limits_at_once_is_found_and_meets_all_of_them():
    outcome = search.optimize(SEVERAL_LIMITS)
    assert outcome.success, outcome.message
    constraints = outcome.best.constraint_records()
    assert all(c["satisfied"] for c in constraints)
    active = {c["name"] for c in constraints if c["active"]}
    # within 0.5 % of the limit (model.ACTIVE_TOLERANCE): the root stress, the fatigue limit at the
    # holes (with their K_t, docs/model.md §7) and the force target bind at once (with the holes' K_t
    # before their refit, the clamp clearance and the edges of the hole fits' domain bound instead,
    # and the design was 4 % worse); the load clearance, 5.5 mm of room against 5 mm, had counted as
    # binding while it was judged against x_min (0.5 mm of 150 mm)
    assert {"stress_root", "fatigue_feature", "force_error"} <= active
    margins = {c["name"]: c["margin"] for c in constraints}
    assert all(0 <= margins[n] <= 0.01 for n in active)
    assert _recheck(outcome, SEVERAL_LIMITS).feasible
    ref = reference.reference_best(SEVERAL_LIMITS, levels=9)
    assert ref.feasible
    assert outcome.best.objective <= ref.objective * (1 + REFERENCE_GAP)


def _twin(name: str, monkeypatch, **changes) -> str:
    """A catalogue with a copy of ``name`` whose fields differ by ``changes``."""
    table = dict(catalogue.materials())
    twin = replace(table[name], name=f"{name}-twin", **changes)
    table[twin.name] = twin
    monkeypatch.setattr(catalogue, "materials", lambda: table)
    return twin.name


def test_materials_that_tie_exactly_are_chosen_by_mass_whatever_their_order(monkeypatch):
    # MODEL.md 5: objectives within 0.1 % rank by lower deflection, then lower mass. A denser twin
    # of 7075-T6 (same E and strengths) has the same best objective and deflection, more mass.
    twin = _twin("7075-T6", monkeypatch, density=1.5 * catalogue.material("7075-T6").density)
    spec = _spec("kilonewtons on a millimetre beam")
    spec = replace(spec, load=replace(spec.load, force_max=1000.0))   # (1.5 kN: no 7075-T6 lug meets every limit)
    chosen = []
    for order in (("7075-T6", twin), (twin, "7075-T6")):
        outcome = search.optimize(replace(spec, search=replace(spec.search, materials=order)))
        assert outcome.success
        chosen.append(outcome.x.material.name)
        a, b = (c.evaluation for c in outcome.candidates[:2])
        assert a.objective == pytest.approx(b.objective, rel=model.TIE_TOLERANCE)
        assert float(a.analysis.mass) < float(b.analysis.mass)
    assert chosen == ["7075-T6", "7075-T6"]


def test_materials_that_tie_within_a_tenth_of_a_percent_are_chosen_by_deflection():
    # Without the fatigue cap every one of these materials may strain its gauge to the gauge's
    # rating, and a gauge-strain-limited beam's sensitivity k = V G g n eps / (4 F (x - d1)) does
    # not depend on the material: they tie on the error ratio, and the design with the lowest
    # deflection (then mass) among those within 0.1 % must win. Plain round bars: the clamp's
    # correction (docs/model.md §7), which depends on a rectangle's width/height, leaves them
    # alone, and so does the flats' strain factor, which depends on each design's flat. The
    # stations are kept about a diameter from the clamp, where a round bar's own near-clamp
    # factor (§7), which depends on the diameter and so on the material, is 1 within 1e-4. At
    # nominal sizes (tolerances: none): a tolerance corner's room differs by material.
    spec = _spec("kilonewtons on a millimetre beam")
    spec = replace(spec, limits=replace(spec.limits, fatigue=False, safety_factor=1.5, clamp_clearance=0.02),
                   tolerances=Tolerances("none"),
                   load=replace(spec.load, position_min=0.06, position_max=0.09),
                   search=replace(spec.search, materials=("7075-T6", "Ti-6Al-4V", "17-4PH-H900"), sections=("round",),
                                  feature="none"))
    outcome = search.optimize(spec)
    assert outcome.success
    feasible = [c.evaluation for c in outcome.candidates if c.status == "optimal"]
    lead = min(ev.objective for ev in feasible)
    band = [ev for ev in feasible if ev.objective <= lead * (1 + model.TIE_TOLERANCE)]
    assert len(band) >= 2  # a real tie, or the test proves nothing
    best = outcome.best
    assert best in band
    assert all((float(best.analysis.deflection), float(best.analysis.mass))
               <= (float(ev.analysis.deflection), float(ev.analysis.mass)) for ev in band)
    again = search.optimize(replace(spec, search=replace(spec.search, materials=spec.search.materials[::-1])))
    assert again.x.material.name == outcome.x.material.name


@pytest.mark.parametrize("method", ["slsqp", "mma", "cobyla"])
def test_an_nlopt_method_that_raises_is_recorded_and_the_answer_still_checked(method, monkeypatch):
    import nlopt

    monkeypatch.setattr(nlopt.opt, "optimize", _raise_roundoff)
    spec = _spec("kilonewtons on a metre beam")
    outcome = search.optimize(spec, method=method)
    own = [s for c in outcome.candidates for s in c.solves if s.method == method]
    assert own and all(not s.success and "RoundoffLimited" in s.message for s in own)
    assert any("RoundoffLimited" in f for f in outcome.solver["fallbacks"])
    # The spec is feasible (test_extreme_forces_and_lengths_give_verified_near_optimal_designs
    # finds a design within 0.5 % of the reference search), so the fallback to IPOPT must deliver
    # one: the design rebuilt from its record meets every limit.
    ev = _recheck(outcome, spec)
    assert ev.feasible and outcome.success
    assert outcome.status == "optimal"


def test_slsqp_stopping_on_roundoff_is_caught_and_the_answer_checked():
    # Without any patching SLSQP stops with RoundoffLimited on the 304 steel candidate of the
    # bench's 007-long-beam spec (a hole in a beam too weak to carry the load).
    spec = replace(SEVERAL_LIMITS, search=replace(SEVERAL_LIMITS.search, materials=("304", "17-7PH-RH950")))
    outcome = search.optimize(spec, method="slsqp")
    messages = [s.message for c in outcome.candidates for s in c.solves if s.method == "slsqp"]
    assert any("RoundoffLimited" in m for m in messages)
    ev = _recheck(outcome, spec)
    assert ev.feasible
    assert outcome.success  # 17-7PH carries it: found directly or through the IPOPT fallback


def test_ipopt_that_raises_falls_back_to_slsqp_and_the_answer_is_checked(monkeypatch):
    class Raising:
        def __call__(self, **kwargs):
            raise RuntimeError("Error in Function::call for 'solver' [IpoptInterface] at .../casadi/core/function.cpp")

        def stats(self):  # pragma: no cover - never reached
            return {}

    monkeypatch.setattr(search.FamilyProblem, "ipopt", lambda self, stage="primary": Raising())
    spec = _spec("kilonewtons on a millimetre beam")
    outcome = search.optimize(spec)
    ipopt_runs = [s for c in outcome.candidates for s in c.solves if s.method == "ipopt"]
    assert ipopt_runs and all(s.message.startswith("IPOPT raised") for s in ipopt_runs)
    assert any(s.method == "slsqp" for c in outcome.candidates for s in c.solves)
    ev = _recheck(outcome, spec)
    assert ev.feasible and outcome.success
