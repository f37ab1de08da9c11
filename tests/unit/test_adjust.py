"""A design's model adjusted to its 3-D check (docs/model.md §11): what each factor scales, the
optimiser's derivatives with the factors in the graph, and design.json carrying them."""

import math
from dataclasses import replace

import numpy as np
import pytest

from designer import model
from designer.errors import DesignFileError
from designer.model import Adjustment
from designer.result.designfile import parse_design
from designer.result.evaluation import evaluate, fixed_design
from designer.result.record import build_record
from designer.spec.reader import parse_spec_text
from shared_inputs import STIFF_FINGER, STIFF_FINGER_DESIGN, assert_exact_jacobian

FACTORS = Adjustment((0.9, 0.8), deflection=1.2, stress_concentration=1.5)


def _plain_and_adjusted(adjust=FACTORS):
    spec = parse_spec_text(STIFF_FINGER + STIFF_FINGER_DESIGN)
    design = fixed_design(spec).rounded(spec.cad)
    params = design.material_params(spec)
    plain = model.analyse(design.geometry, params, spec)
    return spec, plain, model.analyse(design.geometry, params, spec, adjust=adjust)


def test_strain_factors_scale_k_and_strain_and_the_errors_as_their_closed_forms():
    spec, plain, adj = _plain_and_adjusted()
    c = FACTORS.gauge_strain
    assert adj.sensitivities == pytest.approx([k * f for k, f in zip(plain.sensitivities, c)], rel=1e-15)
    assert adj.gauge_strain == pytest.approx([e * f for e, f in zip(plain.gauge_strain, c)], rel=1e-15)
    # two stations: F = (V_1/k_1 - V_2/k_2)/(d_2 - d_1), so sigma_F = sigma_V sqrt(1/k_1^2 + 1/k_2^2)/(d_2 - d_1)
    # (paper eq. 35 with unequal k)
    k1, k2 = (float(k) for k in adj.sensitivities)
    d1, d2 = spec.design.stations
    sigma_f = spec.sigma_v * math.sqrt(1 / k1 ** 2 + 1 / k2 ** 2) / (d2 - d1)
    assert float(adj.force_error) == pytest.approx(sigma_f / spec.load.force_min, rel=1e-9)
    # the smallest signal is the last gauge's: it scales with that gauge's factor
    assert float(adj.min_signal_snr) == pytest.approx(float(plain.min_signal_snr) * c[-1], rel=1e-15)


def test_equal_strain_factors_scale_both_errors_as_one_over_k():
    # sigma_F and sigma_x are both proportional to sigma_V / k (paper eqs. 35-36)
    _, plain, adj = _plain_and_adjusted(Adjustment((0.95, 0.95)))
    assert float(adj.force_error) == pytest.approx(float(plain.force_error) / 0.95, rel=1e-12)
    assert float(adj.position_error) == pytest.approx(float(plain.position_error) / 0.95, rel=1e-12)


def test_deflection_and_stress_factors_scale_deflection_and_kt_and_nothing_else():
    _, plain, adj = _plain_and_adjusted()
    assert float(adj.deflection) == pytest.approx(1.2 * float(plain.deflection), rel=1e-15)
    assert float(adj.stress_concentration) == pytest.approx(1.5 * float(plain.stress_concentration), rel=1e-15)
    assert float(adj.stress_peak) == pytest.approx(1.5 * float(plain.stress_peak), rel=1e-15)
    for name in ("stress_root", "stress_feature", "mass", "natural_frequency", "sensitivity", "noise_strain"):
        assert float(getattr(adj, name)) == float(getattr(plain, name)), name


def test_factors_of_one_are_the_plain_model_to_the_last_bit():
    _, plain, adj = _plain_and_adjusted(Adjustment.identity(2))
    for name in ("force_error", "position_error", "deflection", "min_signal_snr", "stress_concentration"):
        assert float(getattr(adj, name)) == float(getattr(plain, name)), name
    assert adj.gauge_strain == plain.gauge_strain and adj.sensitivities == plain.sensitivities


def test_a_factor_per_station_is_required():
    spec = parse_spec_text(STIFF_FINGER + STIFF_FINGER_DESIGN)
    design = fixed_design(spec).rounded(spec.cad)
    with pytest.raises(ValueError, match=r"adjustment.gauge_strain: 3 factors for 2 stations"):
        model.analyse(design.geometry, design.material_params(spec), spec, adjust=Adjustment((1.0, 1.0, 1.0)))


def test_composing_multiplies_every_factor():
    again = Adjustment((1.1, 1.25), deflection=0.5, stress_concentration=2.0)
    both = FACTORS.times(again)
    assert both.gauge_strain == pytest.approx((0.9 * 1.1, 0.8 * 1.25), rel=1e-15)
    assert (both.deflection, both.stress_concentration) == pytest.approx((0.6, 3.0), rel=1e-15)
    assert Adjustment.from_dict(both.as_dict()) == both


@pytest.mark.parametrize("data, message", [
    ({"gauge_strain": [1.0, -0.5]}, r"adjustment.gauge_strain: -0.5 must be a positive number"),
    ({"gauge_strain": "1"}, r"adjustment.gauge_strain: '1' must be a list of numbers, one per station"),
    ({"gauge_strain": [1.0, 1.0], "deflection": "x"}, r"adjustment.deflection: 'x' must be a number"),
    ([1, 2], r"adjustment: \[1, 2\] must be an object"),
])
def test_impossible_factors_are_named(data, message):
    with pytest.raises(ValueError, match=message):
        Adjustment.from_dict(data)


def test_the_adjusted_nlp_has_exact_derivatives_and_the_factors_as_constants():
    # OpenMDAO-style check, as tests/unit/test_corrections.py: the casadi Jacobian of the adjusted
    # NLP against central finite differences of the same function.
    from designer.search import Family, FamilyProblem, material_params
    from designer.spec import catalogue

    spec = parse_spec_text(STIFF_FINGER)
    family = Family("round", "pocket")
    plain, adjusted = FamilyProblem(spec, family), FamilyProblem(spec, family, FACTORS)
    params = material_params(catalogue.material("7075-T6"), spec)
    x = adjusted.starts()[0]
    g = assert_exact_jacobian(adjusted, x, params)
    # the deflection limit g = w/w_max - 1: the adjusted w is 1.2 times the plain one
    at = adjusted.limit_names.index("deflection")
    g_plain = float(np.asarray(plain.functions(x, params)[2]).ravel()[at])
    assert float(np.asarray(g).ravel()[at]) + 1 == pytest.approx(1.2 * (g_plain + 1), rel=1e-12)
    # every design the adjusted problem returns carries the factors
    assert adjusted.design(x, catalogue.material("7075-T6")).adjustment == FACTORS


def test_design_json_carries_the_factors_and_reading_it_back_gives_the_same_numbers():
    spec = parse_spec_text(STIFF_FINGER + STIFF_FINGER_DESIGN)
    design = replace(fixed_design(spec).rounded(spec.cad), adjustment=FACTORS)
    ev = evaluate(design, spec)
    record = build_record("feasible", spec, ev)
    assert record["design"]["adjustment"] == FACTORS.as_dict()
    back = parse_design(record)
    assert back.design.adjustment == FACTORS
    assert evaluate(back.design, back.spec).predicted() == record["predicted"]
    plain = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    assert "adjustment" not in build_record("feasible", spec, plain)["design"]
    assert record["predicted"]["deflection"] == pytest.approx(1.2 * plain.predicted()["deflection"], rel=1e-15)


def test_design_json_with_a_factor_count_that_does_not_match_the_stations_is_bad_input():
    spec = parse_spec_text(STIFF_FINGER + STIFF_FINGER_DESIGN)
    record = build_record("feasible", spec, evaluate(fixed_design(spec).rounded(spec.cad), spec))
    record["design"]["adjustment"] = {"gauge_strain": [1.0], "deflection": 1.0, "stress_concentration": 1.0}
    with pytest.raises(DesignFileError, match=r"design.adjustment.gauge_strain: 1 factors for 2 stations"):
        parse_design(record)
    record["design"]["adjustment"] = {"gauge_strain": [1.0, 0.0]}
    with pytest.raises(DesignFileError, match=r"design.adjustment.gauge_strain: 0.0 must be a positive number"):
        parse_design(record)
