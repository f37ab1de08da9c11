"""spec.yaml (SPEC.md): what a good spec becomes in designer.spec.reader.

References: SPEC.md (units, spellings, defaults), exact unit factors (1 in = 25.4 mm,
1 lbf = 4.4482216152605 N, 1 gf = 9.80665 mN) and MODEL.md sections 1 and 3.
"""

from __future__ import annotations

import copy
import math

import pytest
import yaml

from designer.spec import reader as spec_module
from designer.errors import SpecError
from designer.spec.reader import parse_spec, parse_spec_text

GF = 9.80665e-3  # N per gram-force


MINIMAL = {"load": {"force": ["0.5 N", "20 N"], "position": ["40 mm", "110 mm"]},
           "electronics": {"excitation": "5 V", "gain": 128, "noise_rti": "50 nV"}}


@pytest.mark.parametrize("text, key, expected", [
    # SPEC.md's examples of values with units, against hand conversions (exact factors:
    # 1 in = 25.4 mm, 1 lbf = 4.4482216152605 N, 1 gf = 9.80665 mN).
    ("[0.5 in, 4 in]", "position", (0.0127, 0.1016)),
    ("[2 lbf, 10 lbf]", "force", (2 * 4.4482216152605, 10 * 4.4482216152605)),
    ("[250 gf, 2 kgf]", "force", (250 * GF, 2000 * GF)),
    ("[0.5, 20]", "force", (0.5, 20.0)),  # bare numbers are SI
])
def test_load_values_with_units(text, key, expected):
    raw = copy.deepcopy(MINIMAL)
    raw["load"][key] = yaml.safe_load(text)
    s = parse_spec(raw)
    got = (s.load.force_min, s.load.force_max) if key == "force" else (s.load.position_min, s.load.position_max)
    assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("value", ["1500 ue", "1500 µε", "1500ue", 0.0015, "0.15 %"])
def test_microstrain_spellings(value):
    raw = copy.deepcopy(MINIMAL) | {"gauge": {"name": "BF120-3AA", "max_strain": value}}
    assert parse_spec(raw).gauge.max_strain == pytest.approx(1.5e-3, rel=1e-12)


def test_noise_given_three_ways_is_one_output_noise():
    # MODEL.md section 3: noise is sigma_V; noise_rti gives g * noise_rti; noise_strain gives
    # V_s G g n sigma_eps / 4 (G = 2.0 for the default BF120-3AA, n = 2 for a half bridge).
    def sigma(**electronics):
        raw = copy.deepcopy(MINIMAL)
        raw["electronics"] = {"excitation": "5 V", "gain": 128, **electronics}
        return parse_spec(raw).sigma_v

    assert sigma(noise="1.3 mV") == pytest.approx(1.3e-3, rel=1e-12)
    assert sigma(noise_rti="50 nV") == pytest.approx(128 * 50e-9, rel=1e-12)
    assert sigma(noise_strain="0.1 ue") == pytest.approx(5 * 2.0 * 128 * 2 * 0.1e-6 / 4, rel=1e-12)


def test_relative_and_absolute_position_targets():
    # SPEC.md: position_error "2 %" is relative to x_max (110 mm here); "1 mm" is absolute.
    raw = copy.deepcopy(MINIMAL) | {"targets": {"force_error": "1 %", "position_error": "2 %"}}
    t = parse_spec(raw).targets
    assert t.force_error == pytest.approx(0.01, rel=1e-12)
    assert t.position_error == pytest.approx(0.02 * 0.110, rel=1e-12)
    raw["targets"]["position_error"] = "1 mm"
    assert parse_spec(raw).targets.position_error == pytest.approx(1e-3, rel=1e-12)


def test_defaults_are_those_of_spec_md():
    s = parse_spec(copy.deepcopy(MINIMAL))
    lim = s.limits
    assert (s.bridge, s.stations, s.axes, s.objective) == ("half", 2, 1, "error")
    assert s.gauge.name == "BF120-3AA"
    assert (lim.safety_factor, lim.fatigue, lim.max_deflection, lim.min_frequency) == (2.0, True, None, None)
    assert lim.width == pytest.approx((2e-3, 50e-3)) and lim.height == pytest.approx((2e-3, 50e-3))
    assert (lim.min_wall, lim.clamp_clearance, lim.load_clearance, lim.tip_margin) == pytest.approx(
        (1e-3, 5e-3, 5e-3, 5e-3))
    assert (lim.pocket_margin, lim.gauge_gap, lim.min_pocket_depth) == pytest.approx((1e-3, 2e-3, 0.5e-3))
    assert (lim.max_pocket_fraction, lim.min_snr) == pytest.approx((0.3, 5.0))
    assert (s.targets.force_error, s.targets.position_error) == pytest.approx((0.01, 1e-3))
    assert s.search.feature == "pocket" and s.search.sections == ("rectangle", "round", "tube")
    assert len(s.search.materials) >= 8
    assert s.free_length == pytest.approx(0.110 + 0.005, rel=1e-12)  # x_max + tip_margin (MODEL.md 1)


def test_a_custom_gauge_needs_every_field():
    raw = copy.deepcopy(MINIMAL) | {"gauge": {"factor": 2.1, "length": "5 mm", "width": "3 mm"}}
    with pytest.raises(SpecError, match=r"gauge\.max_strain: missing"):
        parse_spec(raw)
    raw["gauge"]["max_strain"] = "1000 ue"
    g = parse_spec(raw).gauge
    assert (g.name, g.factor, g.length, g.width, g.max_strain) == ("custom", 2.1, 5e-3, 3e-3, pytest.approx(1e-3))


def test_the_normalised_spec_reads_back_unchanged(examples):
    # design.json stores spec.to_dict(); reading it again must give the same Spec.
    for name in ("prototype-a", "prototype-b", "prototype-c"):
        s = spec_module.load_spec(examples / f"{name}.yaml")
        raw = s.to_dict()
        raw["electronics"] = {k: v for k, v in raw["electronics"].items() if v is not None and k != "noise_output"}
        raw.pop("design")
        again = parse_spec(raw)
        assert again.load == s.load and again.electronics == s.electronics and again.gauge == s.gauge
        assert again.limits == s.limits and again.targets == s.targets and again.search == s.search
        assert math.isclose(again.sigma_v, s.sigma_v, rel_tol=1e-15)


def test_yaml_error_message_names_where_the_unclosed_bracket_opens():
    # The parser notices the missing ']' only at the end of the file (line 4); the message
    # must also point at line 3, where the list was opened, or the user cannot find it.
    with pytest.raises(SpecError, match=r"line 4.*flow sequence that starts at line 3, column 10"):
        parse_spec_text("name: x\nload:\n  force: [1 N, 2 N\n", source="s.yaml")


def test_the_corner_radius_default_is_recorded_in_the_normalised_spec():
    """cad.corner_radius: R0.2 (stock bull-nose end mills), else the largest corner radius of the
    tool catalogue (materials/tools.yaml) at most 0.4 of the shallowest pocket allowed and of a
    given end mill, among that end mill's radii where the catalogue lists it; design.json's
    spec.cad carries it. The catalogue's metric radii: 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, ... mm;
    its Ø0.4 mm end mill has R0.01-R0.05."""
    assert parse_spec(copy.deepcopy(MINIMAL)).to_dict()["cad"]["corner_radius"] == pytest.approx(0.2e-3)
    shallow = copy.deepcopy(MINIMAL) | {"limits": {"min_pocket_depth": "0.3 mm"}}
    assert parse_spec(shallow).cad.corner_radius == pytest.approx(0.1e-3)        # 0.12 mm: R0.1
    tiny_mill = copy.deepcopy(MINIMAL) | {"cad": {"end_mill_diameter": "0.4 mm"}}
    assert parse_spec(tiny_mill).cad.corner_radius == pytest.approx(0.05e-3)     # 0.16 mm, Ø0.4's: R0.05
    # with imperial stock, the imperial end mills' (R0.005-0.090 in): R0.005 in under 0.2 mm
    imperial = copy.deepcopy(MINIMAL) | {"search": {"stock": "imperial"}}
    assert parse_spec(imperial).cad.corner_radius == pytest.approx(0.005 * 25.4e-3)
    given = copy.deepcopy(MINIMAL) | {"cad": {"corner_radius": "0.5 mm"}}
    assert parse_spec(given).to_dict()["cad"]["corner_radius"] == pytest.approx(0.5e-3)
    # a fixed design shallower than min_pocket_depth (evaluate judges it) gets a radius that fits it
    raw = copy.deepcopy(MINIMAL) | {"design": {"material": "7075-T6", "section": {"kind": "round", "diameter": "10 mm"},
                                               "stations": ["10 mm", "40 mm"],
                                               "feature": {"kind": "pocket", "depth": "0.25 mm"}}}
    spec = parse_spec(raw)
    assert spec.cad.corner_radius == pytest.approx(0.1e-3)
    # read back from design.json (without the design block) it stays
    again = spec.to_dict()
    again.pop("design")
    again["electronics"] = {k: v for k, v in again["electronics"].items() if v is not None and k != "noise_output"}
    assert parse_spec(again).cad == spec.cad


@pytest.mark.parametrize("example", ["gripper-finger", "prototype-b", "prototype-c"])
def test_design_json_s_spec_reads_back_as_a_spec_file(examples, example):
    """docs/spec.md §4: design.json's ``spec`` is the normalised spec; written out as YAML, without
    electronics' derived ``noise_output`` and its null keys, it is a spec again, the same one (it had
    held the calibration block's defaults without an environment, which a spec file may not)."""
    import yaml

    from designer.spec.reader import load_spec, parse_spec_text

    spec = load_spec(examples / f"{example}.yaml")
    normalised = spec.to_dict()
    # electronics' derived output noise and its unused keys are the record's, not the spec's
    written = dict(normalised, electronics={k: v for k, v in normalised["electronics"].items()
                                            if k != "noise_output" and v is not None})
    again = parse_spec_text(yaml.safe_dump(written), source="design.json's spec")
    assert again.to_dict() == normalised
