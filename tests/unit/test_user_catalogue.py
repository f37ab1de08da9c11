"""Users' own catalogues beside the shipped one (designer.spec.catalogue.use, spec key
``catalogue``, ``--catalogue FILE``): tests/data/user-catalogue.yaml adds a material (6082-T6), a
gauge (KFGS-2-120), a stock table of 6082-T6 round bar and an end mill (Ø8.5 mm, R0.2 and R0.5)."""

import json
import shutil
from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent.parent / "data"
USER = DATA / "user-catalogue.yaml"

SPEC = """name: shop-finger
{catalogue}
load:
  force: [0.5 N, 20 N]
  position: [40 mm, 110 mm]
electronics:
  excitation: 5 V
  gain: 128
  noise_rti: 50 nV
gauge: {gauge}
bridge: half
limits:
  max_deflection: 1 mm
  width: [4 mm, 16 mm]
  height: [3 mm, 16 mm]
{rest}
"""
DESIGN = """design:
  material: {material}
  section: {{kind: round, diameter: 10 mm}}
  stations: [10 mm, 30 mm]
  feature: {{kind: none}}
"""


def _spec(tmp_path: Path, material="6082-T6", gauge="KFGS-2-120", catalogue="catalogue: shop.yaml", rest=None) -> Path:
    shutil.copy(USER, tmp_path / "shop.yaml")
    path = tmp_path / "spec.yaml"
    rest = DESIGN.format(material=material) if rest is None else rest
    path.write_text(SPEC.format(catalogue=catalogue, gauge=gauge, rest=rest))
    return path


def test_a_user_material_and_gauge_are_read_in_si_from_the_spec_s_folder(tmp_path, monkeypatch):
    """The file's figures in SI (70 GPa, 2.1, 6.4 x 3.0 mm backing, 1500 ue), read from the spec's
    folder whatever the working folder."""
    from designer.spec.reader import load_spec

    monkeypatch.chdir(DATA.parent)
    spec = load_spec(_spec(tmp_path))
    from designer.spec import catalogue

    alloy = catalogue.material("6082-T6")
    assert alloy.E == pytest.approx(70e9) and alloy.notch_length == pytest.approx(0.51e-3)
    assert alloy.source.startswith("EN 755-2")
    g = spec.gauge
    assert (g.name, g.factor, g.length, g.width, g.grid_length, g.max_strain) == \
        ("KFGS-2-120", 2.1, pytest.approx(6.4e-3), pytest.approx(3.0e-3), pytest.approx(2e-3), pytest.approx(1.5e-3))


def test_the_model_uses_the_user_material_s_modulus(tmp_path):
    """Reference: a beam's deflection and gauge strain go as 1/E (Euler-Bernoulli, and Timoshenko's
    shear term too, with G = E / 2(1 + nu) at the same nu = 0.33): the same bar in the user's
    6082-T6 (70 GPa) and the shipped 6061-T6 (68.9 GPa) differ by exactly 68.9/70."""
    from designer.result.evaluation import evaluate, fixed_design
    from designer.spec.reader import load_spec

    results = {}
    for material in ("6082-T6", "6061-T6"):
        spec = load_spec(_spec(tmp_path, material=material))
        ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
        results[material] = ev.analysis
    a, b = results["6082-T6"], results["6061-T6"]
    assert float(a.deflection) / float(b.deflection) == pytest.approx(68.9 / 70, rel=1e-9)
    assert float(a.gauge_strain[0]) / float(b.gauge_strain[0]) == pytest.approx(68.9 / 70, rel=1e-9)


def test_design_json_carries_the_catalogue_and_is_read_again_without_the_file(tmp_path):
    """The record's spec holds the user catalogue itself: the design is rebuilt after the file is
    gone and with the shipped catalogue alone in force."""
    from designer.result.designfile import parse_design
    from designer.result.evaluation import evaluate, fixed_design
    from designer.result.record import build_record
    from designer.spec import catalogue
    from designer.spec.reader import load_spec

    spec = load_spec(_spec(tmp_path))
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    record = json.loads(json.dumps(build_record("feasible", spec, ev)))
    assert record["spec"]["catalogue"][0]["file"] == "shop.yaml"
    (tmp_path / "shop.yaml").unlink()
    catalogue.use(())
    again = parse_design(record)
    assert again.design.material.name == "6082-T6" and again.design.material.E == pytest.approx(70e9)
    assert again.spec.gauge.factor == 2.1


def test_a_spec_without_a_catalogue_puts_the_shipped_one_back(tmp_path, examples):
    """The user's entries are in force for the spec that names them, not for the next one."""
    from designer.spec.reader import load_spec

    with_user = load_spec(_spec(tmp_path, rest="search: {materials: all}"))
    assert "6082-T6" in with_user.search.materials
    plain = load_spec(examples / "gripper-finger.yaml")
    assert "6082-T6" not in plain.search.materials


STOCK_ROUND = ("search: {materials: [6082-T6], sections: [round], stock: metric}\n"
               "targets: {force_error: 1 %, position_error: 1 mm}")


def _half_mm_margins(path: Path) -> Path:
    height = "  height: [3 mm, 16 mm]\n"
    path.write_text(path.read_text().replace(height, height + "  pocket_margin: 0.5 mm\n"))
    return path


def test_a_user_stock_table_gives_the_section(tmp_path):
    """With ``stock: metric`` the user's 6082-T6 is cut from its own table's round bar: the
    reported diameter is one of the table's rows (8, 10, 12, 16, 20 mm). (Pocket margins of 0.5 mm:
    with the default 1 mm, KFGS-2's 6.4 mm backing makes a pocket 4.2 of its 2 mm grids long, more
    than a slot may be, the next test.)"""
    from designer.search import optimize
    from designer.spec.reader import load_spec

    spec = load_spec(_half_mm_margins(_spec(tmp_path, rest=STOCK_ROUND)))
    found = optimize(spec)
    best = found.best
    assert best is not None and best.feasible
    assert best.design.stock.table == "shop-6082-round"
    assert round(best.design.geometry.diameter * 1e3, 6) in (8, 10, 12, 16, 20)


def test_a_gauge_whose_backing_makes_long_pockets_is_told_the_margin_that_fits(tmp_path):
    """KFGS-2-120 (2 mm grid, 6.4 mm backing) with the default 1 mm pocket margins: every pocket is
    8.4 mm = 4.2 grid lengths, beyond the 4 a slot may be (docs/model.md §7). On rectangles alone no
    design; the message names the margin that fits: (4 x 2 - 6.4) / 2 = 0.8 mm. A round bar's
    flat may be 6 grid lengths long, so on the round stock bars the same gauge has a design."""
    from designer.search import optimize
    from designer.spec.reader import load_spec

    slots = ("search: {materials: [6082-T6], sections: [rectangle]}\n"
             "targets: {force_error: 1 %, position_error: 1 mm}")
    found = optimize(load_spec(_spec(tmp_path, rest=slots)))
    assert not found.success
    said = next(m for m in found.messages if m.startswith("domain_lp_grid_max:"))
    assert "4.2 gauge grids long" in said and "a pocket_margin of at most 0.8 mm" in said
    on_round = optimize(load_spec(_spec(tmp_path, rest=STOCK_ROUND))).best
    assert on_round.feasible
    g = on_round.design.geometry
    assert g.pocket_length / g.grid_length == pytest.approx(4.2)


BAD = {
    # id: (change to the user catalogue, words the message must contain)
    "wrong unit": (lambda t: t.replace("E: 70 GPa", "E: 70 kg"), ["shop.yaml", "materials[0]", "6082-T6", ".E", "70 kg"]),
    "missing field": (lambda t: t.replace("    density: 2700 kg/m^3\n", ""), ["shop.yaml", "6082-T6", "density", "missing"]),
    "no source": (lambda t: t.replace('    source: "Kyowa KFGS datasheet"\n', ""), ["shop.yaml", "KFGS-2-120", "source"]),
    "shipped name": (lambda t: t.replace("- name: 6082-T6", "- name: 6061-T6"), ["shop.yaml", "6061-T6", "already in materials.yaml"]),
    "unknown key": (lambda t: t.replace("    factor: 2.1", "    factor: 2.1\n    colour: red"), ["shop.yaml", "KFGS-2-120", "colour", "unknown key"]),
    "twice in the file": (lambda t: t.replace("gauges:\n", "gauges:\n  - {name: KFGS-2-120, factor: 2.1, resistance: 120 ohm, "
                                              "grid_length: 2 mm, grid_width: 1.6 mm, length: 6.4 mm, width: 3 mm, "
                                              "max_strain: 1500 ue, source: x}\n"), ["shop.yaml", "gauges[1]", "KFGS-2-120", "already in shop.yaml"]),
    "shipped table name": (lambda t: t.replace("name: shop-6082-round", "name: al-round-metric"), ["shop.yaml", "al-round-metric", "used twice"]),
    "unknown family": (lambda t: t.replace("family: shop-aluminium", "family: nope"), ["shop.yaml", "family", "nope"]),
    "not a mapping": (lambda t: "- 1\n- 2\n", ["shop.yaml", "mapping"]),
    # a metal yields and tires below its breaking stress; a gauge's grid lies on its backing
    "yield above ultimate": (lambda t: t.replace("yield: 260 MPa", "yield: 400 MPa"),
                             ["shop.yaml", "6082-T6", ".yield", "400 MPa", "ultimate"]),
    "fatigue above ultimate": (lambda t: t.replace("fatigue: 90 MPa", "fatigue: 350 MPa"),
                               ["shop.yaml", "6082-T6", ".fatigue", "350 MPa", "ultimate"]),
    "grid longer than the backing": (lambda t: t.replace("grid_length: 2 mm", "grid_length: 20 mm"),
                                     ["shop.yaml", "KFGS-2-120", ".grid_length", "20 mm", "6.4 mm"]),
    "end mill radius too large": (lambda t: t.replace("8.5: [0.2, 0.5]", "8.5: [0.2, 4.5]"),
                                  ["shop.yaml", "shop-mills", "tools.8.5[1]", "4.5 mm", "not less than"]),
    "end mill unit": (lambda t: t.replace("    unit: mm\n    source: \"our tool crib", "    unit: cm\n    source: \"our tool crib"),
                      ["shop.yaml", "shop-mills", ".unit", "'cm'", "mm"]),
    "end mill table twice": (lambda t: t.replace("name: shop-mills", "name: carbide-corner-radius-metric"),
                             ["shop.yaml", "carbide-corner-radius-metric", "used twice"]),
    "end mill missing source": (lambda t: t.replace('    source: "our tool crib, 2026"\n', ""),
                                ["shop.yaml", "shop-mills", "source", "missing"]),
    # Figures no material, gauge or tool has: a slip of a unit or a digit. A modulus of 1 Pa was
    # designed with (the elastica then ran for hours), a gauge factor of 1e10 gave a "feasible"
    # sensor with a force error of 1e-10 %, an R0.005 end mill a design.json no command read back.
    "modulus of a jelly": (lambda t: t.replace("E: 70 GPa", "E: 1 Pa"), ["shop.yaml", "6082-T6", ".E", "1 Pa",
                                                                        "between 1e+08 and 1.5e+12 Pa"]),
    "density of a gas": (lambda t: t.replace("density: 2700 kg/m^3", "density: 1 kg/m^3"),
                         ["6082-T6", ".density", "between 100 and 25000"]),
    "notch length of a beam": (lambda t: t.replace("notch_length: 0.51 mm", "notch_length: 100 m"),
                               ["6082-T6", ".notch_length", "between 0 and 0.01 m"]),
    "gauge factor 1e10": (lambda t: t.replace("factor: 2.1", "factor: 1.0e+10"), ["KFGS-2-120", ".factor",
                                                                               "between 0.5 and 500"]),
    "gauge of a nanometre": (lambda t: t.replace("grid_length: 2 mm", "grid_length: 1 nm"),
                             ["KFGS-2-120", ".grid_length", "between 5e-05 and 0.5 m"]),
    "end mill finer than the grid": (lambda t: t.replace("8.5: [0.2, 0.5]", "8.5: [0.2, 0.005]"),
                                     ["shop-mills", "tools.8.5[1]", "0.005 mm", "0.01 mm"]),
    # names are shown as they are: on one line, and '$' would be read as mathematics by the plots
    "name on two lines": (lambda t: t.replace("- name: 6082-T6", '- name: "60\\n82"'),
                          ["shop.yaml", "materials[0].name", "one line"]),
    "name with dollars": (lambda t: t.replace("- name: 6082-T6", "- name: '$\\foo$'"),
                          ["shop.yaml", "materials[0].name", "'$'"]),
    "material named all": (lambda t: t.replace("- name: 6082-T6", "- name: all"), ["shop.yaml", "(all).name",
                                                                                   "every material"]),
    "empty catalogue": (lambda t: "materials:\ngauges:\n", ["shop.yaml", "the catalogue is empty"]),
    "YAML syntax error": (lambda t: "materials: [\n  - name: x\n", ["shop.yaml", "YAML syntax error at line 2"]),
}


@pytest.mark.parametrize("key", BAD)
def test_a_bad_user_catalogue_exits_2_naming_file_entry_and_key(tmp_path, capsys, key):
    from designer.cli import main

    change, words = BAD[key]
    spec = _spec(tmp_path)
    (tmp_path / "shop.yaml").write_text(change(USER.read_text()))
    assert main(["evaluate", str(spec), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in err[0]
    for word in words:
        assert word in err[0], (word, err[0])
    assert not (tmp_path / "out" / "design.json").exists()


def test_a_missing_catalogue_file_and_a_bad_key_exit_2(tmp_path, capsys):
    from designer.cli import main

    spec = _spec(tmp_path, catalogue="catalogue: nowhere.yaml")
    assert main(["evaluate", str(spec), "-o", str(tmp_path / "out")]) == 2
    assert "nowhere.yaml: no such file" in capsys.readouterr().err
    spec = _spec(tmp_path, catalogue="catalogue: 5")
    assert main(["evaluate", str(spec), "-o", str(tmp_path / "out")]) == 2
    assert "catalogue: 5 must be the path of a catalogue file" in capsys.readouterr().err
    spec = _spec(tmp_path, catalogue="")
    assert main(["evaluate", str(spec), "-o", str(tmp_path / "out"), "--catalogue", str(tmp_path / "none.yaml")]) == 2
    assert "none.yaml: no such file" in capsys.readouterr().err


def test_the_command_line_catalogue_joins_the_spec_and_the_listing(tmp_path, capsys, monkeypatch):
    """``--catalogue FILE``: the spec needs no ``catalogue:`` key, and ``materials`` lists the
    user's entries beside the shipped ones."""
    from designer.cli import main

    spec = _spec(tmp_path, catalogue="")
    out = tmp_path / "out"
    assert main(["evaluate", str(spec), "-o", str(out), "--no-cad", "--no-plots",
                 "--catalogue", str(tmp_path / "shop.yaml")]) == 0
    record = json.loads((out / "design.json").read_text())
    assert record["design"]["material"] == "6082-T6"
    capsys.readouterr()
    assert main(["materials", "--json", "--catalogue", str(tmp_path / "shop.yaml")]) == 0
    listing = json.loads(capsys.readouterr().out)
    assert "6082-T6" in {m["name"] for m in listing["materials"]}
    assert "KFGS-2-120" in {g["name"] for g in listing["gauges"]}
    assert "shop-6082-round" in {t["name"] for t in listing["stock"]}


def test_a_user_material_without_a_stock_family_has_no_stock_and_says_so(tmp_path, capsys):
    from designer.cli import main

    spec = _spec(tmp_path, rest="search: {materials: [6082-T6], sections: [round], stock: metric}")
    text = (tmp_path / "shop.yaml").read_text()
    (tmp_path / "shop.yaml").write_text(text[:text.index("stock:")])
    assert main(["optimize", str(spec), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "6082-T6 is in no stock family" in err and "stock.families" in err


def test_a_user_end_mill_cuts_the_flats_it_fits(tmp_path):
    """A flat is cut across the bar by the largest end mill with the spec's corner radius (R0.2)
    no wider than the flat is long: BF350-3AA's 6.9 mm backing and 1 mm margins make the flats
    8.9 mm long, so the shop's Ø8.5 R0.2 mm beats the shipped Ø8 R0.2 mm (materials/tools.yaml),
    and design.json, the summary and the drawing name it."""
    from designer.outputs import report
    from designer.outputs.cad import resolve
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import load_spec

    rest = DESIGN.format(material="6082-T6").replace("feature: {kind: none}", "feature: {kind: pocket, depth: 1 mm}")
    record = evaluate_fixed(load_spec(_spec(tmp_path, gauge="BF350-3AA", rest=rest))).record
    assert record["design"]["feature"]["length"] == pytest.approx(8.9e-3)
    tool = record["design"]["feature"]["tool"]
    assert (tool["label"], tool["table"]) == ("end mill Ø8.5 R0.2 mm", "shop-mills")
    assert tool["diameter"] == pytest.approx(8.5e-3) and tool["corner_radius"] == pytest.approx(0.2e-3)
    rows = dict(report.summary_rows(record))
    assert rows["end mill"].startswith("Ø8.5 R0.2 mm (shop-mills), moved across the bar")
    # the CAD takes the recorded tool, without the user's file
    assert resolve(json.loads(json.dumps(record))).tool == "end mill Ø8.5 R0.2 mm"
    shipped = evaluate_fixed(load_spec(_spec(tmp_path, material="6061-T6", gauge="BF350-3AA", catalogue="",
                                             rest=rest.replace("6082-T6", "6061-T6")))).record
    assert shipped["design"]["feature"]["tool"]["label"] == "end mill Ø8 R0.2 mm"


def test_a_given_end_mill_cuts_the_flats(tmp_path):
    """cad.end_mill_diameter names the end mill of flats as of slots: a Ø6 mm R0.2 mm (a catalogue
    tool, materials/tools.yaml) instead of the largest no longer than the 8.9 mm flat."""
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import load_spec

    rest = (DESIGN.format(material="6061-T6").replace("feature: {kind: none}", "feature: {kind: pocket, depth: 1 mm}")
            + "cad: {end_mill_diameter: 6 mm}\n")
    record = evaluate_fixed(load_spec(_spec(tmp_path, material="6061-T6", gauge="BF350-3AA", catalogue="",
                                            rest=rest))).record
    tool = record["design"]["feature"]["tool"]
    assert (tool["label"], tool["table"]) == ("end mill Ø6 R0.2 mm", "carbide-corner-radius-metric")


def test_a_spec_with_a_catalogue_beside_it_is_benched_from_any_folder(tmp_path, capsys, monkeypatch):
    """``bench --specs FOLDER``: a spec's relative ``catalogue:`` is found in the spec's folder
    (docs/spec.md 2.9), not the working one, and the catalogue file beside the specs is not read
    as a spec (it stopped the bench: 'spec.materials: unknown key')."""
    from designer.cli import main

    folder = tmp_path / "specs"
    folder.mkdir()
    _spec(folder, rest="search: {materials: [6082-T6]}")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    assert main(["bench", "--specs", str(folder), "--count", "0", "--methods", "ipopt", "--levels", "2",
                 "-o", str(tmp_path / "bench"), "--quiet"]) == 0
    summary = (tmp_path / "bench" / "bench.md").read_text()
    assert "shop.yaml (a catalogue)" in summary
    assert "6082-T6" in (tmp_path / "bench" / "runs.csv").read_text()   # the design of the user's material


def test_an_empty_command_line_catalogue_is_named(tmp_path, capsys):
    from designer.cli import main

    assert main(["materials", "--catalogue", ""]) == 2
    assert capsys.readouterr().err.strip() == ("fpdesign: error: --catalogue: '' is empty; give a catalogue file "
                                               "(docs/spec.md 2.9)")
