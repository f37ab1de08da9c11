"""``fpdesign plot`` as a whole command: the files it writes next to a design or into a folder,
and bad input refused with exit 2, nothing written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from designer.outputs import plots
from designer.cli import main
from shared_inputs import check_plot_files

pytestmark = pytest.mark.slow

DATA = Path(__file__).resolve().parents[1] / "data"


def test_plot_command_writes_png_next_to_the_design(tmp_path, capsys):
    design = tmp_path / "design.json"
    design.write_text((DATA / "plot_prototype_c.json").read_text())
    assert main(["plot", str(design), "--format", "png"]) == 0
    written = sorted(p.name for p in tmp_path.glob("*.png"))
    assert written == sorted(f"{n}.png" for n in plots.PLOT_NAMES[:4])
    assert str(tmp_path / "operating-region.png") in capsys.readouterr().out


def test_plot_command_with_tradeoff_points_and_svg(tmp_path):
    out = tmp_path / "plots"
    assert main(["plot", str(DATA / "plot_optimized.json"), "-o", str(out), "--format", "svg",
                 "--tradeoff", str(DATA / "plot_tradeoff.json")]) == 0
    check_plot_files(list(out.iterdir()), plots.PLOT_NAMES, ("svg",))


@pytest.mark.parametrize("content, message", [
    (None, "no such file"),
    ("{", "not valid JSON"),
    (json.dumps({"spec": {}, "design": {}}), "design.material: missing"),
])
def test_plot_command_bad_input_exits_2_without_traceback(tmp_path, capsys, content, message):
    path = tmp_path / "design.json"
    if content is not None:
        path.write_text(content)
    assert main(["plot", str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_plot_command_bad_tradeoff_file_exits_2(tmp_path, capsys):
    bad = tmp_path / "tradeoff.json"
    bad.write_text(json.dumps({"max_deflection": [{"material": "A", "section": "tube", "x": 1e-3}]}))
    assert main(["plot", str(DATA / "plot_prototype_b.json"), "-o", str(tmp_path / "out"),
                 "--tradeoff", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "tradeoff.max_deflection[0].feasible: None must be true or false" in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("key, value, message", [
    # matplotlib read '$\\foo$' as mathematics and stopped with a traceback
    ("material", "$\\foo$", "tradeoff.max_deflection[0].material: '$\\\\foo$' must be a name"),
    # the plot's scales overflowed: six lines of numpy warnings before the plot
    ("x", 1e307, "tradeoff.max_deflection[0].x: 1e+307 must be a positive number (SI units) up to 1e+10"),
    ("objective", 1e308, "tradeoff.max_deflection[0].objective: 1e+308 must be a positive number up to 1e+10"),
])
def test_plot_command_refuses_trade_off_points_it_cannot_draw(tmp_path, capsys, key, value, message):
    points = json.loads((DATA / "plot_tradeoff.json").read_text())
    points["max_deflection"][0][key] = value
    bad = tmp_path / "tradeoff.json"
    bad.write_text(json.dumps(points))
    assert main(["plot", str(DATA / "plot_prototype_b.json"), "-o", str(tmp_path / "out"),
                 "--tradeoff", str(bad)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_plot_command_with_a_folder_in_the_way_names_it_and_writes_no_plot(tmp_path, capsys):
    out = tmp_path / "out"
    (out / "voltage-isolines.png").mkdir(parents=True)    # the second plot of four
    assert main(["plot", str(DATA / "plot_prototype_b.json"), "-o", str(out)]) == 2
    assert capsys.readouterr().err.strip() == (f"fpdesign: error: cannot write {out / 'voltage-isolines.png'}: "
                                               "a folder is in the way; choose another folder for the plots with -o")
    assert [p.name for p in out.iterdir()] == ["voltage-isolines.png"]
    assert not any((out / "voltage-isolines.png").iterdir())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_plot_command_missing_prediction_names_the_key(tmp_path, capsys):
    record = json.loads((DATA / "plot_prototype_b.json").read_text())
    del record["predicted"]["sensitivity"]
    path = tmp_path / "design.json"
    path.write_text(json.dumps(record))
    assert main(["plot", str(path)]) == 2
    assert "predicted.sensitivity: missing" in capsys.readouterr().err


def test_evaluate_writes_svg_copies_of_the_plots_only_when_asked(tmp_path):
    from pathlib import Path

    example = Path(__file__).resolve().parents[2] / "examples" / "prototype-c.yaml"
    plain, svg = tmp_path / "png", tmp_path / "svg"
    assert main(["evaluate", str(example), "-o", str(plain), "--no-cad"]) == 0
    assert main(["evaluate", str(example), "-o", str(svg), "--no-cad", "--svg"]) == 0
    names = ("operating-region", "voltage-isolines", "error-maps", "candidates")
    check_plot_files([p for p in plain.iterdir() if p.suffix in (".png", ".svg")], names, ("png",))
    check_plot_files([p for p in svg.iterdir() if p.suffix in (".png", ".svg")], names, ("png", "svg"))


@pytest.mark.parametrize("content, message", [
    # a readings file given by mistake: its rows are not echoed whole (10,000 of them filled the screen)
    ([[0.1 * i, 0.2 * i] for i in range(10_000)],
     "fpdesign: error: tradeoff: [[0.0, 0.0], [0.1, 0.2], [0.2, 0.4], [0.30000000000000004, 0.6000000000000001... "
     "must map max_deflection / min_frequency to lists of points"),
    ({"max_deflection": [{"material": "A", "section": "round", "x": 1e-3, "objectiv": 0.5, "feasible": True}]},
     "fpdesign: error: tradeoff.max_deflection[0]: unknown key 'objectiv'; allowed keys are one of [material, section, "
     "x, objective, feasible, value]"),
])
def test_plot_command_names_a_wrong_trade_off_file_in_one_short_line(tmp_path, capsys, content, message):
    bad = tmp_path / "tradeoff.json"
    bad.write_text(json.dumps(content))
    assert main(["plot", str(DATA / "plot_prototype_b.json"), "-o", str(tmp_path / "out"),
                 "--tradeoff", str(bad)]) == 2
    assert capsys.readouterr().err.strip() == message
    assert not (tmp_path / "out").exists()
