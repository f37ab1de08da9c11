"""Plots: the numbers behind them, the files they make and the ``plot`` command.

Fixtures (tests/data):
- ``plot_prototype_b.json``: ``fpdesign evaluate examples/prototype-b.yaml``: the paper's
  Prototype B (Noh et al. 2025, Table 1): 2024-T3 12.7 x 12.7 mm bar, 9.5 mm through-holes,
  half bridges at 20 and 100 mm, 200-2000 g at 150-450 mm, sigma_V = 1.3 mV (paper section 4.3).
  The paper gives neither excitation nor gain; 5 V and a gain of 1000 are assumed: with the
  paper's 1.3 mV noise this gives k = 0.345 V/(N m), about 3 % force and position error at 200 g
  and below 1 % above 1000 g, the magnitudes of the paper's Figs. 14 and 16-17 (checked below).
- ``plot_prototype_c.json``: ``fpdesign evaluate examples/prototype-c.yaml``: Prototype C,
  6061-T6 tube 12.7 x 1.65 mm, bridges at 20 and 70 mm, two axes, 250-2000 g at 100-200 mm.
- ``plot_optimized.json``: ``fpdesign optimize`` of Prototype B's load case (no design block):
  a real candidate list of 9 materials x 3 section families.
- ``plot_tradeoff.json``: the candidates of the same search rerun with limits.max_deflection of
  1-12 mm and limits.min_frequency of 20-100 Hz, as trade-off points.
"""

from __future__ import annotations

import copy
import json
from dataclasses import replace
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from designer.outputs import plots
from designer.outputs.plots import candidates, common
from designer.outputs.plots import write as plot_write
from designer.result.designfile import load_design
from designer.errors import DesignFileError, InputError
from shared_inputs import check_plot_files

DATA = Path(__file__).resolve().parents[1] / "data"
G0 = 9.80665  # standard gravity, m/s^2 (the paper's loads are masses)


@pytest.fixture(scope="module")
def optimized() -> dict:
    return load_design(DATA / "plot_optimized.json")


@pytest.fixture(scope="module")
def tradeoff() -> dict:
    return json.loads((DATA / "plot_tradeoff.json").read_text())


def test_stress_governs_when_the_allowable_is_low(proto_b):
    design = copy.deepcopy(proto_b)
    design["predicted"]["stress_allowable"] = 30e6  # below the 43 MPa at the hole edge
    region = plots.operating_region(design)
    assert region.governing.name == "stress_feature"
    ratio = 30e6 / design["predicted"]["stress_feature"]
    assert region.force_max_allowed == pytest.approx(region.force_max * ratio, rel=1e-12)
    assert region.force_max_allowed < region.force_max  # the load range no longer fits
    fig = plots.plot_operating_region(design)
    assert "does NOT fit" in " ".join(t.get_text() for t in fig.axes[0].texts)


def test_stress_limit_from_max_stress_alone(proto_b):
    """A record with only predicted.max_stress: the stress isoline is the root moment scaled by
    stress_allowable / max_stress, exact at x_max and conservative nearer the clamp."""
    design = copy.deepcopy(proto_b)
    for key in ("stress_root", "stress_feature"):
        del design["predicted"][key]
    limits = {lim.name: lim for lim in plots.operating_region(design).upper}
    assert set(limits) == {"gauge_strain", "stress_root"}
    pred, (f_max, x_max) = design["predicted"], (2.0 * G0, 0.45)
    assert limits["stress_root"].force(x_max) == pytest.approx(
        f_max * pred["stress_allowable"] / pred["max_stress"], rel=1e-12)
    exact = plots.operating_region(proto_b).upper[2]   # the hole-edge limit it stands in for
    assert exact.name == "stress_feature"
    assert np.all(limits["stress_root"].force(np.array([0.15, 0.3])) < exact.force(np.array([0.15, 0.3])))


def test_noise_and_biaxial_sensitivity_fallbacks(proto_b, proto_c):
    design = copy.deepcopy(proto_b)
    del design["predicted"]["noise_voltage"]            # read from spec.electronics instead
    assert plots.SensorData.from_design(design).noise == pytest.approx(1.3e-3)
    biaxial = copy.deepcopy(proto_c)
    k = biaxial["predicted"]["sensitivity"]
    biaxial["predicted"]["sensitivity"] = k + k          # one k_i per station and axis
    assert plots.SensorData.from_design(biaxial).sensitivity == tuple(k)
    biaxial["design"]["axes"] = 3
    with pytest.raises(DesignFileError, match=r"design.axes: 3 is not allowed"):
        plots.SensorData.from_design(biaxial)


def test_operating_region_plot_draws_the_computed_isolines(proto_b):
    fig = plots.plot_operating_region(proto_b)
    ax = fig.axes[0]
    region = plots.operating_region(proto_b)
    lines = {line.get_label().split(":")[0]: line for line in ax.get_lines()}
    for lim in list(region.upper) + [region.lower]:
        line = lines[lim.label]
        x_mm, force = line.get_data()
        np.testing.assert_allclose(force, lim.moment / (np.asarray(x_mm) / 1e3 - lim.pivot), rtol=1e-9)
    assert ax.get_yscale() == "log"
    assert "(mm)" in ax.get_xlabel() and "(N)" in ax.get_ylabel()
    text = " ".join(t.get_text() for t in ax.texts)
    assert "R_F = 134" in text and "eq. 21" in text
    assert {"d1", "d2"} <= {t.get_text() for t in ax.texts}


def test_operating_region_with_three_stations(proto_b):
    """Prototype B with all three bridges (20, 60, 100 mm): the strain limit is about d_1,
    the smallest signal about d_N = 100 mm."""
    design = copy.deepcopy(proto_b)
    k = design["predicted"]["sensitivity"][0]
    design["design"]["stations"] = [0.02, 0.06, 0.10]
    design["predicted"]["sensitivity"] = [k, k, k]
    region = plots.operating_region(design)
    assert region.lower.pivot == 0.10
    assert region.governing.pivot == 0.02
    m = plots.error_map(design, force=[2.0], position=[0.3])
    # By hand (MODEL.md section 3): with rows (k, -k d_i) for z = (F x, F) and equal k,
    # (A^T A)^-1 gives sigma_F = sigma_V/(k sqrt(sum (d_i - mean d)^2)): 0.04 sqrt(2) m here,
    # the middle bridge sitting at the mean (the relative force error at 2 N is sigma_F/2 N).
    d = np.array([0.02, 0.06, 0.10])
    assert m.force_error[0, 0] == pytest.approx(1.3e-3 / (k * math.sqrt(np.sum((d - d.mean()) ** 2))) / 2.0,
                                                rel=1e-12)


def test_worst_errors_equal_the_designs_prediction(proto_b, proto_c):
    """The map's worst corner equals what evaluate wrote to design.json (predicted.*_error)."""
    for design in (proto_b, proto_c):
        force_error, position_error = plots.worst_errors(design)
        assert force_error == pytest.approx(design["predicted"]["force_error"], rel=1e-9)
        assert position_error == pytest.approx(design["predicted"]["position_error"], rel=1e-9)


def test_error_map_plot_marks_the_worst_case_and_targets(proto_b):
    from matplotlib.figure import Figure

    given = Figure()
    fig = plots.plot_error_maps(proto_b, fig=given)
    assert fig is given
    maps = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"][:3]
    force_error, position_error = plots.worst_errors(proto_b)
    legends = [" ".join(t.get_text() for t in ax.get_legend().get_texts()) for ax in maps]
    assert f"worst case {common.fmt_number(force_error * 100)} %" in legends[0]
    assert f"worst case {common.fmt_number(position_error * 1e3)} mm" in legends[1]
    assert "target 4 %: met" in legends[0] and "target 13.5 mm: met" in legends[1]
    for ax in maps:
        star = [line for line in ax.get_lines() if line.get_marker() == "*"][0]
        assert star.get_xdata()[0] == pytest.approx(450.0) and star.get_ydata()[0] == pytest.approx(0.2 * G0)
        assert ax.get_yscale() == "log" and "(N)" in ax.get_ylabel() and "(mm)" in ax.get_xlabel()
    units = [ax.get_title() for ax in maps]
    assert "(%)" in units[0] and "(mm)" in units[1] and "(%)" in units[2]


def test_missed_target_is_said(proto_b):
    design = copy.deepcopy(proto_b)
    design["spec"]["targets"]["force_error"] = 0.02   # below the 3.4 % at F_min
    fig = plots.plot_error_maps(design)
    legend = " ".join(t.get_text() for t in fig.axes[0].get_legend().get_texts())
    assert "target 2 %: missed in part of the region" in legend    # met towards F_max: sigma_F / F falls as 1/F
    # below sigma_F / F_max, the least over the region (3.4 % x F_min / F_max): missed everywhere,
    # where the legend had said "in part of the region"
    f_min, f_max = design["spec"]["load"]["force"]
    design["spec"]["targets"]["force_error"] = 0.5 * 0.034 * f_min / f_max
    fig = plots.plot_error_maps(design)
    legend = " ".join(t.get_text() for t in fig.axes[0].get_legend().get_texts())
    assert "missed over the whole region" in legend


def test_candidates_follow_the_ranking_rule(optimized):
    """MODEL.md section 5: the optimiser's list is already ranked; the chart keeps its order,
    and the chosen design is first and outlined."""
    rows = candidates._candidate_rows(optimized, plots.SensorData.from_design(optimized))
    assert [(r["material"], r["section"]) for r in rows] == \
        [(c["material"], c["section"]) for c in optimized["candidates"]]
    assert rows[0]["chosen"] and sum(r["chosen"] for r in rows) == 1
    fig = plots.plot_candidates(optimized)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert labels[0] == f"{optimized['design']['material']} · {optimized['design']['section']['kind']}"
    assert len(ax.patches) == len(optimized["candidates"])
    assert "e = max(σ_F/F_min ÷ target, σ_x ÷ target)" in ax.get_xlabel()
    assert "e ≤ 1" in ax.get_xlabel()


def test_candidate_ranking_ties_infeasible_and_missing():
    rows = [
        {"material": "A", "section": "tube", "status": "optimal", "objective": 0.5010, "deflection": 2e-3, "mass": 0.1},
        {"material": "B", "section": "tube", "status": "optimal", "objective": 0.5008, "deflection": 3e-3, "mass": 0.1},
        {"material": "C", "section": "tube", "status": "infeasible", "objective": 0.1, "worst_violation": 0.2},
        {"material": "D", "section": "tube", "status": "failed", "objective": None},
        {"material": "E", "section": "tube", "status": "infeasible", "objective": 0.3, "worst_violation": 0.05},
        {"material": "F", "section": "tube", "status": "optimal", "objective": 0.7, "deflection": 1e-3, "mass": 0.1},
        {"material": "G", "section": "tube", "status": "optimal", "objective": 0.5030, "deflection": 1e-3, "mass": 0.1},
    ]
    # A and B tie (0.04 %): A deflects less; G is 0.4 % worse: no tie; the infeasible ones as the
    # search ranked them (docs/model.md §5: keeping the geometry's rules before the worst
    # violation, which a design.json row does not say), not by their worst violation alone
    order = [r["material"] for r in plots.rank_candidates(rows)]
    assert order == ["A", "B", "G", "F", "C", "E", "D"]


def test_candidates_plot_marks_infeasible_and_shows_an_evaluated_design(optimized, proto_b):
    design = copy.deepcopy(optimized)
    design["candidates"][-1]["status"] = "infeasible"
    design["candidates"].append({"material": "X", "section": "round", "status": "failed", "objective": None})
    ax = plots.plot_candidates(design).axes[0]
    assert sum(1 for p in ax.patches if p.get_hatch() == "xx") == 1
    assert "no design found" in " ".join(t.get_text() for t in ax.texts)
    alone = plots.plot_candidates(proto_b).axes[0]   # evaluate writes no candidates
    assert [t.get_text() for t in alone.get_yticklabels()] == ["2024-T3 · rectangle"]


def test_every_candidate_label_ends_inside_the_axes_even_on_the_longest_bar(optimized):
    # An infeasible spec's candidates keep the search's order (closeness, not the objective), so the
    # chosen design may be the longest bar, its label the longest ("... ◀ chosen"): drawn at the
    # fixed 1.45 x margin it ran into the legend. Laid out as saved, each label's right edge is
    # within the axes' (display pixels).
    design = copy.deepcopy(optimized)
    design["status"] = "infeasible"
    longest = max(c["objective"] for c in design["candidates"] if c.get("objective") is not None)
    for c in design["candidates"]:
        c["status"] = "infeasible"
        if c["material"] == design["design"]["material"] and c.get("objective") is not None:
            c["objective"] = 3 * longest
    fig = plots.plot_candidates(design)
    ax = fig.axes[0]
    fig.draw_without_rendering()
    edge = ax.get_window_extent().x1
    chosen = [t for t in ax.texts if "chosen" in t.get_text()]
    assert chosen and all(t.get_window_extent().x1 <= edge for t in ax.texts)


# ----------------------------------------------------------------------------- trade-off fronts

def test_tradeoff_front_is_the_best_feasible_point_at_each_limit(tradeoff):
    points = tradeoff["max_deflection"]
    expected = {}
    for p in points:
        if p["feasible"]:
            expected[p["x"]] = min(expected.get(p["x"], math.inf), p["objective"])
    chosen = {"x": 7.16e-3, "objective": 0.2325}
    fig = plots.plot_tradeoff(points, chosen=chosen, x="max_deflection")
    ax = fig.axes[0]
    front = [line for line in ax.get_lines() if line.get_label() == "front: best of all"][0]
    xs, ys = front.get_data()
    np.testing.assert_allclose(xs, np.array(sorted(expected)) * 1e3)   # drawn in mm
    np.testing.assert_allclose(ys, [expected[x] for x in sorted(expected)])
    assert all(np.diff(ys) <= 1e-3)   # a looser deflection limit never makes the best design worse
    star = [line for line in ax.get_lines() if line.get_marker() == "*"][0]
    assert star.get_xdata()[0] == pytest.approx(7.16) and star.get_ydata()[0] == pytest.approx(0.2325)
    assert "(mm)" in ax.get_xlabel() and "e ≤ 1" in ax.get_ylabel()
    materials = {p["material"] for p in points}
    legend = {t.get_text() for t in ax.get_legend().get_texts()}
    assert materials <= legend          # one line per material


def test_tradeoff_against_frequency_and_grouping(tradeoff):
    points = tradeoff["min_frequency"]
    ax = plots.plot_tradeoff(points, x="natural_frequency", by="section").axes[0]
    assert "(Hz)" in ax.get_xlabel()
    legend = {t.get_text() for t in ax.get_legend().get_texts()}
    assert {"rectangle", "round", "tube"} <= legend
    # a higher frequency floor never improves the best design (speed costs accuracy)
    front = [line for line in ax.get_lines() if line.get_label() == "front: best of all"][0]
    assert all(np.diff(front.get_ydata()) >= -1e-3)


@pytest.mark.parametrize("points, x, message", [
    ([], "max_deflection", "the list is empty"),
    ([{"material": "A", "section": "tube", "x": 1e-3, "objective": 0.5}], "max_deflection",
     "feasible: None must be true or false"),
    ([{"material": "A", "section": "tube", "x": -1, "objective": 0.5, "feasible": True}], "max_deflection",
     "x: -1 must be a positive number"),
    ([{"material": "A", "section": "tube", "x": 1e-3, "objective": 0.5, "feasible": True}], "mass",
     "x: 'mass' is not allowed; must be one of [max_deflection, min_frequency]"),
])
def test_tradeoff_rejects_bad_points(points, x, message):
    with pytest.raises(InputError, match=message.replace("[", r"\[").replace("]", r"\]")):
        plots.plot_tradeoff(points, x=x)


def test_tradeoff_accepts_points_without_objective():
    points = [{"material": "A", "section": "tube", "x": 1e-3, "objective": None, "feasible": False},
              {"material": "A", "section": "tube", "x": 2e-3, "objective": 0.8, "feasible": True}]
    fig = plots.plot_tradeoff(points)
    assert fig.axes[0].get_lines()


# ----------------------------------------------------------------------------- reading a design

@pytest.mark.parametrize("path, value, message", [
    (("predicted", "sensitivity"), None, "predicted.sensitivity: missing"),
    (("predicted", "sensitivity"), [0.3], "predicted.sensitivity: 1 values for 2 stations"),
    (("design", "stations"), [0.02, 0.2], "must lie before the operating region"),
    (("spec", "load"), {"force": [2.0, 1.0], "position": [0.15, 0.45]}, "spec.load.force"),
    (("predicted", "stress_allowable"), -1.0, "predicted.stress_allowable: -1.0 must be a positive number"),
])
def test_bad_design_raises_a_design_file_error(proto_b, path, value, message):
    design = copy.deepcopy(proto_b)
    design[path[0]][path[1]] = value
    with pytest.raises(DesignFileError, match=message):
        plots.operating_region(design)


def test_plot_functions_draw_into_a_given_axes(proto_b):
    from matplotlib.figure import Figure

    fig = Figure()
    axes = fig.subplots(1, 3)
    assert plots.plot_operating_region(proto_b, ax=axes[0]) is fig
    assert plots.plot_voltage_isolines(proto_b, ax=axes[1]) is fig
    assert plots.plot_candidates(proto_b, ax=axes[2]) is fig


# ----------------------------------------------------------------------------- files


@pytest.mark.slow
def test_write_design_plots_writes_every_plot(proto_b, tradeoff, tmp_path):
    paths = plots.write_design_plots(proto_b, tmp_path / "out", formats=("png",), tradeoff=tradeoff)
    check_plot_files(paths, plots.PLOT_NAMES, ("png",))
    assert all(p.parent == tmp_path / "out" for p in paths)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(p.name for p in paths)


def test_write_design_plots_leaves_nothing_behind_on_failure(proto_b, tmp_path, monkeypatch):
    def broken(design, ax=None):
        raise RuntimeError("drawing failed")

    monkeypatch.setattr(plot_write, "plot_voltage_isolines", broken)
    with pytest.raises(RuntimeError):
        plots.write_design_plots(proto_b, tmp_path / "out", formats=("png",))
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    assert [p.name for p in tmp_path.iterdir() if p.name != "out"] == []


def test_the_same_design_gives_the_same_plot_files_svg_too(proto_b, tmp_path):
    # An SVG names its clip paths and glyphs by a hash that matplotlib salts with a random value
    # unless ``svg.hashsalt`` is set: the plots' SVG copies were new files at every run.
    first = plots.write_design_plots(proto_b, tmp_path / "a", formats=("png", "svg"))
    second = plots.write_design_plots(proto_b, tmp_path / "b", formats=("png", "svg"))
    assert len(first) == 2 * 4 and [p.name for p in first] == [p.name for p in second]
    for a, b in zip(first, second):
        assert a.read_bytes() == b.read_bytes(), a.name


def test_write_design_plots_rejects_unknown_formats(proto_b, tmp_path):
    with pytest.raises(InputError, match=r"format: 'jpg' is not allowed; must be one of \[png, svg\]"):
        plots.write_design_plots(proto_b, tmp_path / "out", formats=("jpg",))
    assert not (tmp_path / "out").exists()


def test_plotting_imports_matplotlib_lazily_and_leaves_global_state_alone():
    """The command module must not load matplotlib; drawing never loads pyplot or edits rcParams."""
    code = (
        "import sys, json\n"
        "import designer.cli.plot, designer.outputs.plots as p\n"
        "assert 'matplotlib' not in sys.modules, 'matplotlib imported at start-up'\n"
        "import matplotlib\n"
        "before = matplotlib.rcParams.copy()  # copy() does not resolve the backend\n"
        f"d = json.load(open({str(DATA / 'plot_prototype_b.json')!r}))\n"
        "p.plot_operating_region(d); p.plot_error_maps(d)\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot imported'\n"
        "after = matplotlib.rcParams.copy()\n"
        "assert [k for k in before if before._get(k) != after._get(k)] == [], 'rcParams changed'\n"
    )
    root = Path(__file__).resolve().parents[2]
    result = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


def test_a_pocket_on_a_round_section_is_called_a_flat_in_the_titles():
    from designer.outputs.plots.sensor import SensorData

    s = SensorData.from_design(json.loads((DATA / "plot_prototype_b.json").read_text()))
    assert replace(s, section="tube", feature="pocket").label.endswith("tube, flats")
    assert replace(s, section="rectangle", feature="pocket").label.endswith("rectangle, pockets")


def test_png_files_hold_the_same_pixels_as_pillows_default_compression(proto_b, tmp_path):
    # The plots are written with zlib's fastest level (drawing.figures.PNG_OPTIONS) to save time;
    # a PNG is lossless at every level, so the decoded image must equal the one Pillow's default
    # level (6) writes, byte for byte of pixels.
    from PIL import Image

    written = plot_write.write_design_plots(proto_b, tmp_path / "plots")
    fig = plots.plot_error_maps(proto_b)
    fig.savefig(tmp_path / "default.png", format="png", dpi=plot_write.PNG_DPI)
    ours = np.asarray(Image.open(next(p for p in written if p.name == "error-maps.png")))
    default = np.asarray(Image.open(tmp_path / "default.png"))
    assert ours.shape == default.shape and np.array_equal(ours, default)
