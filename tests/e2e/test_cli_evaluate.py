"""``fpdesign evaluate`` and ``fpdesign materials``: design.json (SPEC.md), report.md, the
paper's prototypes against hand calculations, and re-checking a design from its file.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from designer.result import designfile
from designer.result import evaluation
from designer.cli import main

pytestmark = pytest.mark.slow

GF = 9.80665e-3  # N per gram-force
E_2024, E_6061 = 73.1e9, 68.9e9  # Pa, materials/materials.yaml (MatWeb typical values)
SPEC_KEYS = {"version", "status", "spec", "design", "predicted", "constraints", "candidates", "solver"}
DESIGN_KEYS = {"material", "material_properties", "section", "feature", "stations", "length", "bridge", "axes"}
PREDICTED_KEYS = {"force_error", "position_error", "objective", "deflection", "max_stress", "stress_allowable",
                  "gauge_strain", "min_signal_snr", "sensitivity", "noise_strain", "mass", "natural_frequency"}


def run_evaluate(spec_path, out_dir, *extra):
    return main(["evaluate", str(spec_path), "-o", str(out_dir), "--no-cad", "--no-plots", *extra])


@pytest.fixture(scope="module")
def prototype_b(examples, tmp_path_factory):
    """Prototype B evaluated once through the command line: (exit code, stdout, design.json, folder)."""
    out = tmp_path_factory.mktemp("prototype-b")
    code, stdout = _run_capturing(examples / "prototype-b.yaml", out)
    return code, stdout, json.loads((out / "design.json").read_text(encoding="utf-8")), out


def _run_capturing(spec_path, out):
    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stdout(buffer):
        code = run_evaluate(spec_path, out)
    return code, buffer.getvalue()


def test_design_json_has_every_key_of_spec_md(prototype_b):
    code, _, record, out = prototype_b
    # Over its holes Prototype B's gauges read 0.614 of the net-section strain (3-D check,
    # benchmarks/fea_table.md), so sigma_F/F_min = sqrt(2) sigma_V/(k delta F_min) =
    # sqrt(2) 1.3 mV/(0.614 x 0.3446 V/(N m) x 0.08 m x 1.961 N) = 5.5 % > the spec's 4 %
    # target: the design misses it, exit 1 (docs/spec.md §10), and the record is complete.
    assert code == 1
    assert SPEC_KEYS <= record.keys()
    assert record["version"] == 1
    assert record["status"] == "infeasible"
    d, p = record["design"], record["predicted"]
    assert DESIGN_KEYS <= d.keys()
    assert {"E", "yield", "fatigue", "density"} <= d["material_properties"].keys()
    assert d["section"] == {"kind": "rectangle", "width": pytest.approx(0.0127), "height": pytest.approx(0.0127)}
    assert d["feature"] == {"kind": "hole", "diameter": pytest.approx(0.0095)}
    assert d["stations"] == pytest.approx([0.02, 0.10]) and d["length"] == pytest.approx(0.45)
    assert (d["material"], d["bridge"], d["axes"]) == ("2024-T3", "half", 1)
    assert d["material_properties"]["E"] == pytest.approx(E_2024)
    assert PREDICTED_KEYS <= p.keys()
    assert len(p["gauge_strain"]) == len(p["sensitivity"]) == 2
    assert record["constraints"], "no limits were recorded"
    for c in record["constraints"]:
        assert {"name", "value", "limit", "margin", "active"} <= c.keys()
        assert isinstance(c["active"], bool)
    names = {c["name"] for c in record["constraints"]}
    assert {"stress_root", "stress_feature", "gauge_strain", "min_signal_snr", "force_error",
            "position_error"} <= names
    assert record["candidates"] == []
    assert {"method", "seconds", "evaluations"} <= record["solver"].keys()
    assert {"load", "electronics", "gauge", "limits", "targets"} <= record["spec"].keys()
    assert record["spec"]["load"]["position"] == pytest.approx([0.15, 0.45])
    report = (out / "report.md").read_text(encoding="utf-8")
    assert report.startswith("# prototype-b")
    assert "2024-T3" in report and "rectangle 12.70 × 12.70 mm" in report and "through-hole Ø9.50 mm" in report
    assert "stress_feature" in report  # the limits table


def test_prototype_b_predictions_against_hand_calculation(prototype_b):
    # docs/model.md §2-4 by hand for Prototype B (Noh et al. Table 1): 12.7 mm square,
    # 9.5 mm holes at 20 and 100 mm, half bridges, 5 V, gain 1000, G = 2.0, 1.3 mV noise.
    # The reduced section at a hole is b (h^3 - d^3)/12 (the net-section formula). Over a
    # hole the gauge reads less than that formula says: the model's hole correction
    # (docs/model.md §7) must give the 3-D check's 0.614 (benchmarks/fea_table.md, normal
    # mesh, fpdesign verify on this design) within the 3 % the 3-D acceptance allows, at both
    # stations (the first, 1.2 heights from the clamp, reads 0.1 % more: the holes' near-clamp
    # decay). The rest follows from
    # the two k exactly (docs/model.md §3: sigma_F = sigma sqrt(1/k1^2 + 1/k2^2)/delta and
    # sigma_x = sigma sqrt((x - d2)^2/k1^2 + (x - d1)^2/k2^2)/(delta F) for two stations), rel 1e-9.
    _, _, record, _ = prototype_b
    p = record["predicted"]
    b = h = 12.7e-3
    dh, d1, d2, sigma = 9.5e-3, 0.020, 0.100, 1.3e-3
    f_min, f_max, x_min, x_max = 200 * GF, 2000 * GF, 0.150, 0.450
    I, I_s = b * h ** 3 / 12, b * (h ** 3 - dh ** 3) / 12
    k_net = 5 * 2.0 * 1000 * 2 * (h / 2) / (4 * E_2024 * I_s)
    factors = [k / k_net for k in p["sensitivity"]]
    assert factors == pytest.approx([0.614, 0.614], rel=0.03)
    k1, k2 = (k_net * f for f in factors)
    delta = d2 - d1
    assert p["force_error"] == pytest.approx(sigma * math.hypot(1 / k1, 1 / k2) / delta / f_min, rel=1e-9)
    assert p["position_error"] == pytest.approx(sigma * math.hypot((x_max - d2) / k1, (x_max - d1) / k2)
                                                / (delta * f_min), rel=1e-9)
    stress_root = f_max * x_max * (h / 2) / I
    stress_hole = f_max * (x_max - (d1 - dh / 2)) * (h / 2) / I_s  # clamp-side edge of the first hole
    assert p["max_stress"] == pytest.approx(max(stress_root, stress_hole), rel=1e-9)
    assert p["stress_allowable"] == pytest.approx(345e6 / 1.5, rel=1e-9)  # yield / safety factor, no fatigue
    assert p["gauge_strain"] == pytest.approx([f * f_max * (x_max - d) * (h / 2) / (E_2024 * I_s)
                                               for f, d in zip(factors, (d1, d2))], rel=1e-9)
    assert p["min_signal_snr"] == pytest.approx(k2 * f_min * (x_min - d2) / sigma, rel=1e-9)
    # Mean absolute error as the paper reports it: sqrt(2/pi) sigma (docs/model.md §3).
    assert p["mean_abs_force_error"] == pytest.approx(math.sqrt(2 / math.pi) * p["force_error"], rel=1e-12)


def test_prototype_b_summary_is_printed(prototype_b):
    _, stdout, _, out = prototype_b
    assert "prototype-b" in stdout and "feasible" in stdout
    assert f"wrote {out / 'design.json'}" in stdout


def test_doubling_the_gauge_spacing_halves_the_force_error(examples, tmp_path):
    # Noh et al. Fig. 13 (and eq. 35): sigma_F = sqrt(2) sigma_V/(k delta); Prototype B with
    # bridges 40 mm apart (20/60 mm) against 80 mm apart (20/100 mm). The same k (the holes'
    # near-clamp decay, docs/model.md §7, leaves 1e-6 of it at 60 mm), so the ratio is 2 to 1e-6.
    # With the holes' 3-D strain both pairs miss the spec's 4 % force target (5.6 % and 11 %):
    # exit 1, and design.json still records the design and what it violates.
    records = {}
    for name in ("prototype-b-inner", "prototype-b"):
        out = tmp_path / name
        code = run_evaluate(examples / f"{name}.yaml", out)
        records[name] = (code, json.loads((out / "design.json").read_text(encoding="utf-8")))
    (code_40, inner), (code_80, outer) = records["prototype-b-inner"], records["prototype-b"]
    assert inner["predicted"]["force_error"] == pytest.approx(2 * outer["predicted"]["force_error"], rel=1e-6)
    assert inner["predicted"]["position_error"] > 1.9 * outer["predicted"]["position_error"]
    assert (code_40, code_80) == (1, 1)
    assert inner["status"] == "infeasible"
    assert any("violates" in m and "force_error" in m for m in inner["messages"])
    violated = {c["name"] for c in inner["constraints"] if c["margin"] < 0}
    assert violated == {"force_error", "position_error"}


def test_prototype_a_deflects_a_third_of_its_length_and_says_so(examples, tmp_path):
    # Prototype A (Noh et al. Table 1): 6061-T6, 50 x 3.18 mm, 800 mm, 2000 g at 650 mm.
    # Linear theory (Gere & Goodno Table H-1): w = F x^2 (3l - x)/(6EI) = 0.327 l (0.325 l with the
    # clamp's plate effect of docs/model.md §4). The paper
    # measured 26.5 % (section 6): past 10 % the linear model overestimates, hence the warning,
    # which must reach both design.json and the terminal.
    out = tmp_path / "a"
    code, stdout = _run_capturing(examples / "prototype-a.yaml", out)
    record = json.loads((out / "design.json").read_text(encoding="utf-8"))
    # The clamp's restraint of the wide plate (docs/model.md §7, 3-D: 0.93 at station 1) costs the
    # paper's design its 4 % position target, by a fraction of a percent: exit 1 for that alone
    assert code == 1 and {c["name"] for c in record["constraints"] if not c["satisfied"]} == {"position_error"}
    b, h, ell, x, f = 0.050, 3.18e-3, 0.800, 0.650, 2000 * GF
    EI = E_6061 * b * h ** 3 / 12
    linear = f * x ** 2 * (3 * ell - x) / (6 * EI)
    # plus the plain bar's stiffness terms (docs/model.md §4) with the shipped fit's constants:
    # the clamp's plate effect, a curvature deficit A(w) exp(-s / (reach b)) integrated by
    # quadrature, and Timoshenko's shear with Cowper's kappa (nu = 0.33)
    from scipy import integrate

    from designer.model import corrections

    fit = corrections.stiffness_fit(corrections.load())
    w, nu = b / h, 0.33
    amplitude = fit.plate * (1 - math.exp(-((w - 1) / fit.w0) ** 2))
    plate = f * amplitude * integrate.quad(lambda s: math.exp(-s / (fit.reach * b)) * (x - s) * (ell - s), 0, x,
                                           limit=200)[0] / EI
    kappa = 10 * (1 + nu) / (12 + 11 * nu)
    shear = fit.shear * f * x / (kappa * E_6061 / (2 * (1 + nu)) * b * h)
    expected = (linear - plate + shear) / ell
    assert 0.99 * linear / ell < expected < linear / ell     # the plate effect: -0.7 %
    assert record["predicted"]["deflection_ratio"] == pytest.approx(expected, rel=1e-6)
    warnings = [m for m in record["messages"] if m.startswith("warning") and "deflect" in m]
    assert len(warnings) == 1 and "32.5%" in warnings[0] and "small-deflection" in warnings[0]
    flat = " ".join(stdout.split())  # the terminal table wraps long lines
    assert "warning: the free end deflects 32.5% of the free length" in flat
    assert "32.5%" in (out / "report.md").read_text(encoding="utf-8")


def test_prototype_b_has_no_large_deflection_warning(prototype_b):
    _, _, record, _ = prototype_b
    assert record["predicted"]["deflection_ratio"] < 0.10
    assert not any("deflect" in m for m in record["messages"])


POCKET_SPECS = {
    # A pocketed rectangle and a biaxial tube with flats: designs the optimiser writes.
    "rectangle pocket": """
load: {force: [0.5 N, 20 N], position: [40 mm, 110 mm]}
electronics: {excitation: 5 V, gain: 128, noise_rti: 50 nV}
gauge: {name: BF350-3AA, factor: 2.13}
limits: {safety_factor: 2.5, min_snr: 3, max_deflection: 1 mm}
design:
  material: 7075-T6
  section: {kind: rectangle, width: 10 mm, height: 4 mm}
  stations: [10 mm, 25 mm]
  feature: {kind: pocket, depth: 0.8 mm, length: 9.5 mm, width: 6 mm}
""",
    "biaxial tube flats": """
load: {force: [2 N, 20 N], position: [100 mm, 200 mm]}
electronics: {excitation: 5 V, gain: 1000, noise: 1.3 mV}
axes: 2
bridge: full
targets: {force_error: 5 %, position_error: 5 mm}
design:
  material: 6061-T6
  section: {kind: tube, diameter: 16 mm, wall: 2.5 mm}
  stations: [12 mm, 60 mm]
  feature: {kind: pocket, depth: 0.6 mm}
""",
}


# The exit code each design must give (0 feasible, 1 infeasible), by hand:
# - the three prototypes meet their limits and targets (exit 0, as the tests above and
#   test_a_biaxial_design_records_two_axes assert for each);
# - "rectangle pocket": root stress 6 F x/(b h^2) = 6 x 20 N x 110 mm/(10 x 4^2 mm^3) = 82.5 MPa
#   (Gere & Goodno) against 7075-T6's fatigue strength 159 MPa / 2.5 = 63.6 MPa: exit 1;
# - "biaxial tube flats": sigma_x = sigma_V sqrt((x - d1)^2 + (x - d2)^2)/(k delta F) (MODEL.md 3)
#   at 2 N and 200 mm with the plain tube's k = V_s G g n y/(4 E I) = 5 x 2 x 1000 x 4 x 8 mm /
#   (4 x 68.9 GPa x pi (16^4 - 11^4)/64 mm^4) = 0.465 V/(N m) is 1.3 mV x 234 mm/(0.465 x 48 mm x
#   2 N) = 6.8 mm; 0.6 mm flats change k by a few per cent, and 5 mm would take 37 % more: exit 1.
# Prototype B misses its 4 % force target once the holes' 3-D strain is modelled (5.5 %, see
# test_design_json_has_every_key_of_spec_md).
EXPECTED_CODE = {"prototype-a": 1, "prototype-b": 1, "prototype-c": 0, "rectangle pocket": 1,
                 "biaxial tube flats": 1}


@pytest.mark.parametrize("source", ["prototype-a", "prototype-b", "prototype-c", *POCKET_SPECS])
def test_reevaluating_from_design_json_alone_gives_the_same_predictions(source, examples, tmp_path):
    # design.json must describe the design completely (SPEC.md): rebuild it from the file and
    # evaluate again. The file holds the SI floats themselves: equal to rel 1e-12.
    if source in POCKET_SPECS:
        spec_path = tmp_path / "spec.yaml"
        spec_path.write_text(POCKET_SPECS[source], encoding="utf-8")
    else:
        spec_path = examples / f"{source}.yaml"
    out = tmp_path / "out"
    assert run_evaluate(spec_path, out) == EXPECTED_CODE[source]
    record = designfile.load_design(out / "design.json")
    spec, design = designfile.rebuild(record)
    again = evaluation.evaluate(design, spec)
    predicted = again.predicted()
    for key, value in record["predicted"].items():
        assert predicted[key] == pytest.approx(value, rel=1e-12, abs=1e-300), key
    assert [c["name"] for c in again.constraint_records()] == [c["name"] for c in record["constraints"]]
    for mine, theirs in zip(again.constraint_records(), record["constraints"]):
        assert mine["value"] == pytest.approx(theirs["value"], rel=1e-12, abs=1e-15), mine["name"]
        assert mine["satisfied"] == theirs["satisfied"]
    assert again.feasible == (record["status"] == "feasible")
    if source == "rectangle pocket":  # the non-default choices survive the round trip
        g = design.geometry
        assert (g.pocket_length, g.pocket_width) == pytest.approx((9.5e-3, 6e-3), rel=1e-12)
        assert spec.gauge.factor == 2.13 and spec.limits.safety_factor == 2.5


def test_the_reported_design_is_rounded_to_a_hundredth_of_a_millimetre(tmp_path):
    # MODEL.md section 5: what is reported is what was checked, at 0.01 mm.
    spec_path = tmp_path / "spec.yaml"
    spec_path.write_text(POCKET_SPECS["rectangle pocket"].replace("10 mm, 25 mm", "10.0042 mm, 25.0061 mm")
                         .replace("depth: 0.8 mm", "depth: 0.8049 mm"), encoding="utf-8")
    out = tmp_path / "out"
    run_evaluate(spec_path, out)
    d = json.loads((out / "design.json").read_text(encoding="utf-8"))["design"]
    assert d["stations"] == pytest.approx([0.01, 0.02501], abs=1e-12)
    assert d["feature"]["depth"] == pytest.approx(0.0008, abs=1e-12)


def test_a_biaxial_design_records_two_axes(examples, tmp_path):
    out = tmp_path / "c"
    assert run_evaluate(examples / "prototype-c.yaml", out) == 0
    record = json.loads((out / "design.json").read_text(encoding="utf-8"))
    assert record["design"]["axes"] == 2
    assert record["design"]["section"] == {"kind": "tube", "diameter": pytest.approx(0.0127),
                                           "wall": pytest.approx(0.00165)}


# ----------------------------------------------------------------- fpdesign materials

REQUIRED_MATERIALS = {"6061-T6", "2024-T3", "7075-T6", "17-4PH-H900", "Ti-6Al-4V", "C17200", "304"}


def test_materials_json_from_another_folder(tmp_path):
    # The catalogue ships as package data: the command must find it whatever the working folder.
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    done = subprocess.run([sys.executable, "-m", "designer.cli", "materials", "--json"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    listing = json.loads(done.stdout)
    materials = {m["name"]: m for m in listing["materials"]}
    gauges = {g["name"]: g for g in listing["gauges"]}
    assert len(materials) >= 8 and REQUIRED_MATERIALS <= materials.keys()
    assert any("spring" in m["description"].lower() for m in materials.values())
    assert len(gauges) >= 3 and {"BF120-3AA", "BF350-3AA"} <= gauges.keys()
    for entry in [*materials.values(), *gauges.values()]:
        assert entry["source"].strip(), f"{entry['name']} has no source"
    # SI in the JSON: 6061-T6 at 68.9 GPa and 2700 kg/m^3 (MatWeb), the BF120-3AA backing 6.9 mm.
    assert materials["6061-T6"]["E"] == pytest.approx(68.9e9) and materials["6061-T6"]["density"] == 2700
    assert gauges["BF120-3AA"]["length"] == pytest.approx(6.9e-3)
    # the stock tables, each with its source, its family's materials and its rows in SI: EN 754-3's
    # Ø10 mm drawn aluminium round bar is 0.010 m, ASTM B211's Ø3/8 in one 9.525 mm (25.4 mm/in)
    stock = {t["name"]: t for t in listing["stock"]}
    assert all(t["source"].strip() and t["items"] for t in stock.values())
    assert "6061-T6" in stock["al-round-metric"]["materials"]
    rows = {i["designation"]: i["sizes"] for t in stock.values() for i in t["items"]}
    assert rows["Ø10 mm"] == [pytest.approx(0.010)] and rows["Ø3/8 in"] == [pytest.approx(9.525e-3)]


def test_materials_table_from_another_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("COLUMNS", "300")  # one row per entry in the terminal table
    assert main(["materials"]) == 0
    out = capsys.readouterr().out
    for name in [*REQUIRED_MATERIALS, "BF120-3AA", "BF350-3AA", "al-round-metric", "EN 754-3"]:
        assert name in out


# ----------------------------------------------------------------- a damaged design.json
# `fpdesign simulate design.json` rebuilds the design from the file (designfile.rebuild) and
# evaluates it again; every damage below must stop it with exit 2 and a one-line message.

BAD_RECORDS = {
    # id: (change to Prototype B's design.json, words the message must contain)
    "spec not an object": (lambda r: r.update(spec=["prototype-b"]), ["spec", "['prototype-b']", "object"]),
    "electronics not a mapping": (lambda r: r["spec"].update(electronics="5 V"), ["spec.electronics", "5 V"]),
    "section kind a list": (lambda r: r["design"]["section"].update(kind=["rectangle"]),
                            ["design.section.kind", "['rectangle']", "rectangle"]),
    "feature kind unknown": (lambda r: r["design"]["feature"].update(kind="slot"), ["design.feature.kind", "slot"]),
    "length missing": (lambda r: r["design"].pop("length"), ["design.length", "missing"]),
    "negative width": (lambda r: r["design"]["section"].update(width=-0.01), ["design.section.width", "-0.01"]),
    "station off the beam": (lambda r: r["design"].update(stations=[0.02, 0.5]), ["design.stations[1]", "0.5"]),
    "stations reversed": (lambda r: r["design"].update(stations=[0.1, 0.02]), ["design.stations", "increase"]),
    "three axes": (lambda r: r["design"].update(axes=3), ["design.axes", "3"]),
    "predictions missing": (lambda r: r.pop("predicted"), None),  # simulate re-evaluates: exit 0
    "a reversed load in the spec": (lambda r: r["spec"]["load"].update(force=[19.6, 1.96]),
                                    ["spec.load.force", "19.6", "reversed"]),
}


@pytest.mark.parametrize("case", list(BAD_RECORDS))
def test_a_damaged_design_json_exits_2_with_a_one_line_message(case, prototype_b, tmp_path, capsys):
    _, _, record, _ = prototype_b
    damaged = json.loads(json.dumps(record))
    change, words = BAD_RECORDS[case]
    change(damaged)
    path = tmp_path / "design.json"
    path.write_text(json.dumps(damaged), encoding="utf-8")
    code = main(["simulate", str(path), "--draws", "100", "--grid", "2", "2"])
    err = capsys.readouterr().err
    if words is None:
        assert code == 0 and not err
        return
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("fpdesign: error: ") and "Traceback" not in err
    for word in words:
        assert word in lines[0], f"{word!r} missing from: {lines[0]}"


def test_a_design_json_that_is_not_json_exits_2(tmp_path, capsys):
    path = tmp_path / "design.json"
    path.write_text('{"version": 1,\n "spec": {', encoding="utf-8")
    assert main(["simulate", str(path)]) == 2
    err = capsys.readouterr().err
    assert "not valid JSON at line 2" in err


def test_an_output_path_that_is_a_file_exits_2(examples, tmp_path, capsys):
    target = tmp_path / "taken"
    target.write_text("keep me", encoding="utf-8")
    assert run_evaluate(examples / "prototype-b.yaml", target) == 2
    err = capsys.readouterr().err
    assert "-o" in err and str(target) in err and "not a folder" in err
    assert target.read_text(encoding="utf-8") == "keep me"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]  # no scratch folder left behind


def _stderr_on_a_terminal(args: list[str], cwd) -> str:
    """What ``fpdesign ARGS`` writes to standard error when that is a terminal (a pseudo-terminal
    of this test's, read while the command runs so that its output never fills the terminal's
    buffer), with standard output to a pipe."""
    import pty
    import threading

    main_fd, term = pty.openpty()
    chunks = []

    def read():
        while True:
            try:
                chunk = os.read(main_fd, 65536)
            except OSError:     # the terminal's other end closed: everything was read
                return
            if not chunk:
                return
            chunks.append(chunk)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        done = subprocess.run([sys.executable, "-m", "designer.cli", *args], cwd=cwd, stderr=term,
                              stdout=subprocess.PIPE, timeout=300, env={**os.environ, "COLUMNS": "100"})
    finally:
        os.close(term)
        reader.join(timeout=10)
        os.close(main_fd)
    assert done.returncode in (0, 1), done.stdout    # (1: the design breaks a limit; written all the same)
    return b"".join(chunks).decode("utf-8", "replace")


@pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX's")
def test_evaluate_shows_its_stages_on_a_terminal_and_nothing_with_quiet(examples, tmp_path):
    # docs/spec.md section 9: a progress bar on standard error names each stage while it runs, and
    # is not drawn with --quiet; the evaluate command writes plots, so the bar names that stage
    spec = str(examples / "prototype-b.yaml")
    shown = _stderr_on_a_terminal(["evaluate", spec, "-o", "shown", "--no-cad"], tmp_path)
    assert "plots" in shown
    quiet = _stderr_on_a_terminal(["evaluate", spec, "-o", "quiet", "--no-cad", "--quiet"], tmp_path)
    assert "plots" not in quiet and "evaluating" not in quiet
    for out in ("shown", "quiet"):
        assert (tmp_path / out / "error-maps.png").is_file()


@pytest.mark.skipif(sys.platform == "win32", reason="pseudo-terminals are POSIX's")
def test_optimize_shows_its_search_on_a_terminal_with_standard_output_redirected(examples, tmp_path):
    # the bar is on standard error: shown when that is a terminal, wherever standard output goes
    spec = str(examples / "gripper-finger.yaml")
    shown = _stderr_on_a_terminal(["optimize", spec, "-o", "out", "--no-cad", "--no-plots"], tmp_path)
    assert "search" in shown
