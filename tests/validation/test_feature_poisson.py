"""The limits keep room for the material's Poisson's ratio (docs/model.md §7, ``model.poisson``):
the features' fits were taken on 6061-T6 (nu 0.33). References are fresh 3-D runs of study bars
inside the fits' domain in 6061-T6 and in 17-4PH-H900 (nu 0.272, the catalogue's lowest), each
over the shipped model (as ``checks.study.model_ratios``, with the deflection), and the model's
limits in closed form."""

from __future__ import annotations

from dataclasses import replace

import pytest

from designer.checks import study
from designer.checks.fea import verify_design
from designer.model import corrections, poisson
from designer.result.pipeline import evaluate_fixed
from designer.spec.reader import parse_spec_text

STEEL = "17-4PH-H900"
# a round bar 9.44 mm across, two flats 0.34 D deep and 1.02 D long (the study's round-pocket
# case 77, inside every fit's domain): a short, deep flat, where the material moves the reading most
DEEP_FLAT = study.Case("round-pocket", diameter=9.439e-3, depth=3.215e-3, clamp_clearance=8.035e-3,
                       pocket_length=9.649e-3, corner_radius=0.486e-3)
# a 25 x 20 mm bar with 15 mm holes 5 mm from the clamp (the study's wide-bar holes)
WIDE_HOLE = study.Case("rectangle-hole", width=25e-3, height=20e-3, hole=15e-3, clamp_clearance=5e-3)
# a plain round bar 20 mm across, its near gauge's grid 2 mm from the clamp face (the study's
# round_clamp_cases): the clamp takes about 5 % off that gauge's strain in 6061-T6
ROUND_NEAR_CLAMP = study.Case("round-none", diameter=20e-3, clamp_clearance=2e-3)


def _in(case, material):
    """``(spec, evaluate_fixed's result)`` of the case in ``material``, inside the fits' domain."""
    spec = parse_spec_text(replace(case, material=material).spec_text(), source=case.family)
    result = evaluate_fixed(spec)
    assert not [v.name for v in result.evaluation.violations if v.name.startswith("domain_")]
    return spec, result


def _steel_limit(case, name):
    """``(spec, limit, room)``: the steel design's ``name`` limit and the share of the strain it keeps
    as room, its fits' (``corrections.strain_allowance``) plus the room for nu (``poisson.strain_room``)."""
    spec, result = _in(case, STEEL)
    g = result.evaluation.design.geometry
    limit = next(lim for lim in result.evaluation.judged if lim.name == name)
    room = corrections.strain_allowance(g, corrections.load()) + poisson.strain_room(corrections.family(g), 0.272)
    return spec, float(limit.limit), room


def _readings(case, material):
    """``(gauge ratios, deflection ratio)``: 3-D over the shipped model in ``material``."""
    v = verify_design(_in(case, material)[1].record, mesh="normal")
    return [g.ratio for g in v.gauges], v.deflection_fea / v.deflection_model


@pytest.mark.slow
def test_a_deep_round_flat_in_steel_reads_more_strain_and_deflection_and_the_limits_keep_that_room():
    """In 3-D the steel flat reads about 1.1 % more gauge strain and deflection over the model than
    the same aluminium flat (benchmarks/feature_poisson_check.md); the gauge-strain limit of the steel
    design keeps its fits' room plus at least that much, the deflection limit likewise."""
    alu, alu_deflection = _readings(DEEP_FLAT, "6061-T6")
    steel, steel_deflection = _readings(DEEP_FLAT, STEEL)
    shifts = [s / a - 1 for s, a in zip(steel, alu)]
    assert min(shifts) > 0.008, shifts
    room = poisson.strain_room("round-pocket", 0.272)
    assert room >= max(shifts)
    assert poisson.deflection_room("round-pocket", 0.272) >= steel_deflection / alu_deflection - 1 > 0.008
    # the steel design's gauge-strain limit: the gauge's rating over 1 + its fits' room + the room for nu
    spec, limit, kept = _steel_limit(DEEP_FLAT, "gauge_strain")
    assert limit == pytest.approx(spec.gauge.max_strain / (1 + kept), rel=1e-12)


@pytest.mark.slow
def test_a_hole_in_a_wide_steel_bar_reads_less_strain_and_the_targets_keep_that_room():
    """In 3-D the steel bar's gauges over its holes read up to 1.4 % less strain over the model than
    the aluminium bar's: the errors, which scale as one over the strain, rise by as much, and the
    accuracy targets keep that room."""
    alu, _ = _readings(WIDE_HOLE, "6061-T6")
    steel, _ = _readings(WIDE_HOLE, STEEL)
    shifts = [s / a - 1 for s, a in zip(steel, alu)]
    assert max(shifts) < -0.008, shifts
    room = poisson.strain_room("rectangle-hole", 0.272)
    assert room >= -min(shifts)
    spec, target, kept = _steel_limit(WIDE_HOLE, "force_error")
    assert target == pytest.approx(spec.targets.force_error / (1 + kept), rel=1e-12)


@pytest.mark.slow
def test_a_round_bar_near_the_clamp_loses_less_strain_in_steel_and_the_model_scales_that_loss_to_nu():
    """A rigid clamp stops the bar's Poisson contraction, so the strain it takes from a gauge near it
    shrinks with nu: in 3-D the steel bar's near gauge reads about 1.3 % more than the aluminium
    bar's, its far gauge the same (benchmarks/feature_poisson_check.md). The model scales its
    near-clamp loss as (nu / 0.33)^NEAR_POISSON_POWER, and what is left lies within the gauge
    strain's room (the near-clamp fit's left-out error plus the room for nu) on either side."""
    table = corrections.load()
    (_, alu_result), (_, steel_result) = _in(ROUND_NEAR_CLAMP, "6061-T6"), _in(ROUND_NEAR_CLAMP, STEEL)
    g = steel_result.evaluation.design.geometry
    alu_factors = corrections.strain_factors(alu_result.evaluation.design.geometry, table, poisson=0.33)
    steel_factors = corrections.strain_factors(g, table, poisson=0.272)
    # the model's near gauge: the fit's loss in 6061-T6 (nu 0.33), times (0.272 / 0.33)^p in steel
    loss = 1 - alu_factors[0]
    assert loss > 0.04 and alu_factors[1] == pytest.approx(1, abs=1e-9) == steel_factors[1]
    assert steel_factors[0] == pytest.approx(1 - loss * (0.272 / 0.33) ** corrections.NEAR_POISSON_POWER, rel=1e-12)
    # 3-D over the shipped model, times the model's factor: 3-D over the same beam model in both
    alu, _ = _readings(ROUND_NEAR_CLAMP, "6061-T6")
    steel, _ = _readings(ROUND_NEAR_CLAMP, STEEL)
    near_shift = steel[0] * steel_factors[0] / (alu[0] * alu_factors[0]) - 1
    assert near_shift > 0.009 and abs(steel[1] / alu[1] - 1) < 0.001, (alu, steel)
    # unscaled, the model would leave the steel gauge that shift above the aluminium one's reading
    room = corrections.strain_allowance(g, table) + poisson.strain_room("round-none", 0.272)
    assert alu[0] * (1 + near_shift) > 1 + room
    assert all(abs(r - 1) <= room for r in steel), (steel, room)
