"""Designs a shop can buy (issue 15): the stock catalogue (materials/stock.yaml), the spec key
``search.stock`` and the discrete section search (designer/search/stock.py).

References: the search against brute force (every row of a reduced table solved with its
section held, rounded and checked); the catalogue's sizes against the YAML file read on its own
and the inch's definition (25.4 mm exactly); ``stock: none`` against the exhaustive reference
search recorded in README.md.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

import pytest
import yaml

from designer.spec.tolerances import Tolerances
from designer import model
from designer.cli import main
from designer.outputs import report
from designer.outputs.plots.candidates import plot_candidates
from designer.result.record import search_record
from designer.result.evaluation import evaluate
from designer.search.problem import Family, FamilyProblem, start_from
from designer.search.run import optimize, solve_candidate
from designer.search.stock import brute_force, search_stock, stock_rows
from designer.spec import catalogue
from designer.spec import stock as stock_file
from designer.spec.reader import load_spec

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
STOCK_YAML = ROOT / "materials" / "stock.yaml"
INCH = Fraction(254, 10000)   # m, exactly (the international inch, 1959)
MILLIMETRE = Fraction(1, 1000)


def _metres(value, unit: str) -> float:
    """A size written in decimal in a table's unit, in metres: the double nearest the exact value."""
    return float(Fraction(str(value)) * {"mm": MILLIMETRE, "in": INCH}[unit])


def _raw():
    return yaml.safe_load(STOCK_YAML.read_text(encoding="utf-8"))


def _spec_text(name="gripper-finger", **search) -> str:
    """An example's spec.yaml with ``search`` keys added."""
    raw = yaml.safe_load((EXAMPLES / f"{name}.yaml").read_text())
    raw.setdefault("search", {}).update(search)
    return yaml.safe_dump(raw, allow_unicode=True)


def _spec(name="gripper-finger", **search):
    spec = load_spec(EXAMPLES / f"{name}.yaml")
    return replace(spec, search=replace(spec.search, **search))


# ----------------------------------------------------------------------------- the catalogue

def test_every_material_belongs_to_one_family_with_stock():
    table = catalogue.stock()
    for name in catalogue.materials():
        family = table.family_of(name)
        assert family is not None, name
        assert any(t.family == family and t.items for t in table.tables), name


def test_sizes_are_the_files_numbers_in_metres_and_inches_convert_exactly():
    """Each table's rows against the YAML file read on its own: mm x 1e-3, inches x 25.4 mm."""
    by_name = {t.name: t for t in catalogue.stock().tables}
    for entry in _raw()["tables"]:
        u, sizes = entry["unit"], entry["sizes"]
        expected = ({(_metres(v, u),) for v in sizes} if isinstance(sizes, list) else
                    {(_metres(a, u), _metres(b, u)) for a, bs in sizes.items() for b in bs})
        got = {item.sizes for item in by_name[entry["name"]].items}
        assert got == expected, entry["name"]
    three_eighths = next(i for i in by_name["al-round-imperial"].items if i.designation == "Ø3/8 in")
    assert three_eighths.sizes == (0.009525,)   # 3/8 x 25.4 mm


@pytest.mark.parametrize("inches, text", [(0.375, "3/8"), (1.25, "1 1/4"), (0.049, "0.049"), (2.0, "2")])
def test_imperial_sizes_read_as_a_supplier_writes_them(inches, text):
    assert stock_file._number(inches, "in") == text


def test_a_flat_bar_gives_both_orientations_and_a_biaxial_rectangle_needs_a_square_bar():
    flat = stock_file.StockItem("flat bar", (0.025, 0.006), "t", "metric", "mm", "EN 754-5")
    assert flat.sections("rectangle", 1) == [{"width": 0.025, "height": 0.006}, {"width": 0.006, "height": 0.025}]
    assert flat.sections("rectangle", 2) == [] and flat.sections("round", 1) == []
    square = stock_file.StockItem("square bar", (0.012,), "t", "metric", "mm", "EN 754-4")
    assert square.sections("rectangle", 2) == [{"side": 0.012}]
    assert flat.label == "flat bar 25 × 6 mm (EN 754-5)"


# ----------------------------------------------------------------------------- bad stock files

def _bad(raw, path: str, value):
    """``raw`` with the value at ``path`` ("tables[0].unit") replaced (removed when None)."""
    node = raw
    parts = path.replace("]", "").replace("[", ".").split(".")
    for p in parts[:-1]:
        node = node[int(p)] if p.isdigit() else node[p]
    last = int(parts[-1]) if parts[-1].isdigit() else parts[-1]
    if value is None:
        del node[last]
    else:
        node[last] = value
    return raw


def _tube_wall_too_thick(raw):
    raw["tables"][3]["sizes"][10] = [1, 5]   # al-tube-metric: a 10 mm tube with a 5 mm wall
    return raw


def _duplicate(raw):
    raw["tables"][1]["name"] = raw["tables"][0]["name"]
    return raw


BAD_FILES = [
    # what is changed, the words the one error line must hold (file, entry, key, value)
    ("missing source", lambda r: _bad(r, "tables[0].source", None), ("stock.yaml", "al-round-metric.source", "missing")),
    ("wrong unit", lambda r: _bad(r, "tables[0].unit", "N"), ("stock.yaml", "al-round-metric.unit", "'N'", "mm, in")),
    # a metric table's sizes in inches: 3 mm read as 3 in (76.2 mm)
    ("unit of the other system", lambda r: _bad(r, "tables[0].unit", "in"),
     ("stock.yaml", "al-round-metric.unit", "'in'", "metric", "must be mm")),
    ("duplicate name", _duplicate, ("stock.yaml", "tables[1].name", "al-round-metric", "twice")),
    ("non-positive size", lambda r: _bad(r, "tables[0].sizes[2]", -5), ("stock.yaml", "al-round-metric.sizes[2]", "-5",
                                                                        "positive")),
    ("size with a unit", lambda r: _bad(r, "tables[0].sizes[0]", "3 mm"), ("stock.yaml", "al-round-metric.sizes[0]",
                                                                           "'3 mm'", "number")),
    ("wall not below the radius", _tube_wall_too_thick, ("stock.yaml", "al-tube-metric.sizes.10[1]", "wall 5 mm",
                                                         "radius 5 mm")),
    ("unknown shape", lambda r: _bad(r, "tables[0].shape", "hexagon bar"), ("stock.yaml", "al-round-metric.shape",
                                                                            "hexagon bar")),
    ("material in no family", lambda r: _bad(r, "families.titanium.materials", ["7075-T6"]),
     ("stock.yaml", "families.titanium.materials", "7075-T6", "already")),
]


@pytest.mark.parametrize("what, change, words", BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_a_bad_stock_file_exits_2_naming_the_file_entry_and_key(what, change, words, tmp_path, monkeypatch, capsys):
    data = tmp_path / "materials"
    shutil.copytree(ROOT / "materials", data)
    (data / "stock.yaml").write_text(yaml.safe_dump(change(_raw()), allow_unicode=True), encoding="utf-8")
    monkeypatch.setattr(catalogue, "data_folder", lambda: data)
    catalogue.stock.cache_clear()
    catalogue.materials.cache_clear()
    spec = tmp_path / "spec.yaml"
    spec.write_text(_spec_text(stock="metric"))
    out = tmp_path / "out"
    try:
        code = main(["optimize", str(spec), "-o", str(out), "--no-cad", "--no-plots", "--quiet"])
    finally:
        catalogue.stock.cache_clear()
        catalogue.materials.cache_clear()
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    for word in words:
        assert word in err, (word, err)
    assert not out.exists()


# ----------------------------------------------------------------------------- the search

def _reduced(monkeypatch, tables):
    """The catalogue with only ``tables`` (name -> sizes) of aluminium, read by the same parser."""
    raw = _raw()
    raw["tables"] = [dict(t, sizes=tables[t["name"]]) for t in raw["tables"] if t["name"] in tables]
    raw["families"] = {"aluminium": raw["families"]["aluminium"],
                       "rest": {"description": "x", "materials": [m for m in catalogue.materials()
                                                                  if m not in raw["families"]["aluminium"]["materials"]]}}
    raw["tables"].append(dict(raw["tables"][0], name="rest-round", family="rest", shape="round bar", sizes=[10]))
    table = stock_file.parse(raw, tuple(catalogue.materials()))
    monkeypatch.setattr(catalogue, "stock", lambda: table)
    return table


REDUCED = {
    "al-round-metric": [5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16],
    "al-flat-metric": {10: [3, 4, 5, 6, 8], 12: [4, 5, 6, 8, 10], 15: [5, 6, 8], 16: [4, 6, 8]},
    "al-tube-metric": {8: [1, 1.5, 2], 10: [1, 1.5, 2, 2.5, 3], 12: [1, 2, 3], 14: [2, 3], 16: [1.5, 2, 3, 4]},
}


@pytest.mark.parametrize("section", ["rectangle", "round", "tube"])
def test_stock_search_equals_brute_force_on_reduced_tables(section, monkeypatch):
    """Reference: every row of the reduced table solved with its section held, rounded and
    checked; the best that meets every limit. The branch and bound must match it within the
    0.1 % tie band, on a row of the table."""
    _reduced(monkeypatch, REDUCED)
    # a flat is studied only on a tube no thicker than the flat is long (designer/checks/fits.py
    # FIT_DOMAINS), which the gripper's flat leaves no stock tube: its tubes are plain here
    spec = _spec(stock="metric", **({"feature": "none"} if section == "tube" else {}))
    problem = FamilyProblem(spec, Family(section, spec.search.feature))
    material = catalogue.material("7075-T6")
    continuous = solve_candidate(problem, material, "ipopt").evaluation
    x0 = start_from(problem, continuous)
    found = search_stock(problem, material, x0)
    every = [ev for _, ev in brute_force(problem, material, x0) if ev is not None and ev.feasible]
    assert every and found.evaluation is not None and found.evaluation.feasible
    best = min(ev.objective for ev in every)
    assert found.evaluation.objective == pytest.approx(best, rel=model.TIE_TOLERANCE)
    rows, _ = stock_rows(problem, material)
    assert found.evaluation.design.stock in {item for item, _, _ in rows}
    assert found.solved < len(rows)   # the bound spared some rows
    # the continuous optimum bounds every row from below (up to the 0.01 mm rounding of the rest)
    assert continuous.objective <= best * (1 + model.TIE_TOLERANCE)


def test_every_reported_section_is_a_row_of_the_table():
    """The optimiser's chosen design and every candidate on stock: sizes exactly a row of
    stock.yaml (read here on its own), in metres."""
    spec = _spec(stock="any", materials=("7075-T6", "Ti-6Al-4V", "301-full-hard"))
    found = optimize(spec)
    rows = set()
    for entry in _raw()["tables"]:
        u, sizes = entry["unit"], entry["sizes"]
        rows |= ({(_metres(v, u),) for v in sizes} if isinstance(sizes, list) else
                 {(_metres(a, u), _metres(b, u)) for a, bs in sizes.items() for b in bs})
    on_stock = [c.evaluation for c in found.candidates if c.evaluation is not None]
    assert found.x.stock is not None and on_stock
    for ev in on_stock:
        g = ev.design.geometry
        sizes = {"round": (g.diameter,), "tube": (g.diameter, g.wall)}.get(g.section)
        if sizes is None:
            sizes = (g.width,) if g.width == g.height else (max(g.width, g.height), min(g.width, g.height))
        assert sizes in rows, (ev.design.label(), sizes)
        assert sizes == ev.design.stock.sizes or sizes == ev.design.stock.sizes[::-1] or g.width == g.height
    # no stock of titanium tube, nor of round or tube spring strip: those families say so
    notes = {(c.material, c.family.section): c for c in found.candidates}
    assert notes[("Ti-6Al-4V", "tube")].status == "infeasible"
    assert "no metric and imperial stock round tube of Ti-6Al-4V" in notes[("Ti-6Al-4V", "tube")].stock_note
    assert notes[("301-full-hard", "round")].evaluation is None


def test_stock_none_keeps_bars_continuous_and_never_reads_the_catalogue(monkeypatch):
    """``stock: none`` (the default) without tubes is the continuous search: the stock catalogue
    is not read, no design carries a stock item, and the gripper finger's objective is no worse,
    within the 0.1 % tie band, than the exhaustive reference search's at nominal sizes
    (designer/search/reference.py with tolerances none: 0.344142)."""
    def refuse():
        raise AssertionError("search.stock: none read the stock catalogue")

    monkeypatch.setattr(catalogue, "stock", refuse)
    spec = replace(_spec(sections=("rectangle", "round")), tolerances=Tolerances("none"))
    assert spec.search.stock == "none"
    found = optimize(spec)
    assert found.x.stock is None and found.get("continuous") is None
    assert found.best.objective <= 0.344142 * (1 + model.TIE_TOLERANCE)
    assert all("stock" not in c.record() for c in found.candidates)


def test_with_stock_none_a_tube_is_still_a_row_of_the_tube_tables(monkeypatch):
    """No bore is drilled through a beam: with ``stock: none`` the tube family's sections are
    rows of the tube tables (metric and imperial) while bars stay continuous. Reference: every
    row of the reduced tube table solved with its section held (brute force); the search's tube
    matches the best within the 0.1 % tie band, and is the row ``stock: any`` chooses."""
    _reduced(monkeypatch, REDUCED)
    spec = _spec(materials=("7075-T6",), sections=("tube",), feature="none")   # plain tubes, as above
    assert spec.search.stock == "none"
    found = optimize(spec)
    problem = FamilyProblem(spec, Family("tube", "none"))
    material = catalogue.material("7075-T6")
    every = [ev for _, ev in brute_force(problem, material, start_from(problem, found.candidates[0].continuous))
             if ev is not None and ev.feasible]
    assert found.success and found.x.stock is not None and found.x.stock.shape == "round tube"
    assert (found.x.geometry.diameter, found.x.geometry.wall) == found.x.stock.sizes
    assert found.x.stock.sizes in {(_metres(d, "mm"), _metres(t, "mm"))
                                   for d, ts in REDUCED["al-tube-metric"].items() for t in ts}
    assert found.best.objective == pytest.approx(min(ev.objective for ev in every), rel=model.TIE_TOLERANCE)
    assert found.get("continuous") is None   # not a search on stock: no "stock costs" line
    assert optimize(_spec(materials=("7075-T6",), sections=("tube",), feature="none",
                          stock="any")).x.stock == found.x.stock


def test_no_reported_design_or_candidate_has_a_bore_without_tube_stock():
    """The gripper finger with every section and the default ``stock: none``: rectangles and round
    bars continuous, every tube (chosen or not) a stock item of its material, and the titanium tube,
    of which there is no stock, infeasible saying so."""
    spec = _spec()
    found = optimize(spec)
    assert found.x.stock is None or found.x.stock.shape == "round tube"
    tubes = [c for c in found.candidates if c.family.section == "tube"]
    assert tubes
    for c in found.candidates:
        ev = c.evaluation
        if ev is not None and c.family.section == "tube":
            assert ev.design.stock is not None and ev.design.stock.shape == "round tube", c.material
            assert (ev.design.geometry.diameter, ev.design.geometry.wall) == ev.design.stock.sizes
        elif ev is not None:
            assert ev.design.stock is None, (c.material, c.family.label)
    ti = next(c for c in tubes if c.material == "Ti-6Al-4V")
    assert ti.evaluation is None and "no metric and imperial stock round tube of Ti-6Al-4V" in ti.stock_note
    record = search_record(spec, found)
    text = report.markdown(record)  # the report says why, below its candidate table
    assert "- Ti-6Al-4V tube: no metric and imperial stock round tube of Ti-6Al-4V" in text
    # A material of which the stock catalogue (materials/stock.yaml) has no tube, titanium,
    # copper-beryllium (tube only to order) and the stainless strip tempers, has no tube design
    # and says so, also when its answer before rounding ranked far below the best (the
    # copper-beryllium and strip tubes had been listed as outranked at that answer, as if such a
    # tube could be bought).
    no_tube = {"Ti-6Al-4V", "C17200", "301-full-hard", "17-7PH-RH950"}
    assert {c.material for c in tubes} >= no_tube
    for c in tubes:
        if c.material in no_tube:
            assert c.status == "infeasible" and "stock round tube of" in c.stock_note, c.material
    # the candidates chart: those tubes have no stock size; an outranked tube shows its answer
    # before rounding, which is no bound on its stock designs (no "≥")
    texts = [t.get_text() for t in plot_candidates(record).axes[0].texts]
    assert texts.count("no stock size (report.md says why)") == len(no_tube)
    answers = [c.continuous.objective for c in tubes if c.outranked]
    assert answers and all(any(f"{b:.4g} before rounding: outranked" in t for t in texts) for b in answers)
    assert not any("≥" in t for t in texts)


def test_an_infeasible_stock_choice_is_bad_input(tmp_path, capsys):
    """A spec whose limits leave no stock size at all: exit 2, one line naming search.stock."""
    path = tmp_path / "spec.yaml"
    path.write_text(_spec_text(stock="imperial", materials=["Ti-6Al-4V"], sections=["tube"]))
    code = main(["optimize", str(path), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1
    assert "search.stock: 'imperial'" in err and "Ti-6Al-4V" in err and not (tmp_path / "out").exists()


def test_optimize_on_stock_names_the_item_and_the_continuous_optimum(tmp_path, capsys):
    """End to end: examples/weigh-bar.yaml with ``search: {stock: metric}``: the terminal summary,
    report.md and design.json name the stock item and its standard, and give the continuous
    optimum and what stock costs; design.json reads back (``simulate``)."""
    path = tmp_path / "weigh-bar.yaml"
    path.write_text(_spec_text("weigh-bar", stock="metric"))
    out = tmp_path / "out"
    code = main(["optimize", str(path), "-o", str(out), "--no-cad", "--no-plots"])
    text = capsys.readouterr().out
    assert code == 0
    record = json.loads((out / "design.json").read_text())
    item = record["design"]["stock"]
    assert item["system"] == "metric" and item["label"].split(" (")[0] in " ".join(text.split())
    assert item["standard"] in (out / "report.md").read_text()
    assert "stock costs" in (out / "report.md").read_text() and "continuous optimum" in text
    stock = record["stock"]
    # the continuous optimum bounds the stock design from below (the tie band covers rounding)
    assert stock["cost"] >= -model.TIE_TOLERANCE
    assert record["predicted"]["objective"] == pytest.approx(stock["continuous"]["objective"] * (1 + stock["cost"]))
    section = record["design"]["section"]
    mm = [round(v * 1e3, 9) for k, v in section.items() if k != "kind"]
    assert sorted(mm) == sorted(round(v * 1e3, 9) for v in item["sizes"])
    assert main(["simulate", str(out / "design.json"), "--draws", "200"]) == 0


def test_rows_a_relaxation_finds_infeasible_are_infeasible_one_by_one():
    """The probe on imperial stock: 2024-T3 tube is dropped whole, its relaxation (the sizes
    free between the table's) being infeasible. Reference: brute force, every row of its table
    solved on its own with its sizes held, rounded and checked: none meets every limit."""
    spec = _spec("probe", stock="imperial")
    found = optimize(spec)
    cand = next(c for c in found.candidates if c.material == "2024-T3" and c.family.section == "tube")
    assert cand.status == "infeasible" and "IPOPT finds no design" in cand.stock_note
    problem = FamilyProblem(spec, Family("tube", spec.search.feature))
    material = catalogue.material("2024-T3")
    x0 = start_from(problem, cand.continuous)
    every = brute_force(problem, material, x0)
    assert len(every) > 10
    assert not any(ev is not None and ev.feasible for _, ev in every)


def test_with_no_feasible_stock_design_the_least_infeasible_row_is_reported(monkeypatch):
    """When no row of any family meets every limit, the search runs again without dropping the
    rows relaxations found infeasible, so that the least-infeasible stock design is reported
    (as the search did before it dropped any). Here every search.stock design is made infeasible
    by a deflection limit no bar meets."""
    base = _spec(stock="metric", materials=("7075-T6",))
    spec = replace(base, limits=replace(base.limits, max_deflection=1e-7))
    found = optimize(spec)
    assert not found.success
    assert found.x.stock is not None and found.best is not None
    assert not any("IPOPT finds no design" in c.stock_note for c in found.candidates if c.evaluation is not None)


def _least_infeasible_searches(monkeypatch, spec) -> tuple:
    """``optimize(spec)``, and the arguments and outcome of each stock search it made for a least
    infeasible row (``closest``)."""
    from designer.search import stocked

    made, search = [], stocked.search_stock

    def recorded(*args, **kwargs):
        out = search(*args, **kwargs)
        if kwargs.get("closest"):
            made.append((args, kwargs["rows"], out))
        return out
    monkeypatch.setattr(stocked, "search_stock", recorded)
    return optimize(spec), made


def test_the_least_infeasible_row_is_searched_by_branch_and_bound(monkeypatch):
    """With no stock row meeting every limit, the closest stock design is its least violation's
    row, searched by branch and bound over boxes of rows (``stock.least_infeasible``), where every
    row was once solved. Reference: every row solved on its own for its least violation (the
    brute force). The bench suite's 002-kilonewton (seed 0): of 168 stock tubes of 7075-T6 none
    meets every limit; the search finds the brute force's closest row (every rule of the
    geometry kept, the same worst violation) and solves under a tenth of the rows."""
    from designer.bench.suite import _generate
    from designer.search.stock import _farness, least_infeasible

    made = _generate(1, "kilonewton", 0)
    assert made.name == "002-kilonewton"
    found, searches = _least_infeasible_searches(monkeypatch, made.spec)
    assert found.status == "infeasible" and len(searches) == 1
    (problem, material, x0), rows, out = searches[0]
    assert len(rows) == 168 and out.solved < len(rows) / 10
    every = [least_infeasible(problem, material, x0, [row]).evaluation for row in rows]
    closest = min((ev for ev in every if ev is not None), key=_farness)
    assert _farness(closest)[:2] == (False, 0)
    assert _farness(out.evaluation) == pytest.approx(_farness(closest), rel=1e-9)


def test_the_least_infeasible_stock_design_keeps_the_geometry_s_rules(monkeypatch):
    """The closest stock design is a row's least violation with the geometry's own rules held
    (``closest.closeness``: rules broken rank before any violation of the duty). The bench
    suite's seed 14 013-kilonewton (tubes of 2024-T3 and 6061-T6, none meets every limit): solving
    each row for the limits from the continuous answer, as the search once did, left the closest
    tube breaking the gap between its stations and three of the feature corrections' domain
    rules; now it breaks none, and fewer than a tenth of each tube's 158 rows are solved."""
    from designer.bench.suite import _generate
    from designer.search.rounding import broken_rules

    made = _generate(12, "kilonewton", 14)
    assert made.name == "013-kilonewton"
    found, searches = _least_infeasible_searches(monkeypatch, made.spec)
    assert found.status == "infeasible" and found.best.design.stock is not None
    assert not broken_rules(found.best)
    assert len(searches) == 2 and all(out.solved < len(rows) / 10 for _, rows, out in searches)


def test_evaluate_warns_of_a_fixed_tube_that_is_no_stock_size():
    """The paper's prototype C, a 6061-T6 tube 12.7 x 1.65 mm, is 1/2 x 0.065 in drawn tube
    (ASTM B210, in the imperial tube table to 0.01 mm): no warning. With a 2.2 mm wall it is no
    stock size, and evaluate says its 8.3 mm bore (12.7 - 2 x 2.2) would be drilled the beam's
    length."""
    from designer.result.pipeline import evaluate_fixed

    spec = load_spec(EXAMPLES / "prototype-c.yaml")
    assert not any("stock size" in m for m in evaluate_fixed(spec).record["messages"])
    thick = replace(spec, design=replace(spec.design, section=replace(spec.design.section, wall=0.0022)))
    found = [m for m in evaluate_fixed(thick).record["messages"] if "stock size" in m]
    assert len(found) == 1 and "design.section" in found[0] and "Ø8.30 mm bore" in found[0]
    assert f"drilled {spec.free_length * 1e3:.0f} mm deep" in found[0]


# The bench suite's 002-kilonewton (``bench.generate_suite(54, 0)``): tubes only, whose best
# continuous design meets every limit while no stock tube does.
TUBES_ONLY = """name: 002-kilonewton
load: {force: [192.1 N, 2.546 kN], position: [239.3 mm, 403.8 mm]}
electronics: {excitation: 3.3 V, gain: 1000.0, noise: 0.2656 mV}
gauge: CEA-06-125UW-120
bridge: quarter
stations: 2
limits: {width: [9.003 mm, 152.5 mm], height: [9.003 mm, 116.5 mm], min_wall: 1 mm, max_deflection: 8.077 mm}
targets: {force_error: 2.27 %, position_error: 13 mm}
search: {materials: [7075-T6, C17200, 301-full-hard], sections: [tube], feature: none}
objective: deflection
"""


def test_a_tube_s_continuous_design_outranks_nothing_as_its_rows_may_all_fail():
    """A continuous tube is searched on its stock rows afterwards, so it sets no bound under
    which other candidates go unrepaired (``optimize``'s outranking before rounding): here no
    stock tube meets every limit, and the least infeasible row is reported, as the search that
    repairs every candidate reports it (it once found no design to report at all)."""
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(TUBES_ONLY)
    found = optimize(spec)
    assert not found.success and found.x.stock is not None and found.x.stock.shape == "round tube"
    assert not any(c.unrounded for c in found.candidates)
    full = optimize(spec, outrank=False)
    assert found.x.stock == full.x.stock and found.best.objective == full.best.objective


def test_the_continuous_optimum_beside_a_stock_design_is_the_continuous_search_s():
    """On stock the families' continuous answers are only the rows' starts and bounds, kept
    before rounding where rounding breaks a limit or costs more than the tie band; the one
    reported beside the stock design ("stock costs x %") is rounded and repaired afterwards.
    Reference: the gripper finger searched with continuous sizes (``stock: none``; its best, a
    titanium round bar, has no tube to compete with on either search), whose design is rounded and
    repaired as every answer is: the reported continuous optimum is a design on the 0.01 mm grid
    (its depth on the 0.05 mm one), meets every limit, and ranks with it within the tie band."""
    spec = _spec("gripper-finger", stock="metric")
    found = optimize(spec)
    plain = optimize(_spec("gripper-finger", stock="none")).best
    c = found.get("continuous")
    assert c is not None and c.feasible and c.design.stock is None
    # the titanium tube has a continuous answer (within 0.2 % of the bar's in error), but titanium
    # tube is not stocked and no bore is drilled (``stock.always_stocked``): it is no design to
    # compare with
    tube = next(x for x in found.candidates if (x.material, x.family.section) == ("Ti-6Al-4V", "tube"))
    assert tube.continuous is not None and tube.continuous.objective < c.objective * 1.002
    assert (c.design.material.name, c.design.geometry.section) == ("Ti-6Al-4V", "round")
    g = c.design.geometry
    for size in (g.width, g.height, g.diameter, g.wall, *g.stations):
        if size is not None:
            assert size / 1e-5 == pytest.approx(round(size / 1e-5), abs=1e-6)
    assert g.depth / 5e-5 == pytest.approx(round(g.depth / 5e-5), abs=1e-6)
    assert evaluate(c.design, spec).feasible
    assert c.objective == pytest.approx(plain.objective, rel=model.TIE_TOLERANCE)
