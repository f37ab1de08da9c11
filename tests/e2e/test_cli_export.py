"""``fpdesign export``: the STEP model read back from disk against the design's own numbers,
the other files it writes, and bad designs refused.

Reference values are closed forms of the design's geometry (MODEL.md sections 1-2): the
section area times the free length, minus each feature (a slot with rounded corners removes
``p (l w - (4 - pi) r^2)``; a flat removes the circular segment ``R^2 (alpha - sin alpha cos alpha)``
times its length; a hole ``pi d^2/4 b``), less the fillets the tool's corner radius leaves where
pocket and flat floors meet their walls, plus the clamp block, minus its bolt holes, the wire
channels and the load grooves. Tolerances: positions 0.01 mm (the resolution of design.json,
MODEL.md section 5); volume 0.5 % (the acceptance criterion of the CAD issue; the solids are
exact B-reps, so the observed error is far smaller, which the tight secondary check shows).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from designer.outputs import cad
from designer.cli import main
from designer.spec.cad import DEFAULT_CORNER_RADIUS
from shared_inputs import CAD_BAD as BAD
from shared_inputs import cad_mutate as mutate
from shared_inputs import cad_record as record

pytestmark = pytest.mark.slow

DATA = Path(__file__).resolve().parents[1] / "data"
MM = 1e-3
POSITION_TOL_MM = 0.01
VOLUME_REL_TOL = 0.005
FIXTURES = ["prototype_a", "prototype_b", "prototype_c", "prototype_c_flats", "rect_pockets", "round_flats",
            "tube_flats", "square_biaxial_pockets"]


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


# A fillet of radius r in an inside corner between two perpendicular faces fills the corner's
# "spandrel": the square r x r less the quarter disc of radius r centred on its far corner,
#     A = r^2 - pi r^2 / 4 = (1 - pi/4) r^2,
# so along a straight edge of length L it adds (1 - pi/4) r^2 L of material back into a pocket.
# Measured from the wall, the spandrel's centroid lies at
#     u = (r^3/2 - (pi r^2/4)(r - 4r/(3 pi))) / A = r (10 - 3 pi) / (12 - 3 pi)
# (the square's first moment less the quarter disc's, whose centroid is 4r/(3 pi) from its centre).


def spandrel_area(r: float) -> float:
    return (1 - math.pi / 4) * r * r


def slot_floor_fillet(lp: float, wp: float, rho: float, r: float) -> float:
    """Material the bull-nose end mill's corner radius ``r`` leaves around a slot's floor.

    The slot's outline is ``lp x wp`` with plan corner radius ``rho`` (the end mill's radius).
    The straight walls are ``2 (lp - 2 rho) + 2 (wp - 2 rho)`` long; around the four corner arcs
    (a full turn together) the spandrel turns about the arcs' axes at radius ``rho - u``
    (Pappus): ``2 pi (rho - u) A``."""
    u = r * (10 - 3 * math.pi) / (12 - 3 * math.pi)
    return spandrel_area(r) * (2 * (lp - 2 * rho) + 2 * (wp - 2 * rho) + 2 * math.pi * (rho - u))


def flat_end_fillet(R: float, p: float, r: float) -> float:
    """Material the corner radius ``r`` leaves at one end of a flat ``p`` deep on a round of radius ``R``.

    The fillet runs across the bar, but only where there is bar: at height ``v`` above the floor
    (``z = R - p + v``) the spandrel is ``r - sqrt(r^2 - (r - v)^2)`` long (along X) and the bar
    ``2 sqrt(R^2 - z^2)`` wide (a tube's bore lies below the floor, as p < wall). For r << R this is
    close to ``(1 - pi/4) r^2`` times the flat's width, the straight-edge formula."""
    from scipy.integrate import quad

    def slice_area(v):
        z = R - p + v
        return (r - math.sqrt(max(r * r - (r - v) ** 2, 0.0))) * 2 * math.sqrt(max(R * R - z * z, 0.0))

    value, _ = quad(slice_area, 0.0, r, epsabs=1e-22, epsrel=1e-12, limit=200)
    return value


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
        rf = rec["spec"]["cad"].get("corner_radius") or DEFAULT_CORNER_RADIUS   # the tool's corner radius
        if sec["kind"] == "rectangle":
            r = beam.end_mill / 2
            volume -= faces * n * (p * (lp * wp - (4 - math.pi) * r * r) - slot_floor_fillet(lp, wp, r, rf))
        else:
            volume -= faces * n * (segment_area(R, p) * lp - 2 * flat_end_fillet(R, p, rf))
        # the wire channel's floor stays above the fillets (z > floor + r), so they do not overlap
        assert beam.channels is None or beam.channels.depth < p - rf
    elif feat["kind"] == "hole":
        volume -= n * math.pi * feat["diameter"] ** 2 / 4 * b
    if beam.channels is not None:
        cw, cd = beam.channels.width, beam.channels.depth
        run = stations[-1] - feat["length"] / 2 - (n - 1) * feat["length"]   # outside the pockets
        across = cw * cd if sec["kind"] == "rectangle" else channel_area_on_circle(R, cw, cd)
        volume -= faces * (across * run + cd * math.pi * cw * cw / 8)         # half-round end in the block
    if beam.grooves is not None:
        # a full-radius groove: at x from its middle it is f(x) = g - r + sqrt(r^2 - x^2) deep
        # (r half its width), over every face of a rectangle, all around a round bar or tube
        from scipy.integrate import quad

        g, r = beam.grooves.depth, beam.grooves.width / 2

        def cut(x):
            f = max(g - r + math.sqrt(r * r - x * x), 0.0)
            if sec["kind"] == "rectangle":
                return b * h - (b - 2 * f) * (h - 2 * f)
            return math.pi * (R * R - (R - f) ** 2)

        removed, _ = quad(cut, -r, r, epsabs=1e-22, epsrel=1e-12, limit=200)
        volume -= len(beam.grooves.positions) * removed
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


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full, a device that is always full")
def test_a_device_that_cannot_be_written_leaves_no_file_written_and_no_folder_made(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "beam.step").write_text("the previous model")
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert main(["export", str(DATA / "cad_rect_pockets.json"), "--step", str(out / "beam.step"),
                 "--svg", str(out / "new" / "drawing.svg"), "--stl", "/dev/full"]) == 2
    assert capsys.readouterr().err.strip() == "fpdesign: error: cannot write /dev/full: No space left on device"
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


@pytest.mark.parametrize("flag, name, allowed", [("--png", "model.jpg", ".png"), ("--step", "beam.stl", ".step or .stp"),
                                                 ("--svg", "drawing.pdf", ".svg"), ("--drawing-png", "sheet.svg", ".png")])
def test_an_output_named_for_another_format_exits_2_before_any_file_is_written(tmp_path, capsys, flag, name, allowed):
    """export writes each output in one format: --png model.jpg had written a PNG into a .jpg."""
    step = tmp_path / "beam.STEP"   # the suffix in any case
    assert main(["export", str(DATA / "cad_rect_pockets.json"), "--step", str(step), flag, str(tmp_path / name)]) == 2
    assert capsys.readouterr().err.strip() == (f"fpdesign: error: {flag}: {tmp_path / name} names another format "
                                               f"than it is written in; its suffix must be {allowed} (or none)")
    assert sorted(tmp_path.iterdir()) == []


def test_not_json_and_no_outputs_exit_2(tmp_path, capsys):
    path = tmp_path / "design.json"
    path.write_text("{not json")
    assert main(["export", str(path), "--step", str(tmp_path / "b.step")]) == 2
    assert main(["export", str(DATA / "cad_prototype_b.json")]) == 2
    assert "at least one of --step" in capsys.readouterr().err
    assert not (tmp_path / "b.step").exists()


def fillet_axes(rec: dict, rf: float) -> dict:
    """Where the axes of the floor fillets lie (mm), by the axis they run along: for every featured
    face and station, the two end fillets (across the beam) and, in a slot, the two side fillets
    (along it). An axis is given by its two coordinates across its own direction."""
    d = rec["design"]
    sec, feat = d["section"], d["feature"]
    half = sec.get("height", sec.get("diameter")) / 2
    p, lp, wp = feat["depth"], feat["length"], feat["width"]
    level = half - p + rf                       # the axes sit one radius above the floor ...
    ends = lp / 2 - rf                          # ... and one radius in from the walls
    sides = wp / 2 - rf
    slot = sec["kind"] == "rectangle"
    out = {"x": set(), "y": set(), "z": set()}
    faces = [("z", s) for s in (1, -1)] + ([("y", s) for s in (1, -1)] if d.get("axes", 1) == 2 else [])
    for normal, sign in faces:
        across = "y" if normal == "z" else "z"   # the end fillets run across the beam, in the face
        for st in d["stations"]:
            for e in (-ends, ends):
                # key: the coordinates other than the axis' own, in x, y, z order
                out[across].add(tuple(round(v / MM, 3) for v in ((st + e, sign * level))))
        if slot:
            for e in (-sides, sides):
                pos = {normal: sign * level, across: e}
                out["x"].add(tuple(round(pos[k] / MM, 3) for k in ("y", "z")))
    return out


@pytest.mark.parametrize("name", [n for n in FIXTURES if record(n)["design"]["feature"]["kind"] == "pocket"])
def test_floors_meet_their_walls_in_the_tools_corner_radius(exported, name):
    """Pocket and flat floors are rounded into their walls with the end mill's corner radius: a
    cylinder of that radius at each end (and, in a slot, along each side; a slot's corners are
    tori), its axis one radius above the floor and in from the wall. The design.json fixtures
    predate the key, so they get the spec reader's default, R0.2 (min_pocket_depth 0.5 mm)."""
    rec, beam, solid, step = exported[name]
    rf = 0.0002
    assert beam.floor_radius == pytest.approx(rf)
    expected = fillet_axes(rec, rf)
    for axis, where in expected.items():
        i = "xyz".index(axis)
        found = {tuple(round(v, 3) for k, v in enumerate(c) if k != i) for c in cad.cylinders(solid, axis, rf / MM)}
        assert found == where, axis
    # (the load grooves' full-radius roots are tori too on a round bar, around its axis at the groove)
    grooves = beam.grooves.positions if beam.grooves is not None else ()
    tori = [f for f in solid.Faces() if f.geomType() == "TORUS"
            and not any(abs(f.Center().x - x / MM) < 1e-3 for x in grooves)]
    corners = 4 * len(rec["design"]["stations"]) * len(beam.cut_faces)
    assert len(tori) == (corners if beam.section == "rectangle" else 0)


def test_a_given_corner_radius_is_built_and_its_fillets_weigh_as_the_closed_form():
    """spec.cad.corner_radius: 0.5 mm on the round bar's flats and the slot pockets."""
    for name in ("round_flats", "rect_pockets"):
        rec = mutate(name, lambda r: r["spec"]["cad"].update(corner_radius=0.0005, channel_depth=0.0003))
        beam = cad.resolve(rec)
        assert beam.floor_radius == pytest.approx(0.0005)
        solid = cad.build_solid(beam)
        assert solid.isValid()
        assert solid.Volume() == pytest.approx(analytic_volume(rec, beam) / MM ** 3, rel=1e-6)
        assert len(cad.cylinders(solid, "y", 0.5)) == 2 * 2 * len(rec["design"]["stations"])


def test_fillet_volumes_of_the_closed_form():
    """The fillet formulas against plain numbers: a spandrel is (1 - pi/4) r^2; a flat's end fillet
    on a wide bar tends to that times the flat's width."""
    assert spandrel_area(1.0) == pytest.approx(0.21460183660255172)
    R, p, r = 1.0, 1e-3, 1e-5          # a shallow flat on a large round: the chord hardly varies
    chord = 2 * math.sqrt(R * R - (R - p) ** 2)
    assert flat_end_fillet(R, p, r) == pytest.approx(spandrel_area(r) * chord, rel=2e-3)
    # a slot that is one full circle (lp = wp = 2 rho): the fillet is a ring around it (Pappus)
    rho, r = 2.0, 0.5
    u = r * (10 - 3 * math.pi) / (12 - 3 * math.pi)
    assert slot_floor_fillet(2 * rho, 2 * rho, rho, r) == pytest.approx(2 * math.pi * (rho - u) * spandrel_area(r))
