"""spec.yaml (SPEC.md): what a good spec becomes, and how every bad one is refused.

A bad spec must make ``fpdesign evaluate`` exit 2 with one line on stderr that names the key
and the offending value, with no traceback and no output folder (SPEC.md: "errors that name
the key, the value and what is allowed").
"""

from __future__ import annotations

import copy
import math

import pytest
import yaml

from designer.spec import reader as spec_module
from designer.cli import main
from designer.errors import SpecError
from designer.spec.reader import parse_spec, parse_spec_text

GF = 9.80665e-3  # N per gram-force


@pytest.fixture(scope="module")
def base(examples) -> dict:
    """Prototype B as a dictionary: a good spec to break one key at a time."""
    return yaml.safe_load((examples / "prototype-b.yaml").read_text(encoding="utf-8"))


def _set(raw, path, value):
    *parents, last = path.split(".")
    for p in parents:
        raw = raw.setdefault(p, {})
    raw[last] = value


def _del(raw, path):
    *parents, last = path.split(".")
    for p in parents:
        raw = raw[p]
    del raw[last]


# id: (changes to Prototype B, or the whole file text; words the message must contain)
BAD_SPECS = {
    "reversed force range": ({"load.force": ["20 N", "0.5 N"]}, ["load.force", "20 N", "0.5 N", "reversed"]),
    "reversed position range": ({"load.position": ["450 mm", "150 mm"]}, ["load.position", "450 mm", "reversed"]),
    "equal width limits": ({"limits.width": ["5 mm", "5 mm"]}, ["limits.width", "5 mm"]),
    "force in mm": ({"load.force": ["3 mm", "20 N"]}, ["load.force[0]", "3 mm", "wrong units", "force"]),
    "position in newtons": ({"load.position": ["150 mm", "2 N"]}, ["load.position[1]", "2 N", "length"]),
    "noise in newtons": ({"electronics.noise": "5 N"}, ["electronics.noise", "5 N", "voltage"]),
    "gain in volts": ({"electronics.gain": "5 V"}, ["electronics.gain", "5 V"]),
    "force target in mm": ({"targets.force_error": "3 mm"}, ["targets.force_error", "3 mm"]),
    "max strain in mm": ({"gauge": {"name": "BF120-3AA", "max_strain": "2 mm"}}, ["gauge.max_strain", "2 mm"]),
    "unknown top-level key": ({"colour": "red"}, ["colour", "unknown key", "load"]),
    "unknown load key": ({"load.weight": "2 N"}, ["load.weight", "unknown key", "force"]),
    "unknown limits key": ({"limits.saftey_factor": 2}, ["limits.saftey_factor", "unknown key", "safety_factor"]),
    "unknown section key": ({"design.section.depth": "3 mm"}, ["design.section.depth", "unknown key"]),
    "unknown feature key": ({"design.feature.depth": "3 mm"}, ["design.feature.depth", "unknown key"]),
    "missing electronics": ({"-electronics": None}, ["electronics", "missing"]),
    "missing load": ({"-load": None}, ["load", "missing"]),
    "missing force": ({"-load.force": None}, ["load.force", "missing"]),
    "missing excitation": ({"-electronics.excitation": None}, ["electronics.excitation", "missing"]),
    "two noise keys": ({"electronics.noise_rti": "50 nV"}, ["electronics", "noise", "noise_rti", "exactly one"]),
    "no noise key": ({"-electronics.noise": None}, ["electronics", "noise_rti", "none is given"]),
    "unknown material in design": ({"design.material": "unobtainium"}, ["design.material", "unobtainium", "2024-T3"]),
    "unknown material in search": ({"search.materials": ["6061-T6", "unobtainium"]},
                                   ["search.materials[1]", "unobtainium", "7075-T6"]),
    "material as a list": ({"design.material": ["2024-T3"]}, ["design.material", "['2024-T3']"]),
    "search material as a list": ({"search.materials": [["2024-T3"]]}, ["search.materials[0]", "['2024-T3']"]),
    "unknown gauge": ({"gauge": "XYZ-1"}, ["gauge", "XYZ-1", "BF120-3AA"]),
    "unknown gauge name with fields": ({"gauge": {"name": "XYZ-1", "factor": 2.1}}, ["gauge", "XYZ-1", "BF120-3AA"]),
    "gauge name as a list": ({"gauge": {"name": ["BF120-3AA"]}}, ["gauge.name", "['BF120-3AA']"]),
    "NaN force": ({"load.force": [float("nan"), "20 N"]}, ["load.force[0]", "nan", "finite"]),
    "NaN text with units": ({"electronics.noise": "nan mV"}, ["electronics.noise", "nan mV"]),
    "infinite length": ({"design.length": float("inf")}, ["design.length", "inf"]),
    "negative excitation": ({"electronics.excitation": "-5 V"}, ["electronics.excitation", "-5 V", "positive"]),
    "negative force": ({"load.force": ["-1 N", "20 N"]}, ["load.force[0]", "-1 N", "positive"]),
    "zero gain": ({"electronics.gain": 0}, ["electronics.gain", "0", "positive"]),
    "zero length": ({"design.length": "0 mm"}, ["design.length", "0 mm", "positive"]),
    "negative station": ({"design.stations": ["-20 mm", "100 mm"]}, ["design.stations[0]", "-20 mm"]),
    "zero hole": ({"design.feature.diameter": 0}, ["design.feature.diameter", "0"]),
    "safety factor below one": ({"limits.safety_factor": 0.5}, ["limits.safety_factor", "0.5", "at least 1"]),
    "non-numeric gain": ({"electronics.gain": "lots"}, ["electronics.gain", "lots"]),
    "non-numeric force": ({"load.force": ["abc", "20 N"]}, ["load.force[0]", "abc"]),
    "boolean as a number": ({"electronics.gain": True}, ["electronics.gain", "True"]),
    "list as a number": ({"limits.safety_factor": [1, 2]}, ["limits.safety_factor", "[1, 2]"]),
    "force not a pair": ({"load.force": "20 N"}, ["load.force", "20 N", "pair"]),
    "stations not whole": ({"stations": 2.5}, ["stations", "2.5", "whole"]),
    "too few stations": ({"stations": 1}, ["stations", "1", "from 2 to 10"]),
    "fatigue not boolean": ({"limits.fatigue": "yes"}, ["limits.fatigue", "yes", "true or false"]),
    "bad bridge": ({"bridge": "third"}, ["bridge", "third", "quarter", "half", "full"]),
    "bad objective": ({"objective": "speed"}, ["objective", "speed", "error", "deflection", "mass"]),
    "three axes": ({"axes": 3}, ["axes", "3"]),
    "axes as text": ({"axes": "two"}, ["axes", "two"]),
    "bad section kind": ({"design.section": {"kind": "hexagon", "width": "5 mm"}},
                         ["design.section.kind", "hexagon", "rectangle"]),
    "bad feature kind": ({"design.feature": {"kind": "slot"}}, ["design.feature.kind", "slot", "pocket"]),
    "bad search feature": ({"search.feature": "groove"}, ["search.feature", "groove"]),
    "hole on a round section": ({"design.section": {"kind": "round", "diameter": "12.7 mm"}},
                                ["design.feature.kind", "hole", "round"]),
    "hole in a biaxial beam": ({"axes": 2}, ["design.feature.kind", "hole", "axes"]),
    "hole wider than the beam": ({"design.feature.diameter": "13 mm"}, ["design.feature.diameter", "13 mm"]),
    "pocket deeper than the wall": ({"design.section": {"kind": "tube", "diameter": "12.7 mm", "wall": "1.65 mm"},
                                     "design.feature": {"kind": "pocket", "depth": "2 mm"}},
                                    ["design.feature.depth", "2 mm", "1.65 mm", "wall"]),
    "pocket deeper than half the height": ({"design.feature": {"kind": "pocket", "depth": "7 mm"}},
                                           ["design.feature.depth", "7 mm"]),
    "wall thicker than the radius": ({"design.section": {"kind": "tube", "diameter": "10 mm", "wall": "5 mm"}},
                                     ["design.section.wall", "5 mm"]),
    "stations out of order": ({"design.stations": ["100 mm", "20 mm"]}, ["design.stations", "100", "increase"]),
    "one station": ({"design.stations": ["20 mm"]}, ["design.stations", "20 mm", "at least 2"]),
    "beam shorter than the load": ({"design.length": "400 mm"}, ["design.length", "400 mm", "450 mm"]),
    "section not a mapping": ({"design.section": "square"}, ["design.section", "square", "mapping"]),
    "load not a mapping": ({"load": ["1 N", "2 N"]}, ["load", "['1 N', '2 N']", "mapping"]),
    "pocket fraction too large": ({"limits.max_pocket_fraction": 0.6}, ["limits.max_pocket_fraction", "0.6"]),
    "zero corner radius": ({"cad.corner_radius": 0}, ["cad.corner_radius", "0", "positive"]),
    "negative corner radius": ({"cad.corner_radius": "-0.2 mm"}, ["cad.corner_radius", "-0.2 mm", "positive"]),
    "corner radius in newtons": ({"cad.corner_radius": "0.2 N"}, ["cad.corner_radius", "0.2 N", "length"]),
    "corner radius not a number": ({"cad.corner_radius": "round"}, ["cad.corner_radius", "round"]),
    "corner radius of half the end mill": ({"cad.end_mill_diameter": "2 mm", "cad.corner_radius": "1 mm"},
                                           ["cad.corner_radius", "1 mm", "half the end mill", "cad.end_mill_diameter"]),
    "corner radius deeper than the pocket": ({"design.feature": {"kind": "pocket", "depth": "1 mm"},
                                              "cad.corner_radius": "1.5 mm"},
                                             ["cad.corner_radius", "1.5 mm", "design.feature.depth", "1 mm"]),
    # Far outside any physical range: the numbers overflow or divide by zero in the model.
    "sub-atomic width": ({"design.section.width": "1e-30 mm"}, ["cannot be evaluated", "physical range"]),
    "absurd gain": ({"electronics.gain": 1e300}, ["cannot be evaluated", "force_error", "physical range"]),
    "YAML syntax error": ("load: [200 gf, 2000 gf\nelectronics: {excitation: 5 V\n", ["YAML syntax error", "line"]),
    "YAML tab indentation": ("load:\n\tforce: [1 N, 2 N]\n", ["YAML syntax error", "line 2"]),
    "empty file": ("", ["empty", "load", "electronics"]),
    "only a comment": ("# nothing here\n", ["empty"]),
    "list instead of a mapping": ("- load\n- electronics\n", ["mapping", "list"]),
    "a bare number": ("42\n", ["mapping", "int"]),
}


def _spec_text(base, change):
    if isinstance(change, str):
        return change
    raw = copy.deepcopy(base)
    for path, value in change.items():
        if path.startswith("-"):
            _del(raw, path[1:])
        else:
            _set(raw, path, value)
    return yaml.safe_dump(raw, allow_unicode=True, sort_keys=False)


@pytest.mark.parametrize("case", list(BAD_SPECS))
def test_a_bad_spec_exits_2_with_a_one_line_message(case, base, tmp_path, capsys):
    change, words = BAD_SPECS[case]
    path = tmp_path / "spec.yaml"
    path.write_text(_spec_text(base, change), encoding="utf-8")
    out = tmp_path / "out"
    code = main(["evaluate", str(path), "-o", str(out), "--no-cad", "--no-plots"])
    captured = capsys.readouterr()
    assert code == 2, captured.err
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    message = lines[0]
    assert message.startswith("fpdesign: error: ")
    assert "Traceback" not in captured.err + captured.out
    for word in words:
        assert word in message, f"{word!r} missing from: {message}"
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec.yaml"]  # no scratch folder left


def test_a_missing_spec_file_exits_2(tmp_path, capsys):
    code = main(["evaluate", str(tmp_path / "nowhere.yaml"), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"])
    err = capsys.readouterr().err
    assert code == 2
    assert "nowhere.yaml" in err and "no such file" in err


def test_evaluate_without_a_design_block_exits_2(base, tmp_path, capsys):
    raw = copy.deepcopy(base)
    del raw["design"]
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    assert main(["evaluate", str(path), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "design: missing" in err and "optimize" in err


# ----------------------------------------------------------------- what a good spec becomes

def test_the_prototype_b_example_is_the_papers_table_1(examples):
    # Noh et al. 2025, Table 1 (Prototype B) and section 4.3 (1.3 mV, 200-2000 g, 15-45 cm).
    s = spec_module.load_spec(examples / "prototype-b.yaml")
    assert s.design.material == "2024-T3"
    assert (s.design.section.width, s.design.section.height) == pytest.approx((12.7e-3, 12.7e-3), rel=1e-12)
    assert s.design.stations == pytest.approx((0.020, 0.100), rel=1e-12)
    assert s.design.feature.kind == "hole" and s.design.feature.diameter == pytest.approx(9.5e-3, rel=1e-12)
    assert s.free_length == pytest.approx(0.450, rel=1e-12)
    assert s.sigma_v == pytest.approx(1.3e-3, rel=1e-12)
    assert (s.load.force_min, s.load.force_max) == pytest.approx((200 * GF, 2000 * GF), rel=1e-12)
    assert (s.load.position_min, s.load.position_max) == pytest.approx((0.150, 0.450), rel=1e-12)
    assert s.bridge_factor == 2


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


def test_the_corner_radius_default_is_recorded_in_the_normalised_spec():
    """cad.corner_radius: R0.2 (stock bull-nose end mills), at most 0.4 of the shallowest pocket
    allowed and of a given end mill, rounded down to 0.01 mm; design.json's spec.cad carries it."""
    assert parse_spec(copy.deepcopy(MINIMAL)).to_dict()["cad"]["corner_radius"] == pytest.approx(0.2e-3)
    shallow = copy.deepcopy(MINIMAL) | {"limits": {"min_pocket_depth": "0.3 mm"}}
    assert parse_spec(shallow).cad.corner_radius == pytest.approx(0.12e-3)
    tiny_mill = copy.deepcopy(MINIMAL) | {"cad": {"end_mill_diameter": "0.4 mm"}}
    assert parse_spec(tiny_mill).cad.corner_radius == pytest.approx(0.16e-3)
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
