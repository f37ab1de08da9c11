"""README.md and docs/spec.md against the code: the defaults and formats they state."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from designer.spec.reader import Limits, parse_spec

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
LOAD = {"load": {"force": ["1 N", "20 N"], "position": ["100 mm", "300 mm"]},
        "electronics": {"excitation": "5 V", "gain": 500, "noise": "1 mV"}}


def _readme_spec_block() -> str:
    start = README.index("### spec.yaml")
    return README[README.index("```yaml", start) + 7:README.index("```", README.index("```yaml", start) + 7)]


def test_readme_limits_are_the_code_defaults_and_name_no_default_deflection_or_frequency():
    block = _readme_spec_block()
    text = re.search(r"limits: (\{.*?\})", block, re.S).group(1)
    shown = yaml.safe_load(re.sub(r",\s*\.\.\.", "", text))
    assert "max_deflection" not in shown and "min_frequency" not in shown
    defaults = parse_spec(dict(LOAD)).limits
    assert defaults.max_deflection is None and defaults.min_frequency is None
    assert parse_spec(dict(LOAD, limits=shown)).limits == defaults == Limits()


def test_readme_design_block_reads_and_sets_the_free_length():
    block = _readme_spec_block()
    text = re.search(r"^design: (\{.*?\})\n\s+#", block, re.S | re.M).group(1)
    design = yaml.safe_load(text)
    spec = parse_spec(dict(LOAD, design=design))
    assert spec.free_length == spec.design.length == 0.31
    # without a length: x_max + tip_margin, as README and docs/spec.md §2.1 say
    design.pop("length")
    spec = parse_spec(dict(LOAD, design=design))
    assert spec.free_length == spec.load.position_max + spec.limits.tip_margin
    assert "x_max + limits.tip_margin" in README


def test_readings_are_volts_after_the_gain():
    """README and docs/spec.md §7: readings are the amplifier's output. Doubling the gain
    doubles the design's k (V/(N m)), and the k that calibrate fits to readings simulated of
    the design: the readings carry the gain."""
    import numpy as np

    from designer import calibration as cal
    from designer.calibration import readings as rd
    from designer.result.evaluation import evaluate, fixed_design
    from designer.result.record import build_record

    assert "after the gain" in README and "after the gain" in (ROOT / "docs" / "spec.md").read_text()
    design = yaml.safe_load(re.search(r"^design: (\{.*?\})\n\s+#", _readme_spec_block(), re.S | re.M).group(1))
    fitted = {}
    for gain in (500, 1000):
        raw = dict(LOAD, design=design, electronics={"excitation": "5 V", "gain": gain, "noise_rti": "1 uV"})
        spec = parse_spec(raw)
        ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
        record = build_record("feasible" if ev.feasible else "infeasible", spec, ev)
        c = cal.calibrate(rd.simulated_scheme_readings(record, "grid", seed=3), cal.design_constants(record))
        fitted[gain] = (np.asarray(record["predicted"]["sensitivity"]), np.array([b.k for b in c.bridges]),
                        np.array([b.se_k for b in c.bridges]))
    (k1, f1, s1), (k2, f2, s2) = fitted[500], fitted[1000]
    assert k2 == pytest.approx(2 * k1, rel=1e-12)
    assert np.all(np.abs(f1 - k1) < 5 * s1) and np.all(np.abs(f2 - k2) < 5 * s2)


def test_the_model_docs_table_of_corrections_is_the_shipped_table():
    # docs/model.md §7 lists every shipped fit with its largest left-out residual and its shift to
    # the safe side: the table must say what materials/corrections.yaml holds
    from designer.model import corrections

    text = (ROOT / "docs" / "model.md").read_text(encoding="utf-8")
    rows = [line for line in text.splitlines() if line.startswith("| ")
            and any(unit in line for unit in ("% of the factor", "% of the deflection", "% of K_t"))]
    names = {"strain": "`C_ε`", "extra_length": "`Δ`", "stress": "`K_t`", "stress_face": "`K_t` at the rim",
             "clamp": "`C_c`", "near_clamp": "`C_n`", "stiffness": "`φ`, `A`"}
    families = {"rectangle-hole": "rectangle + hole", "rectangle-pocket": "rectangle + slot",
                "round-pocket": "round + flat", "tube-pocket": "tube + flat", "round-none": "round bar",
                "tube-none": "tube", "plain": "every family"}
    table = corrections.load()
    shipped = [(fam, q, f) for fam, qs in table.fits.items() for q, f in qs.items()]
    assert len(rows) == len(shipped)
    for fam, q, f in shipped:
        row = next(r for r in rows if r.startswith(f"| {families[fam]} | {names[q]} |"))
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[5].startswith(f"{f.loo_max:.1%}"), (fam, q, cells[5])
        margin = getattr(f, "margin", 0.0)
        expected = "–" if not margin else (f"×{1 + margin:.3f}" if q.startswith("stress") else f"+{margin:.3f} sizes")
        assert cells[6] == expected, (fam, q, cells[6])


def test_the_readme_s_error_budget_is_the_budget_example_s():
    """README "The whole error budget": the design it names, evaluated under
    examples/budget/gripper-finger-hx711.yaml, has the combined errors and span drift it states."""
    from designer.result.evaluation import evaluate, fixed_design
    from designer.result.record import build_record

    section = README[README.index("## The whole error budget"):README.index("## Compared with the paper")]
    raw = yaml.safe_load((ROOT / "examples" / "budget" / "gripper-finger-hx711.yaml").read_text(encoding="utf-8"))
    raw["design"] = {"material": "17-7PH-RH950", "section": {"kind": "round", "diameter": "7.09 mm"},
                     "stations": ["9.46 mm", "30.55 mm"], "feature": {"kind": "pocket", "depth": "1.35 mm"}}
    assert "17-7PH-RH950 round Ø7.09 mm, flats 1.35 mm deep" in section
    spec = parse_spec(raw)
    ev = evaluate(fixed_design(spec), spec)
    b = build_record("feasible", spec, ev)["predicted"]["budget"]
    terms = {t["name"]: t["u"] for t in b["force"]["terms"]}
    assert f"**{b['force']['combined'] * 100:.3f} %**" in section
    assert f"{terms['span drift'] * 100:.3f} %" in section
    assert f"**{b['position']['combined'] * 1e3:.3f} mm**" in section


def test_the_spec_docs_give_the_length_the_file_names_are_cut_to():
    from designer.outputs.part import MAX_FILE_STEM

    text = (ROOT / "docs" / "spec.md").read_text(encoding="utf-8")
    stated = re.search(r"at most its first (\d+)\s+characters", text)
    assert stated and int(stated.group(1)) == MAX_FILE_STEM
