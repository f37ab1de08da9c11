"""The CAD model: STEP read back from disk against the design's own numbers.

Reference values are closed forms of the design's geometry (MODEL.md sections 1-2): the
section area times the free length, minus each feature (a slot with rounded corners removes
``p (l w - (4 - pi) r^2)``; a flat removes the circular segment ``R^2 (alpha - sin alpha cos alpha)``
times its length; a hole ``pi d^2/4 b``), plus the clamp block, minus its bolt holes, the wire
channels and the load grooves. Tolerances: positions 0.01 mm (the resolution of design.json,
MODEL.md section 5); volume 0.5 % (the acceptance criterion of the CAD issue; the solids are
exact B-reps, so the observed error is far smaller, which the tight secondary check shows).
"""

from __future__ import annotations

import copy
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from designer.outputs import cad
from designer.cli import main
from designer.errors import DesignFileError

DATA = Path(__file__).parent / "data"
MM = 1e-3
POSITION_TOL_MM = 0.01
VOLUME_REL_TOL = 0.005

FIXTURES = ["prototype_a", "prototype_b", "prototype_c", "prototype_c_flats", "rect_pockets", "round_flats",
            "tube_flats", "square_biaxial_pockets"]


def record(name: str) -> dict:
    return json.loads((DATA / f"cad_{name}.json").read_text())


def segment_area(R: float, depth: float) -> float:
    """Circular segment beyond |y| = R - depth (MODEL.md section 2)."""
    alpha = math.acos((R - depth) / R)
    return R * R * (alpha - math.sin(alpha) * math.cos(alpha))


def channel_area_on_circle(R: float, width: float, depth: float) -> float:
    """Area of a circle of radius R above z = R - depth within |y| <= width/2."""
    a = min(width / 2, math.sqrt(R * R - (R - depth) ** 2))

    def F(y):  # antiderivative of sqrt(R^2 - y^2)
        return (y * math.sqrt(R * R - y * y) + R * R * math.asin(y / R)) / 2

    return 2 * (F(a) - F(0)) - 2 * a * (R - depth)


def analytic_volume(rec: dict, beam: cad.BeamCad) -> float:
    """Volume in m^3 from the design's numbers and the resolved CAD options (clamp, channels, grooves)."""
    d = rec["design"]
    sec, feat = d["section"], d["feature"]
    length, stations = d["length"], d["stations"]
    n = len(stations)
    faces = 4 if d.get("axes", 1) == 2 else 2
    if sec["kind"] == "rectangle":
        b, h = sec["width"], sec["height"]
        area = b * h
    else:
        R = sec["diameter"] / 2
        area = math.pi * R * R
        if sec["kind"] == "tube":
            area -= math.pi * (R - sec["wall"]) ** 2
    volume = area * length
    c = beam.clamp
    volume += c.length * c.width * c.height - 2 * math.pi * c.bolt_clearance ** 2 / 4 * c.height
    if feat["kind"] == "pocket":
        p, lp, wp = feat["depth"], feat["length"], feat["width"]
        if sec["kind"] == "rectangle":
            r = beam.end_mill / 2
            volume -= faces * n * p * (lp * wp - (4 - math.pi) * r * r)
        else:
            volume -= faces * n * segment_area(R, p) * lp
    elif feat["kind"] == "hole":
        volume -= n * math.pi * feat["diameter"] ** 2 / 4 * b
    if beam.channels is not None:
        cw, cd = beam.channels.width, beam.channels.depth
        run = stations[-1] - feat["length"] / 2 - (n - 1) * feat["length"]   # outside the pockets
        across = cw * cd if sec["kind"] == "rectangle" else channel_area_on_circle(R, cw, cd)
        volume -= faces * (across * run + cd * math.pi * cw * cw / 8)         # half-round end in the block
    if beam.grooves is not None:
        g, w = beam.grooves.depth, beam.grooves.width
        if sec["kind"] == "rectangle":
            ring = b * h - (b - 2 * g) * (h - 2 * g)
        else:
            ring = math.pi * (R * R - (R - g) ** 2)
        volume -= len(beam.grooves.positions) * w * ring
    return volume


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Each fixture exported once through the command line, then read back from disk."""
    out = {}
    folder = tmp_path_factory.mktemp("cad")
    for name in FIXTURES:
        step = folder / f"{name}.step"
        assert main(["export", str(DATA / f"cad_{name}.json"), "--step", str(step)]) == 0
        rec = record(name)
        out[name] = (rec, cad.resolve(rec), cad.read_step(step), step)
    return out


@pytest.mark.parametrize("name", FIXTURES)
def test_step_is_one_valid_solid_of_the_design_size(exported, name):
    rec, beam, solid, step = exported[name]
    assert solid.isValid()
    bb = solid.BoundingBox(tolerance=1e-6)
    d = rec["design"]
    sec = d["section"]
    width = sec.get("width", sec.get("diameter"))
    height = sec.get("height", sec.get("diameter"))
    assert bb.xmax == pytest.approx(d["length"] / MM, abs=POSITION_TOL_MM)
    assert bb.xmin == pytest.approx(-beam.clamp.length / MM, abs=POSITION_TOL_MM)
    assert bb.ymax - bb.ymin == pytest.approx(max(width, beam.clamp.width) / MM, abs=POSITION_TOL_MM)
    assert bb.zmin == pytest.approx(-height / 2 / MM, abs=POSITION_TOL_MM)
    assert bb.zmax == pytest.approx(height / 2 / MM, abs=POSITION_TOL_MM)


@pytest.mark.parametrize("name", FIXTURES)
def test_step_volume_matches_the_closed_form(exported, name):
    rec, beam, solid, step = exported[name]
    expected_mm3 = analytic_volume(rec, beam) / MM ** 3
    assert solid.Volume() == pytest.approx(expected_mm3, rel=VOLUME_REL_TOL)
    # The B-rep is exact: agreement is in fact at round-off level, far inside 0.5 %.
    assert solid.Volume() == pytest.approx(expected_mm3, rel=1e-6)


@pytest.mark.parametrize("name", [n for n in FIXTURES if record(n)["design"]["feature"]["kind"] == "pocket"])
def test_pocket_floors_at_design_depth_and_stations(exported, name):
    rec, beam, solid, step = exported[name]
    d = rec["design"]
    sec = d["section"]
    half = sec.get("height", sec.get("diameter")) / 2
    floor_mm = (half - d["feature"]["depth"]) / MM
    stations_mm = [s / MM for s in d["stations"]]
    axes = ["z"] + (["y"] if d.get("axes", 1) == 2 else [])
    for axis in axes:
        for sign in (+1, -1):
            floors = cad.planar_faces(solid, axis, sign * floor_mm)
            assert [f[0] for f in floors] == pytest.approx(stations_mm, abs=POSITION_TOL_MM), (axis, sign)
            # centred across the beam
            other = "yz".replace(axis, "")
            for f in floors:
                assert f["xyz".index(other)] == pytest.approx(0.0, abs=POSITION_TOL_MM)


def test_prototype_b_holes_at_stations(exported):
    rec, beam, solid, step = exported["prototype_b"]
    holes = cad.cylinders(solid, "y", 9.5 / 2)
    assert [h[0] for h in holes] == pytest.approx([20.0, 60.0, 100.0], abs=POSITION_TOL_MM)
    assert all(h[2] == pytest.approx(0.0, abs=POSITION_TOL_MM) for h in holes)  # on the neutral axis


@pytest.mark.parametrize("name", FIXTURES)
def test_bolt_holes_in_clamp_block(exported, name):
    rec, beam, solid, step = exported[name]
    bolts = cad.cylinders(solid, "z", beam.clamp.bolt_clearance / 2 / MM)
    xs = sorted(b[0] for b in bolts)
    assert xs == pytest.approx(sorted(x / MM for x in beam.clamp.bolt_positions), abs=POSITION_TOL_MM)
    assert all(x < 0 for x in xs)


def test_step_is_millimetres_with_the_design_name(exported):
    rec, beam, solid, step = exported["prototype_b"]
    text = step.read_text()
    assert "SI_UNIT(.MILLI.,.METRE.)" in text
    assert cad.step_product_names(step) == ["prototype-b"]


def test_prototype_c_tube_is_hollow_with_bore_to_clamp_face(exported):
    rec, beam, solid, step = exported["prototype_c"]
    bore_mm = (12.7 / 2 - 1.65)
    assert len(cad.cylinders(solid, "x", bore_mm)) == 1
    # the bore ends in a flat bottom at the clamp face
    assert cad.planar_faces(solid, "x", 0.0)


# ----------------------------------------------------------------- defaults and overrides

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


def test_non_standard_bolt_gets_a_rounded_up_clearance():
    assert cad.bolt_clearance(0.0035) == pytest.approx(0.0040)  # 1.12 x 3.5 = 3.92 -> 4.0 mm


# ----------------------------------------------------------------- the export command and its files

def read_stl(path: Path):
    import numpy as np

    data = path.read_bytes()
    count = int.from_bytes(data[80:84], "little")
    assert len(data) == 84 + 50 * count
    records = np.frombuffer(data[84:], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    return records["v"].reshape(-1, 3)


def test_export_writes_every_requested_file(tmp_path):
    out = tmp_path / "out"
    files = {"--step": out / "beam.step", "--stl": out / "beam.stl", "--svg": out / "drawing.svg",
             "--drawing-png": out / "drawing.png", "--png": out / "picture.png"}
    argv = ["export", str(DATA / "cad_rect_pockets.json")]
    for flag, path in files.items():
        argv += [flag, str(path)]
    assert main(argv) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in files.values())  # no temporary files
    # STL in mm: its vertices span the design's bounding box (20 x 8 mm bar, 150 mm + 40 mm clamp)
    v = read_stl(files["--stl"])
    assert v.min(axis=0) == pytest.approx([-40.0, -10.0, -4.0], abs=POSITION_TOL_MM)
    assert v.max(axis=0) == pytest.approx([150.0, 10.0, 4.0], abs=POSITION_TOL_MM)
    for key in ("--drawing-png", "--png"):
        assert files[key].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import xml.etree.ElementTree as ET

    root = ET.parse(files["--svg"]).getroot()
    assert root.get("width").startswith("1190.")  # A3 landscape: 420 mm = 1190.55 pt


def test_write_cad_outputs_names_files_after_the_design(tmp_path):
    written = cad.write_cad_outputs(record("prototype_c"), tmp_path)
    assert {k: p.name for k, p in written.items()} == {
        "step": "prototype-c.step", "model_png": "prototype-c-model.png",
        "drawing_svg": "prototype-c-drawing.svg", "drawing_png": "prototype-c-drawing.png"}
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in written.values())
    assert cad.step_product_names(written["step"]) == ["prototype-c"]


def test_outputs_are_readable_like_ordinary_files(tmp_path):
    written = cad.write_cad_outputs(record("prototype_a"), tmp_path)
    mask = os.umask(0)
    os.umask(mask)
    for path in written.values():
        assert path.stat().st_mode & 0o777 == 0o666 & ~mask


# ----------------------------------------------------------------- the drawing states the design

def drawing_texts(name: str) -> str:
    from designer.outputs import drawing

    fig = drawing.plot_drawing(cad.resolve(record(name)))
    return "\n".join(t.get_text() for t in fig.axes[0].texts)


def test_drawing_of_prototype_b_gives_stations_lengths_holes_material_and_name():
    texts = drawing_texts("prototype_b").splitlines()
    for expected in ["20", "60", "100",            # stations from the clamp face
                     "450", "475", "25",           # free length, overall, clamp block
                     "12.7", "Ø9.5",               # section, hole in the section view
                     "3x Ø9.5 THRU", "2x Ø4.5 THRU (M4 CLEARANCE)", "6.25", "12.5",
                     "2024-T3", "prototype-b"]:
        assert expected in texts, expected


def test_drawing_of_slot_pockets_gives_pocket_length_width_depth_and_tool():
    texts = drawing_texts("rect_pockets")
    lines = texts.splitlines()
    for expected in ["8.9", "5.5", "1", "20", "8", "80", "112.5", "145"]:
        assert expected in lines, expected
    assert "SLOT 8.9 x 5.5 x 1 DEEP, R1.5 CORNERS (Ø3 END MILL)" in texts
    assert "WIRE CHANNEL 1.5 WIDE x 0.5 DEEP" in texts
    assert "3x LOAD GROOVE 0.5 WIDE x 0.3 DEEP ALL AROUND" in texts


def test_drawing_of_flats_gives_across_flats_and_bore():
    lines = drawing_texts("tube_flats").splitlines()
    for expected in ["18", "Ø15", "Ø20", "(8.72)", "20", "50", "80", "200"]:
        assert expected in lines, expected   # 20 - 2 x 1 across flats; chord 2 sqrt(10^2 - 9^2) = 8.72


def test_long_plain_runs_are_broken_and_the_axis_keeps_order():
    from designer.outputs.drawing import views

    a = views.length_axis(cad.resolve(record("prototype_a")))
    assert len(a.gaps) == 1                                  # 123 -> 800 mm shortened
    assert a(0.02) < a(0.12) < a(0.5) < a(0.8)
    p = views.length_axis(cad.resolve(record("rect_pockets")))
    assert p.gaps == ()                                      # short runs stay to scale
    assert p(0.1) - p(0.0) == pytest.approx(100 * p.scale)


def test_depth_buffer_keeps_the_nearer_triangle():
    import numpy as np

    from designer.outputs.drawing import picture

    # two triangles over the same 10 x 10 pixel square at depths 1 and 2 (larger is nearer)
    square = np.array([[0, 0], [10, 0], [0, 10]], float)
    xy = np.stack([square, square])
    depth = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])
    z = picture._zbuffer(xy, depth, np.zeros(2), 1.0, (12, 12))
    covered = np.isfinite(z)
    assert np.all(z[covered] == 2.0)
    # the lower-left half of the square: pixel centres with x + y < 10 -> 45 pixels (+ 10 on the diagonal)
    assert 45 <= covered.sum() <= 55
    assert not covered[11, 11]


def test_model_picture_draws_both_panels():
    from designer.outputs import drawing

    beam = cad.resolve(record("prototype_b"))
    fig = drawing.plot_model(cad.model_meshes(beam, cad.build_solid(beam)), beam)
    assert len(fig.axes) == 2                                 # whole beam and the close-up
    assert all(ax.collections for ax in fig.axes)


# ----------------------------------------------------------------- bad input

def mutate(name: str, change) -> dict:
    rec = copy.deepcopy(record(name))
    change(rec)
    return rec


BAD = {
    "missing section": ("prototype_b", lambda r: r["design"].pop("section"), "design.section"),
    "negative width": ("prototype_b", lambda r: r["design"]["section"].update(width=-0.0127),
                       "design.section.width"),
    "flat deeper than the wall": ("prototype_c_flats", lambda r: r["design"]["feature"].update(depth=0.002),
                                  "design.feature.depth"),
    "pocket deeper than half": ("rect_pockets", lambda r: r["design"]["feature"].update(depth=0.004),
                                "design.feature.depth"),
    "station off the beam": ("prototype_b", lambda r: r["design"].update(stations=[0.02, 0.06, 0.46]),
                             "design.stations[2]"),
    "pocket over the clamp face": ("rect_pockets", lambda r: r["design"].update(stations=[0.003, 0.06]),
                                   "design.stations[0]"),
    "holes overlapping": ("prototype_b", lambda r: r["design"].update(stations=[0.02, 0.025, 0.1]),
                          "design.stations[1]"),
    "clamp too short": ("prototype_b", lambda r: r["spec"]["cad"].update(clamp_length=0.01),
                        "spec.cad.clamp_length"),
    "end mill wider than the slot": ("rect_pockets", lambda r: r["spec"]["cad"].update(end_mill_diameter=0.006),
                                     "spec.cad.end_mill_diameter"),
    "groove off the beam": ("round_flats", lambda r: r["spec"]["cad"].update(groove_positions=[0.07, 0.125]),
                            "spec.cad.groove_positions"),
    "default groove at the free end": ("prototype_b", lambda r: r["spec"]["cad"].update(load_grooves=True),
                                       "spec.cad.load_grooves"),
    "channel deeper than the pocket": ("rect_pockets", lambda r: r["spec"]["cad"].update(channel_depth=0.0015),
                                       "spec.cad.channel_depth"),
    "unknown feature": ("prototype_b", lambda r: r["design"]["feature"].update(kind="slot"),
                        "design.feature.kind"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_design_exits_2_names_the_key_and_writes_nothing(tmp_path, capsys, case):
    name, change, key = BAD[case]
    path = tmp_path / "design.json"
    path.write_text(json.dumps(mutate(name, change)))
    out = tmp_path / "out"
    rc = main(["export", str(path), "--step", str(out / "b.step"), "--stl", str(out / "b.stl"),
               "--svg", str(out / "d.svg"), "--png", str(out / "p.png")])
    err = capsys.readouterr().err
    assert rc == 2
    assert key in err, err
    assert "Traceback" not in err
    assert not out.exists() or not any(out.iterdir())


def test_messages_give_the_value_and_the_allowed_range():
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate("rect_pockets", lambda r: r["design"].update(stations=[0.02, 0.149])))
    assert str(info.value) == ("design.stations[1]: 0.149 m (149 mm) is off the beam: with its 8.9 mm pocket it "
                               "must lie between 4.45 mm and 145.55 mm from the clamp face (free length 150 mm)")


def test_not_json_and_no_outputs_exit_2(tmp_path, capsys):
    path = tmp_path / "design.json"
    path.write_text("{not json")
    assert main(["export", str(path), "--step", str(tmp_path / "b.step")]) == 2
    assert main(["export", str(DATA / "cad_prototype_b.json")]) == 2
    assert "at least one of --step" in capsys.readouterr().err
    assert not (tmp_path / "b.step").exists()


def test_cad_modules_import_without_cadquery_or_matplotlib():
    code = ("import sys, designer.cli.cad, designer.outputs.cad, designer.outputs.drawing; "
            "print('cadquery' in sys.modules, 'matplotlib' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                            cwd=Path(__file__).parent.parent)
    assert result.stdout.split() == ["False", "False"]


@pytest.mark.parametrize("case", sorted(BAD))
def test_cad_checks_its_own_needs_without_the_file_reader(case):
    """The same bad designs rejected by ``cad.resolve`` alone (a record built in memory)."""
    name, change, key = BAD[case]
    with pytest.raises(DesignFileError) as info:
        cad.resolve(mutate(name, change))
    assert key in str(info.value)
