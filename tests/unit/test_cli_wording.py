"""What the command line prints: feature names, gauge names, the candidate ranking, the
catalogue at 80 columns, notes, and a closed pipe."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from designer.cli import PIPE_CLOSED, main
from designer.outputs import report
from designer.spec.reader import parse_spec

ROOT = Path(__file__).resolve().parents[2]
LOAD = {"load": {"force": ["1 N", "20 N"], "position": ["100 mm", "300 mm"]},
        "electronics": {"excitation": "5 V", "gain": 500, "noise": "1 mV"}}


def test_flats_on_a_round_bar_are_called_flats_with_their_chord():
    """docs/spec.md §6: flats on round bars and tubes; the drawing says flat. The width at the
    surface of a flat p deep on a bar of diameter D is the chord 2 sqrt(p (D - p)): 6 mm for
    D = 10 mm, p = 1 mm."""
    feature = {"kind": "pocket", "depth": 0.001, "length": 0.0089, "width": 0.0055}
    for section in ({"kind": "round", "diameter": 0.010}, {"kind": "tube", "diameter": 0.010, "wall": 0.002}):
        text = report.feature_text(feature, section)
        assert text.startswith("flat 8.90 mm long, 1.00 mm deep") and "(6.00 mm wide at the surface)" in text
        assert "pocket" not in text
    assert report.feature_text(feature, {"kind": "rectangle", "width": 0.01, "height": 0.005}).startswith(
        "pocket 8.90 × 5.50 mm")


def test_an_overridden_gauge_is_named_as_modified_and_reads_back():
    spec = parse_spec(dict(LOAD, gauge={"name": "BF120-3AA", "max_strain": "2500 ue"}))
    assert spec.gauge.name == "BF120-3AA (modified max_strain)"
    assert spec.gauge.max_strain == pytest.approx(2.5e-3)
    # the same values as the catalogue: still the catalogue's gauge
    assert parse_spec(dict(LOAD, gauge={"name": "BF120-3AA", "max_strain": "1500 ue"})).gauge.name == "BF120-3AA"
    # design.json carries the gauge as a dictionary; read back, it is the same gauge
    again = parse_spec(dict(LOAD, gauge=spec.gauge.as_dict()))
    assert again.gauge.as_dict() == spec.gauge.as_dict()


def _infeasible_record():
    record = json.loads((ROOT / "tests" / "data" / "plot_prototype_b.json").read_text())
    record["status"] = "infeasible"
    record["candidates"] = [
        {"material": "7075-T6", "section": "rectangle + pocket", "status": "infeasible", "objective": 3.0,
         "worst_violation": 0.05},
        {"material": "6061-T6", "section": "round + pocket", "status": "infeasible", "objective": 1.0,
         "worst_violation": 0.4},
    ]
    return record


def test_the_candidate_table_says_how_it_is_ranked_and_shows_the_ranking_key(capsys):
    from rich.console import Console

    record = _infeasible_record()
    report.print_summary(record, Console(width=200))
    out = capsys.readouterr().out
    assert "worst violation" in out and "least infeasible" in out
    assert out.index("0.05") < out.index("0.4")
    md = report.markdown(record)
    assert report.candidate_order(record) in md and "| worst violation |" in md
    record["status"] = "optimal"
    assert "ranked by the objective (error" in report.candidate_order(record)


def test_the_terminal_candidate_table_explains_only_the_statuses_it_shows(capsys):
    """The terminal shows the first six candidates; its caption explained "Outranked" where only
    report.md's full table had one (the weigh-bar's 8th and 9th of 27), and now says how many more
    report.md lists."""
    from rich.console import Console

    record = _infeasible_record()
    record["status"] = "optimal"
    row = {"material": "7075-T6", "section": "round + flat", "status": "optimal", "objective": 0.37,
           "worst_violation": 0.0}
    record["candidates"] = [row] * 6 + [dict(row, status="outranked", objective=None, continuous_objective=0.5)] * 2
    report.print_summary(record, Console(width=200))
    out = " ".join(capsys.readouterr().out.split())
    assert "Outranked" not in out and "2 more in report.md." in out
    assert "Outranked" in report.markdown(record) and "0.5 before rounding" in report.markdown(record)
    record["candidates"] = record["candidates"][2:]   # now the terminal shows one
    report.print_summary(record, Console(width=200))
    out = " ".join(capsys.readouterr().out.split())
    assert "Outranked" in out and "more in report.md" not in out


def test_the_candidates_section_reads_as_the_search_ranks_and_names_each_candidate_once():
    """The infeasible candidates after the feasible ones are ranked by ``closest.closeness`` (rules
    broken before the duty's worst violation): the weigh-bar's rectangles read 1.55, 1.45, ...,
    0.586, ..., 1.78 under "the others by their worst violation". A stock note that names its
    candidate is not prefixed again ("6061-T6 tube: 6061-T6 tube: no design ...")."""
    record = _infeasible_record()
    record["status"] = "optimal"
    assert "the fewest of the geometry's rules broken" in report.candidate_order(record)
    note = "6061-T6 tube: no design of continuous sizes meets every limit, so no stock size was tried"
    record["candidates"].append({"material": "6061-T6", "section": "tube", "status": "infeasible",
                                 "objective": None, "stock_note": note})
    record["candidates"].append({"material": "304", "section": "round", "status": "infeasible",
                                 "objective": None, "stock_note": "no stock row of 304 round meets every limit"})
    md = report.markdown(record)
    assert f"- {note}\n" in md and "- 304 round: no stock row of 304 round meets every limit" in md


def test_materials_reads_at_80_columns(capsys, monkeypatch):
    from designer.spec import catalogue

    monkeypatch.setenv("COLUMNS", "80")
    assert main(["materials"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) <= 80
    for name in list(catalogue.materials()) + list(catalogue.gauges()):
        row = next(line for line in lines if line.lstrip().startswith(name + " "))
        assert "…" not in row   # no figure cut short
    assert any(line.startswith("[1] ") for line in lines)


def test_bench_says_when_it_finds_no_example_specs(tmp_path, capsys, monkeypatch):
    from designer import bench
    from designer.errors import InputError

    def stop(*args, **kwargs):
        raise InputError("stopped before running")

    monkeypatch.setattr(bench, "run_bench", stop)
    monkeypatch.setattr(bench, "default_examples_folder", lambda: None)   # an installed package
    assert main(["bench", "--count", "1", "--quiet", "-o", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert "no examples folder beside the package" in err and "running the 1 generated specs only" in err
    empty = tmp_path / "specs"
    empty.mkdir()
    assert main(["bench", "--specs", str(empty), "--count", "1", "--quiet", "-o", str(tmp_path / "b")]) == 2
    assert f"no optimiser specs in {empty}" in capsys.readouterr().err


def test_ipopt_options_keep_casadis_nan_warnings_off_standard_error(capfd):
    """A trial point where the model is NaN (sqrt of a negative) is IPOPT's to handle; casadi
    would print 'NaN detected' for it."""
    import casadi as ca

    from designer.search.problem import IPOPT_OPTIONS

    x = ca.SX.sym("x")
    solver = ca.nlpsol("nan_probe", "ipopt", {"x": x, "f": (x - 1) ** 2, "g": ca.sqrt(x)}, IPOPT_OPTIONS)
    solver(x0=-1, lbg=-10, ubg=10)
    assert "NaN detected" not in capfd.readouterr().err
    loud = ca.nlpsol("nan_probe2", "ipopt", {"x": x, "f": (x - 1) ** 2, "g": ca.sqrt(x)},
                     dict(IPOPT_OPTIONS, show_eval_warnings=True))
    loud(x0=-1, lbg=-10, ubg=10)
    assert "NaN detected" in capfd.readouterr().err   # the probe does reach a NaN


@pytest.mark.parametrize("argv", [["materials"], ["materials", "--json"]])
def test_a_closed_pipe_is_a_quiet_exit(argv):
    """`fpdesign materials | head`: the reader closes the pipe; no traceback, no message, exit 141."""
    env = {"PATH": "/usr/bin:/bin", "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "designer.cli", *argv], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, env=env, cwd=ROOT)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.wait(timeout=60)
    assert proc.returncode == PIPE_CLOSED == 128 + 13 and err == ""


def test_a_solve_that_meets_an_invalid_number_leaves_standard_error_quiet(capfd):
    """A load region 8-15 mm from the clamp (no room for two stations): IPOPT stops at once on
    an invalid number in the plain rectangle's model (the bar without a feature, whose model no
    fitted correction moves). casadi would then warn "Failed to calculate
    multipliers" for the parameters' multipliers, which the search never reads: over a thousand
    such lines in one optimize run."""
    import casadi as ca

    from designer.search import problem as P
    from designer.spec import catalogue
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text("load: {force: [1 N, 10 N], position: [8 mm, 15 mm]}\n"
                           "electronics: {excitation: 5 V, gain: 100, noise: 1 mV}\n")
    fam = P.FamilyProblem(spec, P.Family("rectangle", "none"))
    params = fam.params(catalogue.material("6061-T6"))
    capfd.readouterr()
    s = fam.solve_ipopt(params, fam.starts()[0])
    assert s.message == "Invalid_Number_Detected"
    assert "Failed to calculate multipliers" not in capfd.readouterr().err
    loud = ca.nlpsol("loud", "ipopt", fam.nlp, dict(P.IPOPT_OPTIONS, calc_lam_p=True, **{"ipopt.tol": P.IPOPT_TOLERANCE}))
    fam.ipopt = lambda stage="primary": loud
    fam.solve_ipopt(params, fam.starts()[0])
    assert "Failed to calculate multipliers" in capfd.readouterr().err   # the same solve does reach it


def test_a_design_that_meets_every_limit_to_rounding_shows_no_violation():
    # The weigh-bar's runners-up read "worst violation 8.67e-16" beside "optimal": a limit met to
    # within FEASIBILITY_TOLERANCE (1e-9) is met, and the table says "none" for it.
    from designer.model.limits import Limit
    from designer.result.evaluation import Evaluation

    met = Evaluation(None, None, (Limit("deflection", 1.97e-3 * (1 + 8.67e-16), 1.97e-3),), 0.3986, 0.9)
    assert met.feasible and met.worst_violation == 0.0
    assert report._violation({"worst_violation": met.worst_violation}) == "none"
    broken = Evaluation(None, None, (Limit("deflection", 1.97e-3 * 1.01, 1.97e-3),), 0.3986, 0.9)
    assert not broken.feasible and broken.worst_violation == pytest.approx(0.01)


@pytest.mark.parametrize("example, said", [("prototype-b", "half, 1 axis"), ("prototype-c", "half, 2 axes")])
def test_the_bridges_row_names_the_axes_in_english(example, said):
    """The summary's bridges row: "1 axis", "2 axes" (a biaxial sensor's had read "2 axises")."""
    from designer.result.evaluation import evaluate, fixed_design
    from designer.result.record import build_record
    from designer.spec.reader import load_spec

    spec = load_spec(ROOT / "examples" / f"{example}.yaml")
    record = json.loads(json.dumps(build_record("feasible", spec, evaluate(fixed_design(spec), spec))))
    assert dict(report.summary_rows(record))["bridges"] == said
