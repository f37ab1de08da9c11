"""``fpdesign optimize --verify`` correcting a design that fails in 3-D (docs/model.md §11), with
the real 3-D check on the coarse mesh, and the design.json it writes read back by ``verify``."""

from __future__ import annotations

import json

import pytest

from designer.cli import main
from shared_inputs import STUBBY_LUG

pytestmark = pytest.mark.slow


def test_a_design_over_its_deflection_limit_in_3d_is_corrected_until_the_3d_check_passes(tmp_path, capsys):
    spec = tmp_path / "spec.yaml"
    spec.write_text(STUBBY_LUG, encoding="utf-8")
    out = tmp_path / "out"
    code = main(["optimize", str(spec), "-o", str(out), "--no-cad", "--no-plots", "--quiet", "--verify",
                 "--verify-mesh", "coarse"])
    text = capsys.readouterr().out
    record = json.loads((out / "design.json").read_text())
    rounds = record["verify_rounds"]
    limit = 0.012e-3  # limits.max_deflection
    # round 0: the beam model's optimum meets the deflection limit, the 3-D check does not
    assert not rounds[0]["passed"] and "deflection" in rounds[0]["failed"]
    assert rounds[0]["worst_limit"] == "deflection" and rounds[0]["worst_ratio"] > 1
    # a later round passes, and what is reported is that round's design and its 3-D check
    assert code == 0 and record["status"] == "optimal"
    assert rounds[-1]["passed"] and len(rounds) >= 2
    verification = record["verification"]
    assert verification["passed"] and all(c["satisfied"] for c in verification["limits"])
    assert verification["deflection"]["fea"] <= limit
    # the factors of the reported design are round 0's 3-D/model ratios, composed round by round
    factors = record["design"]["adjustment"]
    assert factors == rounds[-1]["adjustment"]
    product = 1.0
    for r in rounds[:-1]:
        product *= r["ratios"]["deflection"]
    assert factors["deflection"] == pytest.approx(product, rel=1e-12)
    assert "corrected by the 3-D check" in " ".join(record["messages"]) and "round 1" in text
    assert "## 3-D check" in (out / "report.md").read_text()

    # verify of design.json judges it with the same adjusted model: the same model figures
    check = tmp_path / "check"
    assert main(["verify", str(out / "design.json"), "--mesh", "coarse", "-o", str(check)]) == 0
    again = json.loads((check / "verify.json").read_text())
    assert again["deflection"]["model"] == pytest.approx(record["predicted"]["deflection"], rel=1e-12)
    assert [g["model_strain"] for g in again["gauges"]] == pytest.approx(record["predicted"]["gauge_strain"],
                                                                         rel=1e-12)
    assert again["passed"]


def test_without_rounds_a_design_that_fails_in_3d_is_infeasible_with_its_round(tmp_path, capsys):
    spec = tmp_path / "spec.yaml"
    spec.write_text(STUBBY_LUG, encoding="utf-8")
    out = tmp_path / "out"
    code = main(["optimize", str(spec), "-o", str(out), "--no-cad", "--no-plots", "--quiet", "--verify",
                 "--verify-mesh", "coarse", "--verify-rounds", "0"])
    record = json.loads((out / "design.json").read_text())
    assert code == 1 and record["status"] == "infeasible"
    assert [r["round"] for r in record["verify_rounds"]] == [0]
    assert "deflection" in [c["name"] for c in record["verification"]["limits"] if not c["satisfied"]]
    assert "infeasible in 3-D" in " ".join(record["messages"]) and "FAILS in 3-D" in (out / "report.md").read_text()


def test_a_negative_round_count_is_bad_input(capsys):
    assert main(["optimize", "spec.yaml", "--verify", "--verify-rounds", "-1"]) == 2
    assert "--verify-rounds: -1 is not allowed; must be 0 or more" in capsys.readouterr().err
