"""The CAD model's options (designer.outputs.cad.resolve): the documented defaults, the spec's
overrides, and the design checks it makes on its own.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from designer.outputs import cad
from designer.errors import DesignFileError
from shared_inputs import CAD_BAD as BAD
from shared_inputs import cad_mutate as mutate
from shared_inputs import cad_record as record


def test_defaults_for_prototype_b_follow_the_documented_rules():
    beam = cad.resolve(record("prototype_b"))
    c = beam.clamp
    # largest default bolt with 3 d <= 12.7 mm is M4; ISO 273 medium clearance for M4 is 4.5 mm
    assert c.bolt_diameter == pytest.approx(0.004)
    assert c.bolt_clearance == pytest.approx(0.0045)
    # clamp: max(1.5 x 12.7, 6 x 4) = 24 mm, rounded up to 5 mm; holes at L/4 and 3L/4
    assert c.length == pytest.approx(0.025)
    assert sorted(c.bolt_positions) == pytest.approx([-0.01875, -0.00625])
    assert beam.channels is None and beam.grooves is None  # no pockets; grooves off by default


def test_defaults_for_slot_pockets():
    beam = cad.resolve(record("rect_pockets"))
    # largest standard end mill <= 0.6 x 5.5 mm = 3.3 mm is 3 mm; the 6.9 x 3.5 gauge clears its corners
    assert beam.end_mill == pytest.approx(0.003)
    assert beam.channels.width == pytest.approx(0.0015)
    assert beam.channels.depth == pytest.approx(0.0005)
    # default grooves at x_min, mid and x_max of the load range [80, 145] mm
    assert beam.grooves.positions == pytest.approx((0.08, 0.1125, 0.145))
    assert beam.grooves.depth == pytest.approx(0.0003)


@pytest.mark.parametrize("name, depth, mill, expected", [
    # half of a 0.75 mm pocket is 0.375 mm: drawn 0.37 mm deep; 1.5 mm wide (0.4 x 5.5 = 2.2 mm)
    ("rect_pockets", 0.75e-3, None, (1.5e-3, 0.37e-3)),
    # a given 4.5 mm end mill leaves 1 mm of the 5.5 mm slot's end wall straight
    ("rect_pockets", 1.2e-3, 4.5e-3, (1.0e-3, 0.5e-3)),
    ("round_flats", 0.85e-3, None, (1.5e-3, 0.42e-3)),
])
def test_the_model_counts_the_wire_channel_the_cad_cuts(name, depth, mill, expected):
    from designer.result.designfile import parse_design

    rec = mutate(name, lambda r: (r["design"]["feature"].update(depth=depth),
                                  r["spec"]["cad"].update(end_mill_diameter=mill)))
    built = cad.resolve(rec).channels
    g = parse_design(rec).design.geometry
    assert (built.width, built.depth) == pytest.approx(expected, rel=1e-9)
    assert (g.channel_width, g.channel_depth) == pytest.approx(expected, rel=1e-9)


def test_spec_cad_keys_override_the_defaults():
    beam = cad.resolve(record("round_flats"))
    assert beam.clamp.length == pytest.approx(0.030)
    assert beam.clamp.bolt_diameter == pytest.approx(0.005)
    assert beam.clamp.bolt_clearance == pytest.approx(0.0055)   # ISO 273 medium, M5
    assert beam.grooves.positions == pytest.approx((0.07, 0.10))
    assert beam.grooves.depth == pytest.approx(0.0004)
    rec = record("rect_pockets")
    rec["spec"]["cad"].update(wire_channels=False, load_grooves=False, end_mill_diameter=0.002)
    beam = cad.resolve(rec)
    assert beam.channels is None and beam.grooves is None and beam.end_mill == pytest.approx(0.002)


@pytest.mark.parametrize("depth, ok", [(0.0008, True), (0.00081, False), (0.004, False)])
def test_a_groove_is_at_most_the_default_s_share_of_the_section_the_beam_model_leaves_out(depth, ok):
    """The round-flats record's bar is 16 mm across: 5 % of it is 0.8 mm. A 4 mm groove (half the
    radius) had been drawn, and the design reported as holding, on a beam model that had no
    groove; the 3-D check of such a part found 2173 MPa at the groove."""
    rec = record("round_flats")
    rec["spec"]["cad"]["groove_depth"] = depth
    if ok:
        assert cad.resolve(rec).grooves.depth == pytest.approx(depth)
        return
    with pytest.raises(DesignFileError) as err:
        cad.resolve(rec)
    assert str(err.value) == (f"spec.cad.groove_depth: {depth!r} m ({depth * 1e3:g} mm) is too deep; it must be at "
                              "most 0.8 mm (5% of the section's smaller side)")


def test_non_standard_bolt_gets_a_rounded_up_clearance():
    assert cad.bolt_clearance(0.0035) == pytest.approx(0.0040)  # 1.12 x 3.5 = 3.92 -> 4.0 mm


def test_messages_give_the_value_and_the_allowed_range():
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("rect_pockets", lambda r: r["design"].update(stations=[0.02, 0.149])))
    assert str(info.value) == ("design.stations[1]: 0.149 m (149 mm) is off the beam: with its 8.9 mm pocket it "
                               "must lie between 4.45 mm and 145.55 mm from the clamp face (free length 150 mm)")


def test_cad_modules_import_without_cadquery_or_matplotlib():
    code = ("import sys, designer.cli.cad, designer.outputs.cad, designer.outputs.drawing; "
            "print('cadquery' in sys.modules, 'matplotlib' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                            cwd=Path(__file__).resolve().parents[2])
    assert result.stdout.split() == ["False", "False"]


@pytest.mark.parametrize("case", sorted(BAD))
def test_cad_checks_its_own_needs_without_the_file_reader(case):
    """The same bad designs rejected by ``cad.resolve`` alone (a record built in memory)."""
    name, change, key = BAD[case]
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate(name, change))
    assert key in str(info.value)


def test_corner_radius_messages_give_the_value_and_what_is_allowed():
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("rect_pockets", lambda r: r["spec"]["cad"].update(corner_radius=0.001)))
    assert str(info.value) == ("spec.cad.corner_radius: 0.001 m (1 mm) must be less than the pocket depth (1 mm), "
                               "so that the pocket keeps a wall above its floor radius")
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("round_flats", lambda r: r["spec"]["cad"].update(corner_radius=0.0011)))
    assert str(info.value) == ("spec.cad.corner_radius: 0.0011 m (1.1 mm) leaves a flat floor 6.7 mm long, shorter "
                               "than the 6.9 mm gauge backing; it must be at most 1 mm")
    # a flat as long as the backing has no room for any radius: the message says what would have
    # (the fixture's flats are 8.9 mm long, its gauge backing 6.9 mm)
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("round_flats", lambda r: (r["design"]["feature"].update(length=0.0069),
                                                     r["spec"]["cad"].update(corner_radius=0.0002))))
    assert str(info.value) == ("spec.cad.corner_radius: 0.0002 m (0.2 mm) leaves a flat floor 6.5 mm long, shorter "
                               "than the 6.9 mm gauge backing; a flat no longer than the backing has no room for "
                               "one: make it at least 7.3 mm long (design.feature.length)")


def test_a_flats_end_mill_may_be_as_long_as_the_flat():
    # the round_flats fixture's flats are 8.9 mm long; an end mill of that diameter cuts them
    beam = cad.resolve(mutate("round_flats", lambda r: r["spec"]["cad"].update(end_mill_diameter=0.0089)))
    assert beam.pocket_length == pytest.approx(0.0089) and "Ø8.9" in beam.tool


FLAT_SPEC = """\
name: flats
load: {force: [0.5 N, 19 N], position: [40 mm, 110 mm]}
electronics: {excitation: 5 V, gain: 128, noise_rti: 50 nV}
gauge: BF350-3AA
bridge: half
limits: {max_deflection: 1 mm}
design:
  material: Ti-6Al-4V
  section: {kind: round, diameter: 8 mm}
  stations: [9.45 mm, 30.55 mm]
  feature: {kind: pocket, depth: 1.65 mm, length: 8.9 mm}
  length: 115 mm
"""


@pytest.mark.parametrize("cad_line, key", [
    ("cad: {channel_depth: 5 mm}", "cad.channel_depth"),          # deeper than the 1.65 mm flat
    ("cad: {channel_width: 50 mm}", "cad.channel_width"),         # wider than the flat (5.5 mm)
    ("cad: {corner_radius: 1.6 mm}", "cad.corner_radius"),        # floor 8.9 - 3.2 mm under the 6.9 mm backing
    ("cad: {end_mill_diameter: 50 mm}", "cad.end_mill_diameter"),  # longer than the 8.9 mm flat
])
@pytest.mark.parametrize("cad_flag", ["--no-cad", None])
def test_evaluate_refuses_cad_options_that_do_not_fit_the_fixed_design(tmp_path, capsys, cad_line, key, cad_flag):
    # docs/spec.md 2.8: checked against a fixed design's pockets before it is judged, with or
    # without CAD outputs (the model would otherwise judge a channel deeper than the flat)
    from designer.cli import main

    spec = tmp_path / "flats.yaml"
    spec.write_text(FLAT_SPEC + cad_line + "\n")
    out = tmp_path / "out"
    code = main(["evaluate", str(spec), "-o", str(out), "--no-plots"] + ([cad_flag] if cad_flag else []))
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and f"error: {key}:" in err and "Traceback" not in err
    assert not out.exists()


def test_the_fixed_flats_design_alone_is_judged_feasible(tmp_path):
    # the control of the test above: without the cad line the design meets every limit (exit 0)
    from designer.cli import main

    spec = tmp_path / "flats.yaml"
    spec.write_text(FLAT_SPEC)
    assert main(["evaluate", str(spec), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"]) == 0


def test_a_search_keeps_its_pockets_deeper_than_a_given_channel(examples):
    """A search took a given cad.channel_depth for granted: the gripper finger's flats came out
    1.55 mm deep under a 3 mm channel, and the CAD refused the design it reported (exit 2 after
    the search). The least depth is now 0.01 mm over the channel (and over the corner radius;
    docs/model.md §1), and the CAD's own checks pass on the design reported."""
    cad_key, value = "channel_depth", "3 mm"
    import yaml

    from designer.result.pipeline import DesignOptions, design
    from designer.spec.reader import parse_spec

    raw = yaml.safe_load((examples / "gripper-finger.yaml").read_text(encoding="utf-8"))
    raw.setdefault("cad", {})[cad_key] = value
    spec = parse_spec(raw)
    result = design(spec, DesignOptions(tradeoff=False))
    assert result.record["status"] == "optimal"
    depth = result.record["design"]["feature"]["depth"]
    assert depth >= getattr(spec.cad, cad_key) + 1e-5 - 1e-12
    beam = cad.resolve(result.record)     # the CAD's checks of the channel and the radius
    assert beam.section == "round"


@pytest.mark.parametrize("change", [{"limits": {"pocket_margin": "0 mm"}}, {"cad": {"corner_radius": "1.6 mm"}}])
def test_a_search_keeps_its_flats_long_enough_for_the_corner_radius(examples, change):
    """A flat's floor, between the radii the end mill leaves where it meets the walls, must hold
    the gauge backing: its length less two corner radii. With limits.pocket_margin 0 mm (the
    default corner radius 0.2 mm) or a 1.6 mm corner radius (the 1 mm default margin), the search
    reported flats the CAD then refused (exit 2 after the search, naming design.feature.length,
    which a spec to optimize does not have). The pocket's margin is now at least the corner
    radius (Spec.pocket_size): BF350-3AA's 6.9 mm backing needs a 7.3 mm flat with R0.2 and a
    10.1 mm one with R1.6."""
    import yaml

    from designer.result.pipeline import DesignOptions, design
    from designer.spec.reader import parse_spec

    raw = yaml.safe_load((examples / "gripper-finger.yaml").read_text(encoding="utf-8"))
    for block, values in change.items():
        raw.setdefault(block, {}).update(values)
    spec = parse_spec(raw)
    result = design(spec, DesignOptions(tradeoff=False))
    assert result.record["status"] == "optimal"
    feature = result.record["design"]["feature"]
    corner = spec.cad.corner_radius
    assert feature["length"] >= 6.9e-3 + 2 * corner - 1e-9
    assert feature["length"] - 2 * corner >= spec.gauge.length - 1e-9
    beam = cad.resolve(result.record)     # the CAD's check of the floor passes
    assert beam.section == "round"


@pytest.mark.parametrize("length, tail", [
    # 10 mm holds two bolts of 10 / 6 = 1.666 mm (holes 1.5 diameters from each end and apart)
    (0.010, "; or give a spec.cad.bolt_diameter of at most 1.66 mm"),
    # 0.05 mm holds none of the 0.01 mm grid's: no smaller bolt to offer (it had been offered)
    (0.00005, ""),
])
def test_a_short_clamp_offers_a_bolt_it_can_hold(length, tail):
    r = record("prototype_b")
    r["spec"]["cad"].update(clamp_length=length)
    with pytest.raises(DesignFileError) as err:
        cad.resolve(r)
    assert str(err.value) == (f"spec.cad.clamp_length: {length!r} m ({length * 1e3:g} mm) is too short for two 4 mm "
                              "bolts; it must be at least 24 mm (holes 1.5 bolt diameters from the block's ends)"
                              + tail)


@pytest.mark.parametrize("width, depth", [(0.0055, 0.0003), (0.017, 0.002)])
def test_a_flat_narrower_than_its_pocket_is_told_the_depth_that_holds_it_or_that_none_does(width, depth):
    # A flat p deep on a Ø16 mm bar is 2 sqrt(p (D - p)) wide: a 5.5 mm pocket needs p = (D -
    # sqrt(D^2 - 5.5^2))/2 = 0.4878 mm; no flat is wider than the bar, so a 17 mm pocket has none
    import re

    change = (lambda r: r["design"]["feature"].update(width=width, depth=depth))
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("round_flats", change))
    text = str(info.value)
    if width < 0.016:
        least = float(re.search(r"the depth must be at least ([0-9.]+) mm", text).group(1))
        assert least == pytest.approx((16 - (16 ** 2 - 5.5 ** 2) ** 0.5) / 2, abs=0.005)
    else:
        assert "no flat on a Ø16 mm bar is that wide" in text and "at least" not in text


def test_a_size_on_its_grid_reads_as_the_file_holds_it():
    # a depth of 12 steps of the 0.05 mm grid is 12 * 5e-5 = 0.0006000000000000001 m in binary
    # (design.json holds 0.0006); the message names it 0.0006 m. (A 6.5 mm pocket on the Ø16 mm
    # bar needs a flat (16 - sqrt(16^2 - 6.5^2))/2 = 0.69 mm deep.)
    depth = 12 * 5e-5
    assert repr(depth) == "0.0006000000000000001"
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("round_flats", lambda r: r["design"]["feature"].update(width=0.0065, depth=depth)))
    assert str(info.value).startswith("design.feature.depth: 0.0006 m (0.6 mm) gives a flat ")
