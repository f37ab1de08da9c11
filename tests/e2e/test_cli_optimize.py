"""``fpdesign optimize`` as a whole command (issue 3): design.json rebuilt and checked again,
infeasible specs reported with exit 1 and a reason, bad input refused with exit 2, --verify,
and solvers that raise inside the command.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from designer.result import designfile
from designer.search import run as search_run
from designer.cli import main
from designer.result.evaluation import evaluate
from shared_inputs import STUBBY_LUG
from shared_inputs import STABILITY_SCALES as SCALES
from shared_inputs import optimize_spec_text as _spec_text
from shared_inputs import raise_roundoff as _raise_roundoff

pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
OPTIMISER_EXAMPLES = ["gripper-finger", "weigh-bar", "probe", "prototype-b-optimized"]


@pytest.mark.parametrize("name", OPTIMISER_EXAMPLES)
def test_reported_design_meets_every_limit_when_rebuilt_from_design_json(name, tmp_path):
    out = tmp_path / "out"
    code = main(["optimize", str(EXAMPLES / f"{name}.yaml"), "-o", str(out), "--no-cad", "--no-plots", "--quiet"])
    assert code == 0
    record = designfile.load_design(out / "design.json")
    assert record["status"] == "optimal"
    spec, design = designfile.rebuild(record)
    ev = evaluate(design, spec)
    assert ev.feasible, [v.name for v in ev.violations]
    assert all(c["satisfied"] for c in record["constraints"])
    # what was reported is what was checked: re-evaluation reproduces the predictions
    assert ev.objective == pytest.approx(record["predicted"]["objective"], rel=1e-12)
    # (to round-off: the stiffness terms' exponentials of the rebuilt sizes)
    assert float(ev.analysis.deflection) == pytest.approx(record["predicted"]["deflection"], rel=1e-10)
    # rounded to 0.01 mm
    for s in record["design"]["stations"]:
        assert abs(s * 1e5 - round(s * 1e5)) < 1e-6
    # ranked candidates of every material x family, with a status each
    n = len(spec.search.materials) * len(spec.search.sections)
    assert len(record["candidates"]) == n
    assert {c["status"] for c in record["candidates"]} <= {"optimal", "infeasible", "failed", "outranked"}
    # (outranked: a tube, whose rows of the tube stock the best bar already ranks before, or a bar
    # whose answer before rounding was already 5 % above the best found before it: either way its
    # bound ranks below the reported design)
    outranked = [c for c in record["candidates"] if c["status"] == "outranked"]
    assert all(c["continuous_objective"] > record["predicted"]["objective"] for c in outranked)
    assert record["solver"]["method"] == "ipopt" and record["solver"]["evaluations"] > 0
    # the report lists each of the solver's notes on a line of its own
    lines = (out / "report.md").read_text(encoding="utf-8").splitlines()
    assert all(f"- {note}" in lines for note in record["solver"].get("fallbacks", []))


def _run(tmp_path, text, capsys):
    path = tmp_path / "spec.yaml"
    path.write_text(text)
    out = tmp_path / "out"
    code = main(["optimize", str(path), "-o", str(out), "--no-cad", "--no-plots", "--quiet"])
    captured = capsys.readouterr()
    return code, captured.out + captured.err, out


def test_feasible_base_spec_is_feasible(tmp_path, capsys):
    # The infeasible cases below each change one thing of this spec.
    code, text, out = _run(tmp_path, _spec_text(), capsys)
    assert code == 0, text


def test_infeasible_noise_too_high_names_targets_and_noise(tmp_path, capsys):
    code, text, out = _run(tmp_path, _spec_text(electronics="  excitation: 5 V\n  gain: 128\n  noise_rti: 50 uV"),
                           capsys)
    assert code == 1
    assert "Traceback" not in text
    assert "force_error" in text and "noise" in text
    record = json.loads((out / "design.json").read_text())
    assert record["status"] == "infeasible"
    # the noise level it proposes does make the targets reachable: errors scale with the noise
    assert "mV at the output" in " ".join(record["messages"])


def test_infeasible_no_room_for_stations(tmp_path, capsys):
    # pockets 8.9 mm long: 5 + 2 x 8.9 + 2 + 5 = 29.8 mm are needed before x_min (MODEL.md section 1)
    code, text, out = _run(tmp_path, _spec_text(load="  force: [1 N, 20 N]\n  position: [20 mm, 150 mm]"), capsys)
    assert code == 1
    assert "no room for 2 gauge stations" in text and "29.8 mm" in text
    record = json.loads((out / "design.json").read_text())
    assert record["status"] == "infeasible"
    violated = {c["name"] for c in record["constraints"] if not c["satisfied"]}
    assert violated & {"load_clearance", "clamp_clearance", "station_gap_1"}


def test_infeasible_deflection_limit_too_tight(tmp_path, capsys):
    code, text, out = _run(tmp_path, _spec_text(limits="  max_deflection: 0.001 mm"), capsys)
    assert code == 1
    assert "deflection" in text and "limits.max_deflection" in text
    record = json.loads((out / "design.json").read_text())
    assert record["status"] == "infeasible"
    assert "deflection" in {c["name"] for c in record["constraints"] if not c["satisfied"]}


def test_unknown_method_is_bad_input(capsys):
    assert main(["optimize", str(EXAMPLES / "probe.yaml"), "--method", "newton", "--no-cad", "--no-plots"]) == 2
    assert "--method: 'newton' is not allowed" in capsys.readouterr().err


def test_verify_reports_a_design_that_fails_in_3d(tmp_path, capsys):
    # A stubby lug on a 0.012 mm deflection limit deflects about 1.036 x the model in 3-D on the
    # coarse mesh (shear and the clamp's give beyond the fitted stiffness, docs/model.md §11), so
    # --verify must report it. No correction rounds: the design is judged as it is.
    spec = tmp_path / "spec.yaml"
    spec.write_text(STUBBY_LUG, encoding="utf-8")
    out = tmp_path / "out"
    code = main(["optimize", str(spec), "-o", str(out), "--no-plots", "--no-cad", "--quiet",
                 "--verify", "--verify-mesh", "coarse", "--verify-rounds", "0"])
    text = capsys.readouterr().out
    record = json.loads((out / "design.json").read_text())
    verification = record["verification"]
    assert {"gauges", "deflection", "stress", "limits"} <= set(verification)
    failed = [c["name"] for c in verification["limits"] if not c["satisfied"]]
    assert "deflection" in failed
    assert all(c["model_satisfied"] for c in verification["limits"])  # the beam model passed it
    # under the default ISO 2768-m the deflection is judged at its worst corner (b min, h min):
    # the model's value there (design.json's tolerances) times the nominal design's 3-D/model ratio
    check = next(c for c in verification["limits"] if c["name"] == "deflection")
    corner = next(c for c in record["tolerances"]["constraints"] if c["name"] == "deflection")
    assert corner["corner"] == "b min, h min" and corner["corner"] in check["source"]
    assert check["model"] == pytest.approx(corner["value"], rel=1e-12)
    ratio = verification["deflection"]["fea"] / verification["deflection"]["model"]
    assert check["fea"] == pytest.approx(corner["value"] * ratio, rel=1e-12)
    assert check["model"] > record["predicted"]["deflection"]  # the thin corner deflects more
    assert code == 1 and record["status"] == "infeasible"
    assert [r["round"] for r in record["verify_rounds"]] == [0] and "adjustment" not in record["design"]
    assert "3-D check" in " ".join(record["messages"]) and "FAILS" in text
    assert (out / "verify.md").exists() and (out / "surface-strain.png").exists()
    # design.json lists every file of the folder, so that a later run without --verify removes
    # them all (previous_outputs) rather than leave a 3-D check of another design beside it
    listed = {name for value in record["files"].values() for name in (value if isinstance(value, list) else [value])}
    assert listed | {"design.json"} == {p.name for p in out.iterdir()}
    assert main(["optimize", str(spec), "-o", str(out), "--no-plots", "--no-cad", "--quiet"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "report.md"]


def test_infeasible_design_with_cad_still_writes_design_json(tmp_path, capsys):
    # No room for the stations: the least-infeasible design has overlapping features, which the
    # CAD module refuses to build; the run must still report it (exit 1), not fail as bad input.
    path = tmp_path / "spec.yaml"
    path.write_text(_spec_text(load="  force: [1 N, 20 N]\n  position: [20 mm, 150 mm]"))
    out = tmp_path / "out"
    code = main(["optimize", str(path), "-o", str(out), "--no-plots", "--quiet"])
    text = capsys.readouterr()
    assert code == 1, text.err
    record = json.loads((out / "design.json").read_text())
    assert record["status"] == "infeasible"
    step = list(out.glob("*.step"))
    assert step or any("no CAD model" in m for m in record["messages"])


# A hole design whose deflection limit is below the stiffest beam's (generated by
# `fpdesign bench`, seed 0, spec 032): every design is infeasible. The least violating
# answers of the NLP have a hole wider than the bar, which is no beam at all.
IMPOSSIBLE_HOLE_SPEC = """
name: impossible-hole
load: {force: [509.2 mN, 8.916 N], position: [74.32 mm, 158.8 mm]}
electronics: {excitation: 2.5 V, gain: 128.0, noise_strain: 0.2158 ue}
gauge: BF120-3AA
bridge: half
stations: 2
limits:
  width: [1.047 mm, 9.267 mm]
  height: [1.047 mm, 8.767 mm]
  min_wall: 0.8767 mm
  max_deflection: 0.06169 mm
targets: {force_error: 1.97 %, position_error: 4.854 mm}
search: {materials: [17-7PH-RH950, '304'], sections: [rectangle], feature: hole}
objective: error
"""


@pytest.mark.parametrize("method", ["ipopt", "slsqp", "grid"])
def test_least_infeasible_design_is_a_buildable_beam(method, tmp_path):
    # The least-infeasible design is reported so that it can be plotted, exported and
    # simulated: its design.json must pass the product's own reader (designfile.validate),
    # which refuses a hole at least as wide as the section height.
    path = tmp_path / "spec.yaml"
    path.write_text(IMPOSSIBLE_HOLE_SPEC)
    out = tmp_path / "out"
    code = main(["optimize", str(path), "-o", str(out), "--method", method, "--no-cad", "--no-plots", "--quiet"])
    assert code == 1
    record = designfile.load_design(out / "design.json")
    assert record["status"] == "infeasible"
    d = record["design"]
    assert d["feature"]["diameter"] < d["section"]["height"]
    # simulate judges no limits: any design it can read gets its Monte Carlo and exit 0
    # (exit 2 would mean the reader refused the file)
    assert main(["simulate", str(out / "design.json"), "--draws", "200"]) == 0


# A miniature gauge 1.2 mm wide with 0.2 mm pocket margins on a bar at most 1.095 mm wide
# (generated by `fpdesign bench`, seed 6, spec 023): its slot, 1.2 + 2 x 0.2 = 1.6 mm wide, fits
# on no bar the limits allow, and a tube's flat on a tube that small breaks the flat's limits, so
# no design found is a beam with its feature.
SLOT_WIDER_THAN_BAR_SPEC = """
name: slot-wider-than-bar
load: {force: [1.32 mN, 37.6 mN], position: [24.97 mm, 42.41 mm]}
electronics: {excitation: 3.3 V, gain: 1.0, noise_strain: 0.1101 ue}
gauge: {name: miniature, factor: 2.0, length: 1.5 mm, width: 1.2 mm, max_strain: 1500 ue}
bridge: full
stations: 2
limits:
  clamp_clearance: 1 mm
  load_clearance: 1 mm
  tip_margin: 1 mm
  pocket_margin: 0.2 mm
  gauge_gap: 0.5 mm
  min_wall: 0.2 mm
  min_pocket_depth: 0.05 mm
  width: [0.3 mm, 1.095 mm]
  height: [0.3 mm, 1.088 mm]
targets: {force_error: 1.36 %, position_error: 0.6229 mm}
search: {materials: [17-7PH-RH950, '304'], sections: [rectangle, tube], feature: pocket}
objective: error
cad: {end_mill_diameter: 0.8 mm}
tolerances: {class: none}
"""


def test_a_spec_whose_closest_design_is_no_beam_is_reported_infeasible_with_why(tmp_path, capsys):
    """No design is a beam, so the closest one's figures can be neither plotted nor reasoned from,
    whatever their signs (the slot fits, extrapolated to a slot wider than its bar, once read it a
    negative sensitivity and now a positive one): exit 1 with design.json and the report, not exit 2
    as if the spec were malformed, and the diagnosis names the slot's width against the widest bar."""
    path = tmp_path / "spec.yaml"
    path.write_text(SLOT_WIDER_THAN_BAR_SPEC)
    out = tmp_path / "out"
    code = main(["optimize", str(path), "-o", str(out), "--no-cad", "--quiet"])
    err = capsys.readouterr().err
    assert code == 1, err
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "report.md"]
    record = json.loads((out / "design.json").read_text())
    assert record["status"] == "infeasible"
    messages = record["messages"]
    assert any(m.startswith("no plots for this infeasible design: ") for m in messages)
    said = next(m for m in messages if m.startswith("design.feature.width: "))
    assert "1.6 mm" in said and "at most 1.095 mm wide" in said
    assert not any("gets no signal" in m for m in messages)   # reasoned from the negative sensitivity


def test_terminal_summary_marks_the_chosen_candidate_among_the_runners_up(tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["optimize", str(EXAMPLES / "gripper-finger.yaml"), "-o", str(out), "--no-plots", "--no-cad"])
    text = capsys.readouterr().out
    record = json.loads((out / "design.json").read_text())
    assert code == 0
    first = record["candidates"][0]
    assert (first["material"], first["section"]) == (record["design"]["material"], record["design"]["section"]["kind"])
    chosen = [line for line in text.splitlines() if "chosen" in line and "│" in line]  # a table row
    assert len(chosen) == 1 and first["material"] in chosen[0] and first["section"] in chosen[0]


def test_an_nlopt_method_that_raises_through_the_command_line_gives_no_traceback(monkeypatch, tmp_path, capsys):
    import nlopt

    monkeypatch.setattr(nlopt.opt, "optimize", _raise_roundoff)
    path = tmp_path / "spec.yaml"
    path.write_text(SCALES["kilonewtons on a metre beam"])
    code = main(["optimize", str(path), "--method", "slsqp", "-o", str(tmp_path / "out"), "--no-cad",
                 "--no-plots", "--quiet"])
    captured = capsys.readouterr()
    # The spec is feasible (unit/test_optimize_stability.py finds a verified design within 0.5 %
    # of the reference search), and IPOPT answers when SLSQP raises: exit 0 (README: 0 optimal).
    assert code == 0
    assert "Traceback" not in captured.out + captured.err
    record = designfile.load_design(tmp_path / "out" / "design.json")
    spec, design = designfile.rebuild(record)
    assert evaluate(design, spec).feasible == (code == 0)


def test_no_design_that_can_be_evaluated_is_an_error_with_a_message_not_a_traceback(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(search_run, "round_and_check", lambda design, spec: None)
    path = tmp_path / "spec.yaml"
    path.write_text(SCALES["kilonewtons on a millimetre beam"])
    code = main(["optimize", str(path), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots", "--quiet"])
    captured = capsys.readouterr()
    assert code == 1
    assert "no solver returned a design" in captured.err
    assert "Traceback" not in captured.out + captured.err
    assert not (tmp_path / "out" / "design.json").exists()


def test_the_whole_job_writes_every_output_and_draws_the_plots_as_the_plot_command_does(tmp_path):
    # The job's two processes share the plots (the CAD process draws them after the CAD outputs
    # while the other computes the trade-off fronts, each claiming a plot before drawing it): the
    # folder holds exactly the files design.json lists (no claims or staging left), the six plots
    # among them, and the design's four are the bytes `fpdesign plot` draws from design.json alone.
    from designer.outputs.plots import PLOT_NAMES

    out = tmp_path / "out"
    assert main(["optimize", str(EXAMPLES / "gripper-finger.yaml"), "-o", str(out), "--quiet"]) == 0
    files = json.loads((out / "design.json").read_text())["files"]
    assert files["plots"] == sorted(f"{name}.png" for name in PLOT_NAMES)
    listed = {files[k] for k in ("step", "model_png", "drawing_svg", "drawing_png", "report")}
    assert sorted(p.name for p in out.iterdir()) == sorted(listed | set(files["plots"]) | {"design.json"})
    # the report shows the model picture and the drawing beside the plots
    report = (out / "report.md").read_text(encoding="utf-8")
    for picture in [files["model_png"], files["drawing_png"], *files["plots"]]:
        assert f"]({picture})" in report, picture
    again = tmp_path / "again"
    assert main(["plot", str(out / "design.json"), "-o", str(again)]) == 0
    for name in PLOT_NAMES[:4]:
        assert (again / f"{name}.png").read_bytes() == (out / f"{name}.png").read_bytes(), name
