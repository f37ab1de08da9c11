"""``fpdesign verify`` as a whole command: its report, JSON and plot, and its refusals."""

from __future__ import annotations

import json

import pytest

from designer.cli import main
from shared_inputs import fea_bar as bar

pytestmark = pytest.mark.slow


def test_verify_command_writes_the_report_json_and_plot(tmp_path, capsys):
    path = tmp_path / "design.json"
    path.write_text(json.dumps(bar(310, (60, 300))), encoding="utf-8")
    out = tmp_path / "check"
    code = main(["verify", str(path), "--mesh", "coarse", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["surface-strain.png", "verify.json", "verify.md"]
    data = json.loads((out / "verify.json").read_text())
    assert data["passed"] and data["converged"]
    assert [g["ratio"] for g in data["gauges"]] == pytest.approx([1.0, 1.0], abs=0.01)
    assert len(data["meshes"]) == 2 and data["meshes"][0]["elements"] > data["meshes"][1]["elements"]
    report = (out / "verify.md").read_text()
    assert "| 30.0 |" in report and "mesh convergence" in report and "converged" in report
    assert (out / "surface-strain.png").read_bytes()[:4] == b"\x89PNG"
    assert "3-D / model" in capsys.readouterr().out


def test_verify_refuses_bad_input_without_a_traceback(tmp_path, capsys):
    missing = tmp_path / "none.json"
    assert main(["verify", str(missing), "-o", str(tmp_path / "o")]) == 2
    assert "no such file" in capsys.readouterr().err
    good = bar(310, (60, 300))
    broken = json.loads(json.dumps(good))
    del broken["design"]["gauge"]["grid_length"]
    path = tmp_path / "broken.json"
    path.write_text(json.dumps(broken), encoding="utf-8")
    assert main(["verify", str(path), "-o", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "design.gauge" in err and "grid_length" in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()        # nothing half-written
    afile = tmp_path / "file"
    afile.write_text("x")
    path.write_text(json.dumps(good), encoding="utf-8")
    assert main(["verify", str(path), "-o", str(afile)]) == 2
    assert "is a file" in capsys.readouterr().err


def test_verify_prints_its_report_without_the_mesher_s_own_messages(tmp_path, capfd):
    # The bench suite's 016-short-beam (fpdesign bench, seed 0): on its coarse mesh gmsh's 3-D
    # mesher (TetGen, recovering the boundary of a mesh that then succeeds) printed "PLC Error: A
    # vertex lies in a segment" from C on standard output, above the report of a check that passes.
    from designer.bench import suite

    item = next(s for s in suite.generate_suite(50, 0) if s.name == "016-short-beam")
    spec = tmp_path / "spec.yaml"
    spec.write_text(item.text, encoding="utf-8")
    assert main(["optimize", str(spec), "-o", str(tmp_path / "d"), "--no-cad", "--no-plots", "--quiet"]) == 0
    capfd.readouterr()
    code = main(["verify", str(tmp_path / "d" / "design.json"), "--mesh", "coarse", "-o", str(tmp_path / "check")])
    out, err = capfd.readouterr()
    assert code == 0, err
    assert "PLC" not in out + err
    assert out.lstrip().startswith("016-short-beam: 3-D check")
