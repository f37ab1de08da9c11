"""spec.yaml (SPEC.md) through ``fpdesign evaluate``: how every bad spec is refused.

A bad spec must make ``fpdesign evaluate`` exit 2 with one line on stderr that names the key
and the offending value, with no traceback and no output folder (SPEC.md: "errors that name
the key, the value and what is allowed").
"""

from __future__ import annotations

import copy

import pytest
import yaml

from designer.cli import main

pytestmark = pytest.mark.slow


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
    "gauge factor of no gauge": ({"gauge": {"name": "BF120-3AA", "factor": 1e10}},
                                 ["gauge.factor", "1e+10", "between 0.5 and 500"]),
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
    "safety factor below one": ({"limits.safety_factor": 0.5}, ["limits.safety_factor", "0.5", "from 1 to 100"]),
    # 1e9 broke every design's stress limit and the diagnosis blamed the stations
    "safety factor of a billion": ({"limits.safety_factor": "1e9"}, ["limits.safety_factor", "1e9", "from 1 to 100"]),
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
    # The CAD details' lengths: none finer than the 0.01 mm grid (a channel 1 nm wide rounded to
    # nothing and stopped the CAD with a traceback, a radius of 1 nm stopped the mesher).
    "corner radius finer than the grid": ({"cad.corner_radius": "0.001 mm"},
                                          ["cad.corner_radius", "0.001 mm", "at least 0.01 mm"]),
    "channel width finer than the grid": ({"cad.channel_width": "1e-6 mm"},
                                          ["cad.channel_width", "1e-6 mm", "at least 0.01 mm"]),
    "channel depth finer than the grid": ({"cad.channel_depth": "0.005 mm"},
                                          ["cad.channel_depth", "0.005 mm", "at least 0.01 mm"]),
    "groove depth finer than the grid": ({"cad.groove_depth": "1 um"}, ["cad.groove_depth", "1 um", "0.01 mm"]),
    # a flat on a round bar: the model's channel on the round took a square root of a negative
    # number first, and a numpy warning of two lines came before the message
    "channel deeper than the flat": ({"design.section": {"kind": "round", "diameter": "12.7 mm"},
                                      "design.feature": {"kind": "pocket", "depth": "1 mm"},
                                      "cad.channel_depth": "100 m"},
                                     ["cad.channel_depth", "100000 mm", "design.feature.depth", "1 mm"]),
    # the default pocket (the gauge and a margin each side) named the key the spec does not have
    "pocket margin beyond any pocket": ({"design.feature": {"kind": "pocket", "depth": "1 mm"},
                                         "limits.pocket_margin": "100 m"},
                                        ["limits.pocket_margin", "100 m", "at most"]),
    # Far outside any physical range: the numbers overflow or divide by zero in the model.
    "sub-atomic width": ({"design.section.width": "1e-30 mm"}, ["'1e-30 mm'", "outside what fpdesign handles"]),
    "absurd gain": ({"electronics.gain": 1e300}, ["electronics.gain", "outside what fpdesign handles"]),
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


def test_a_clamp_clearance_past_the_load_names_it_and_the_load(base, tmp_path, capsys):
    """The stations must lie between the clamp's clearance and the load range: a clearance of
    200 mm with the load from 150 mm was reported as 'check limits.width and limits.height'."""
    raw = copy.deepcopy(base)
    del raw["design"]
    raw.setdefault("limits", {})["clamp_clearance"] = "200 mm"
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    assert main(["optimize", str(path), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("fpdesign: error: limits.clamp_clearance: 200 mm leaves no room for the stations before the "
                   "load range, which begins at load.position 150 mm; must be less than that")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("key, value, least", [
    ("limits.min_pocket_depth", "5 mm", "4.8 mm"),
    ("cad.channel_depth", "40 mm", "4.79 mm"),
    ("cad.corner_radius", "5 mm", "4.79 mm")])
def test_a_pocket_floor_deeper_than_any_pocket_names_its_key(examples, tmp_path, capsys, key, value, least):
    """The gripper finger's rectangles are at most 16 mm high and a pocket at most 0.3 of that
    deep (limits.max_pocket_fraction): 4.8 mm. A least depth past it (limits.min_pocket_depth, or
    a channel or corner radius, which the CAD cuts 0.01 mm shallower than the pocket) left every
    family infeasible, and optimize reported a 40 mm deep design with exit 1."""
    raw = yaml.safe_load((examples / "gripper-finger.yaml").read_text(encoding="utf-8"))
    assert raw["limits"]["height"][1] == "16 mm" and raw["search"]["sections"] == ["rectangle", "round", "tube"]
    _set(raw, key, value)
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    assert main(["optimize", str(path), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    cut = "" if key.startswith("limits") else " (cut 0.01 mm deeper)"
    assert err == (f"fpdesign: error: {key}: {value} leaves no room for a rectangle's pocket{cut} within "
                   f"limits.max_pocket_fraction 0.3 of its largest height (16 mm): 4.8 mm; must be at most {least}")
    assert not (tmp_path / "out").exists()


def test_a_calibration_block_without_an_environment_is_refused(examples, tmp_path, capsys):
    """calibration.weights and .placement are terms of the error budget (docs/spec.md 2.10), which
    only a spec with environment computes: without it they changed nothing, silently."""
    raw = yaml.safe_load((examples / "budget" / "gripper-finger-hx711.yaml").read_text(encoding="utf-8"))
    assert raw["calibration"] and raw["environment"]
    del raw["environment"]
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(raw), encoding="utf-8")
    assert main(["optimize", str(path), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots", "--quiet"]) == 2
    assert capsys.readouterr().err.strip() == (
        "fpdesign: error: calibration: its weights and placement are terms of the error budget, which only a spec "
        "with environment has (docs/spec.md 2.10); give environment.temperature or leave calibration out")
    assert not (tmp_path / "out").exists()
