"""``fpdesign plan``, ``simulate-readings``, ``calibrate`` and ``measure`` as whole commands
(issue 6): a round trip through the files, and bad input refused with exit 2, nothing written.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from designer import calibration as cal
from designer.calibration import readings as rd
from designer.cli import main

pytestmark = pytest.mark.slow

from shared_inputs import calibration_record as record, clean_prototype_b as _clean_b

DATA = Path(__file__).resolve().parents[1] / "data"


def test_plan_command_writes_grams_and_millimetres(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    assert main(["plan", str(DATA / "cal_prototype_a.json"), "-o", str(out), "--repeats", "2"]) == 0
    text = capsys.readouterr().out
    assert "4-point" in text and "9-point" in text
    rows = [line.split(",") for line in out.read_text().splitlines() if not line.startswith("#")]
    header, body = rows[0], rows[1:]
    assert header == ["scheme", "point", "repeat", "mass_g", "force_N", "position_mm"]
    assert len(body) == 2 * (4 + 9)
    corners = {(float(r[3]), float(r[5])) for r in body if r[0] == "4"}
    assert corners == {(250, 150), (250, 650), (2000, 150), (2000, 650)}
    middles = {(float(r[3]), float(r[5])) for r in body if r[0] == "9"} - corners
    assert (1125, 400) in middles


# --------------------------------------------------------------------- commands: round trip

@pytest.mark.parametrize("key", ("b", "c"))
def test_commands_round_trip(tmp_path, capsys, key):
    design = str(DATA / f"cal_prototype_{key}.json")
    cal_csv, test_csv = tmp_path / "cal.csv", tmp_path / "test.csv"
    cal_json, results = tmp_path / "calibration.json", tmp_path / "results.csv"
    assert main(["simulate-readings", design, "-o", str(cal_csv), "--scheme", "9", "--seed", "4",
                 "--repeats", "2"]) == 0
    assert main(["simulate-readings", design, "-o", str(test_csv), "--seed", "4"]) == 0
    assert main(["calibrate", str(cal_csv), "--design", design, "-o", str(cal_json)]) == 0
    out = capsys.readouterr().out
    assert "R²" in out and "V1" in out and "warning" not in out
    saved = json.loads(cal_json.read_text())
    assert saved["points"] == (18 if key == "b" else 36) and saved["axes"] == (1 if key == "b" else 2)
    for b in saved["bridges"]:
        assert {"k", "d", "c", "se_k", "se_d", "se_c", "r2", "residual_rms", "design_k"} <= set(b)
        assert abs(b["k"] - b["design_k"]) < 3 * b["se_k"] and abs(b["d"] - b["design_d"]) < 3 * b["se_d"]
    assert main(["measure", str(cal_json), str(test_csv), "-o", str(results)]) == 0
    lines = results.read_text().splitlines()
    truth = rd.read_readings(test_csv)
    assert len(lines) == 1 + len(truth)
    header = lines[0].split(",")
    assert header[:5] == ["row", "force_N", "sigma_force_N", "position_mm", "sigma_position_mm"]
    assert ("angle_deg" in header) == (key == "c")
    values = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    col = {name: values[:, i] for i, name in enumerate(header)}
    assert np.all(np.abs(col["force_N"] - truth.force) < 4.5 * col["sigma_force_N"])
    if key == "c":
        err = np.abs(col["angle_deg"] - np.degrees(truth.angle))
        assert np.all(err < 4.5 * col["sigma_angle_deg"])
    # without -o the rows are printed
    assert main(["measure", str(cal_json), str(test_csv)]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    # the paper's Table 4 measure, to 3 significant digits (it had read "0.00%" for a good sensor)
    loaded = np.abs(truth.force) > 0
    mean_force = float(np.mean(np.abs(col["force_N"] - truth.force)[loaded] / np.abs(truth.force[loaded])))
    assert f"mean absolute error force {mean_force * 100:.3g} %," in printed
    # --noise overrides the calibration's sigma_V: every 1-sigma scales with it
    sigmas = []
    for noise in ("1.3 mV", "2.6mV"):
        assert main(["measure", str(cal_json), str(test_csv), "-o", str(results), "--noise", noise]) == 0
        sigmas.append(np.array([float(line.split(",")[2]) for line in results.read_text().splitlines()[1:]]))
    assert sigmas[1] == pytest.approx(2 * sigmas[0], rel=1e-5)   # 6 significant digits in the CSV


def test_measure_gives_the_errors_over_their_predicted_sigma_and_warns_when_the_readings_do_not_fit(
        tmp_path, capsys):
    """measure's check against the file's loads in units of each row's predicted 1σ (noise and
    calibration). Monte Carlo reference: where the 1σ is right the mean square of (estimate - load)
    / 1σ is 1, times dof/(dof - 2) = 45/43 for sigma_V estimated from the residuals (18 loads x 3
    bridges - 9 constants); over 40 simulated Prototype B sensors, each calibrated on the 9-point
    scheme twice and measured at the paper's loads, it lies within about 4 standard errors (0.06) of
    that. Readings whose first bridge's zero has moved by 10 sigma_V since calibrating miss by far
    more (about 7 times their 1σ), and are warned of."""
    from designer.calibration.measurement import error_ratios

    design = str(DATA / "cal_prototype_b.json")
    rec = rd.read_design(design)
    squares = []
    for seed in range(40):
        fitted = cal.calibrate(rd.simulated_scheme_readings(rec, "9", seed, 2), cal.design_constants(rec))
        data = rd.simulated_scheme_readings(rec, "paper", seed)
        squares.append(np.square(error_ratios(cal.measure_readings(fitted, data), data.force, data.position)))
    assert np.mean(squares, axis=0) == pytest.approx(45 / 43, abs=0.25)

    cal_csv, test_csv, other_csv = tmp_path / "cal.csv", tmp_path / "test.csv", tmp_path / "other.csv"
    cal_json, results = tmp_path / "calibration.json", tmp_path / "results.csv"
    assert main(["simulate-readings", design, "-o", str(cal_csv), "--scheme", "9", "--seed", "2", "--repeats",
                 "2"]) == 0
    assert main(["simulate-readings", design, "-o", str(test_csv), "--seed", "2"]) == 0
    assert main(["calibrate", str(cal_csv), "--design", design, "-o", str(cal_json)]) == 0
    sigma_v = json.loads(cal_json.read_text())["noise"]["sigma_v"]
    loads = rd.read_readings(test_csv)
    moved = rd.simulated_sensor_offsets(rec, 2) + np.array([10 * sigma_v, 0, 0])
    rd.write_readings(other_csv, rd.simulate_readings(rec, loads.force, loads.position, np.random.default_rng(5),
                                                      offsets=moved))
    capsys.readouterr()
    assert main(["measure", str(cal_json), str(test_csv), "-o", str(results)]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    # the printed figures are those of the written rows: (estimate - load) / 1σ from results.csv
    lines = results.read_text().splitlines()
    values = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    truth = rd.read_readings(test_csv)
    z_force = (values[:, 1] - truth.force) / values[:, 2]
    z_position = (values[:, 3] - truth.position * 1e3) / values[:, 4]
    rms = [float(np.sqrt(np.mean(z ** 2))) for z in (z_force, z_position)]
    assert f"errors over their predicted 1σ, RMS: force {rms[0]:.3g}, position {rms[1]:.3g}" in printed
    assert "the estimates miss" not in printed
    assert main(["measure", str(cal_json), str(other_csv), "-o", str(results)]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    assert "warning: the estimates miss the file's loads by" in printed and "another sensor" in printed


def test_measure_checks_a_biaxial_sensors_angle_and_warns_when_it_has_turned(tmp_path, capsys):
    """A biaxial sensor turned about its axis since calibrating reads the force and the position as
    calibrated (the load's magnitude and place do not change) and only its angle wrong; measure's
    check takes the angle's error over its predicted 1σ too. Monte Carlo reference as for the
    uniaxial check: over 40 simulated Prototype C sensors, calibrated on the 9-point scheme twice
    (36 rows x 4 bridges - 12 constants = 132 degrees of freedom) and measured at the paper's 210
    loads (section 4.2.1's angles), the mean square of each ratio is 132/130 within about 4
    standard errors; turned by 3° (about 9 times the angle's 1σ of 0.3° at the paper's loads) only
    the angle's ratio rises, and measure warns that the sensor has turned."""
    from designer.calibration.measurement import error_ratios

    design = str(DATA / "cal_prototype_c.json")
    rec = rd.read_design(design)
    turn = np.radians(3.0)
    squares, turned = [], []
    for seed in range(40):
        fitted = cal.calibrate(rd.simulated_scheme_readings(rec, "9", seed, 2), cal.design_constants(rec))
        loads = rd.simulated_scheme_readings(rec, "paper", seed)
        squares.append(np.square(error_ratios(cal.measure_readings(fitted, loads), loads.force, loads.position,
                                              loads.angle)))
        data = rd.simulate_readings(rec, loads.force, loads.position, np.random.default_rng([seed, 7]),
                                    angles=loads.angle + turn, offsets=rd.simulated_sensor_offsets(rec, seed))
        turned.append(error_ratios(cal.measure_readings(fitted, data), loads.force, loads.position, loads.angle))
    assert np.mean(squares, axis=0) == pytest.approx(np.full(3, 132 / 130), abs=0.15)
    turned = np.array(turned)
    assert np.all(turned[:, :2] < 1.5) and np.all(turned[:, 2] > 3 * 2)

    cal_csv, test_csv, turned_csv = tmp_path / "cal.csv", tmp_path / "test.csv", tmp_path / "turned.csv"
    cal_json = tmp_path / "calibration.json"
    assert main(["simulate-readings", design, "-o", str(cal_csv), "--scheme", "9", "--seed", "2", "--repeats",
                 "2"]) == 0
    assert main(["simulate-readings", design, "-o", str(test_csv), "--seed", "2"]) == 0
    assert main(["calibrate", str(cal_csv), "--design", design, "-o", str(cal_json)]) == 0
    loads = rd.read_readings(test_csv)
    # the file states the angles the loads were meant to have; the turned sensor felt them 3° on
    felt = rd.simulate_readings(rec, loads.force, loads.position, np.random.default_rng(5), angles=loads.angle + turn,
                                offsets=rd.simulated_sensor_offsets(rec, 2))
    rd.write_readings(turned_csv, dataclasses.replace(felt, angle=loads.angle))
    capsys.readouterr()
    assert main(["measure", str(cal_json), str(test_csv)]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    assert ", angle " in printed.split("errors over their predicted 1σ")[1] and "the estimates miss" not in printed
    assert main(["measure", str(cal_json), str(turned_csv)]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    assert "warning: the estimates miss the file's loads by" in printed and "(RMS, the angle;" in printed
    assert "turned about its axis" in printed


def test_calibrate_prints_warnings(tmp_path, capsys):
    rec = record("a")
    three = rd.simulate_readings(rec, [2.0, 10.0, 19.0], [0.15, 0.65, 0.3], np.random.default_rng(1))
    src = rd.write_readings(tmp_path / "three.csv", three)
    out = tmp_path / "c.json"
    assert main(["calibrate", str(src), "--design", str(DATA / "cal_prototype_a.json"), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "warning: only 3 calibration points" in printed
    assert json.loads(out.read_text())["warnings"][0].startswith("only 3 calibration points")


B_HEADER = "mass_g,position_mm,V1,V2,V3"
GOOD_ROWS = ["20,150,0.003,0.004,0.005", "3000,150,1.3,0.9,0.5", "20,450,0.03,0.025,0.027",
             "3000,450,4.3,3.9,3.5"]


def _csv(*lines):
    return "\n".join(lines) + "\n"


BAD_CALIBRATION_CSVS = {
    "empty file": ("", ["empty"]),
    "header only": (_csv(B_HEADER), ["no data rows"]),
    "missing position column": (_csv("mass_g,V1,V2,V3", "20,0.1,0.2,0.3"), ["column position_mm missing"]),
    "no bridge columns": (_csv("mass_g,position_mm", "20,150"), ["line 1", "no bridge columns"]),
    "unknown column": (_csv("mass_g,positon_mm,V1,V2,V3", "20,150,1,2,3"), ["line 1", "'positon_mm'",
                                                                              "not a known column"]),
    "duplicate column": (_csv("mass_g,position_mm,V1,V2,V2", "20,150,1,2,3"), ["line 1", "'V2'", "twice"]),
    "gap in bridges": (_csv("mass_g,position_mm,V1,V3", "20,150,1,2"), ["line 1", "['V1', 'V3']", "without gaps"]),
    "non-numeric cell": (_csv(B_HEADER, GOOD_ROWS[0], "3000,150,1.3,abc,0.5", *GOOD_ROWS[2:]),
                         ["line 3", "column V2", "'abc' is not a number"]),
    "NaN": (_csv(B_HEADER, *GOOD_ROWS[:3], "3000,450,4.3,nan,3.5"), ["line 5", "column V2", "not a finite"]),
    # Python's float reads "30_00" as 3000 and Arabic-Indic digits as numbers: a cell holds ASCII decimals
    "digit separator": (_csv(B_HEADER, GOOD_ROWS[0], "30_00,150,1.3,0.9,0.5", *GOOD_ROWS[2:]),
                        ["line 3", "column mass_g", "'30_00' is not a number"]),
    "other script's digits": (_csv(B_HEADER, GOOD_ROWS[0], "3000,\u0661\u0665\u0660,1.3,0.9,0.5", *GOOD_ROWS[2:]),
                              ["line 3", "column position_mm", "is not a number"]),
    "empty cell": (_csv(B_HEADER, *GOOD_ROWS[:2], "20,,0.03,0.025,0.027", GOOD_ROWS[3]),
                   ["line 4", "column position_mm", "empty"]),
    "ragged row": (_csv(B_HEADER, GOOD_ROWS[0], "3000,150,1.3,0.9", *GOOD_ROWS[2:]), ["line 3", "4 cells"]),
    "negative mass": (_csv(B_HEADER, GOOD_ROWS[0], "-3000,150,1.3,0.9,0.5", *GOOD_ROWS[2:]),
                      ["line 3", "column mass_g", "negative"]),
    "fewer than 3 points": (_csv(B_HEADER, *GOOD_ROWS[:2]), ["2 data rows", "at least 3"]),
    "all at one position": (_csv(B_HEADER, GOOD_ROWS[0], GOOD_ROWS[1], "1500,150,0.6,0.5,0.2"),
                            ["line 2 to line 4", "column position_mm", "one position (150 mm)"]),
    "all at one force": (_csv(B_HEADER, GOOD_ROWS[1], GOOD_ROWS[3], "3000,300,2.3,2.0,1.9"),
                         ["line 2 to line 4", "column mass_g", "same force"]),
    "both force and mass": (_csv("force_N,mass_g,position_mm,V1,V2,V3", "1,20,150,1,2,3"), ["not both"]),
    "wrong bridges for the design": (_csv("mass_g,position_mm,V1,V2", "20,150,1,2", "3000,150,1,2",
                                          "3000,450,3,2"), ["header", "['V1', 'V2']", "['V1', 'V2', 'V3']"]),
    "biaxial, z axis never loaded": (_csv("mass_g,position_mm,angle_deg,V1y,V1z,V2y,V2z", "250,100,0,1,0,2,0",
                                          "2000,100,0,9,0,8,0", "250,200,0,2,0,1,0", "2000,200,0,7,0,6,0"),
                                     ["column mass_g for the z axis", "no row loads the beam"]),
    "biaxial without angle": (_csv("mass_g,position_mm,V1y,V1z,V2y,V2z", "250,100,1,2,3,4"),
                              ["column angle_deg missing"]),
}


@pytest.mark.parametrize("case", list(BAD_CALIBRATION_CSVS))
def test_bad_calibration_csv_exits_2_and_writes_nothing(tmp_path, capsys, case):
    text, expected = BAD_CALIBRATION_CSVS[case]
    src = tmp_path / "readings.csv"
    src.write_text(text)
    out = tmp_path / "calibration.json"
    design = ["--design", str(DATA / "cal_prototype_b.json")] if "design" in case else []
    assert main(["calibrate", str(src), "-o", str(out)] + design) == 2
    err = capsys.readouterr().err
    assert err.startswith("fpdesign: error: ") and "Traceback" not in err
    for piece in expected:
        assert piece in err, (piece, err)
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["readings.csv"]   # no temporary file left either


def test_a_mis_recorded_reading_is_blamed_on_its_own_column_and_line(tmp_path, capsys):
    """Prototype A's 9-point scheme, twice, with one V2 reading written as 5 V (a slip of the
    pen; the row reads about 0.12 V): the noise pooled from both bridges' residuals made V1, which
    is clean, look like a bridge that does not respond to the load, and the file's line was not
    named. V2's own residuals judge V2 now, and V1's judge V1."""
    src = tmp_path / "r.csv"
    assert main(["simulate-readings", str(DATA / "cal_prototype_a.json"), "-o", str(src), "--scheme", "9",
                 "--repeats", "2"]) == 0
    lines = src.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    cells = lines[header + 4].split(",")
    cells[lines[header].split(",").index("V2")] = "5"
    lines[header + 4] = ",".join(cells)
    src.write_text("\n".join(lines) + "\n")
    assert main(["calibrate", str(src), "-o", str(tmp_path / "cal.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert "column V2: does not respond to the load" in err and "column V1" not in err
    assert f"line {header + 5} lies" in err and "check that reading" in err
    assert len(err.splitlines()) == 1 and not (tmp_path / "cal.json").exists()


def test_failed_calibration_leaves_an_existing_file_untouched(tmp_path):
    out = tmp_path / "calibration.json"
    out.write_text("previous\n")
    src = tmp_path / "readings.csv"
    src.write_text(_csv(B_HEADER, GOOD_ROWS[0]))
    assert main(["calibrate", str(src), "-o", str(out)]) == 2
    assert out.read_text() == "previous\n"


def test_measure_with_bridges_that_do_not_match_the_calibration_exits_2(tmp_path, capsys):
    _, dc, r = _clean_b()
    cal_json = rd.write_calibration(tmp_path / "c.json", cal.calibrate(r, dc))
    src = tmp_path / "readings.csv"
    src.write_text(_csv("V1,V2", "0.1,0.2"))
    results = tmp_path / "results.csv"
    assert main(["measure", str(cal_json), str(src), "-o", str(results)]) == 2
    err = capsys.readouterr().err
    assert "header: bridge columns ['V1', 'V2'] do not match the calibration's ['V1', 'V2', 'V3']" in err
    assert not results.exists()
    # voltages alone (no loads) are enough to measure
    src.write_text(_csv("V1,V2,V3", "1.3,0.9,0.5"))
    assert main(["measure", str(cal_json), str(src), "-o", str(results)]) == 0
    assert results.read_text().count("\n") == 2


@pytest.mark.parametrize("mutate,expected", [
    (lambda d: d.pop("bridges"), "bridges: missing"),
    (lambda d: d["bridges"][1].update(k="x"), "bridges[1].k: 'x' must be a finite number"),
    (lambda d: d["bridges"].pop(1), "bridges: ['V1', 'V3'] must be ['V1', 'V2', 'V3']"),
    (lambda d: d.update(version=7), "version: 7"),
    (lambda d: d.update(version=True), "version: True is not allowed"),   # (True == 1 in Python)
    (lambda d: d.update(axes=3), "axes: 3 does not match the bridges ['V1', 'V2', 'V3'], which are those of 1 axis"),
    (lambda d: d.update(axes=2), "axes: 2 does not match"),
    (lambda d: d.update(points="nine"), "points: 'nine' must be a whole number"),
    (lambda d: d.update(noise=[1]), "noise: [1] must be an object"),
    (lambda d: d["span"].update(force=[1, "x"]), "span.force[1]: 'x' must be a finite number"),
    (lambda d: d.clear(), "bridges: missing"),
])
def test_bad_calibration_json_exits_2(tmp_path, capsys, mutate, expected):
    _, dc, r = _clean_b()
    data = cal.calibrate(r, dc).to_dict()
    mutate(data)
    path = tmp_path / "c.json"
    path.write_text(json.dumps(data))
    src = tmp_path / "readings.csv"
    src.write_text(_csv("V1,V2,V3", "1.3,0.9,0.5"))
    assert main(["measure", str(path), str(src)]) == 2
    assert expected in capsys.readouterr().err


def test_malformed_calibration_json_exits_2(tmp_path, capsys):
    path = tmp_path / "c.json"
    path.write_text("{\n  \"bridges\": [\n")
    src = tmp_path / "readings.csv"
    src.write_text(_csv("V1,V2", "1.3,0.9"))
    assert main(["measure", str(path), str(src)]) == 2
    assert "not valid JSON at line 3" in capsys.readouterr().err
    assert main(["measure", str(tmp_path / "none.json"), str(src)]) == 2
    assert "no such file" in capsys.readouterr().err


def test_bad_design_for_calibration_exits_2(tmp_path, capsys):
    rec = record("b")
    del rec["predicted"]["sensitivity"]
    path = tmp_path / "design.json"
    path.write_text(json.dumps(rec))
    assert main(["plan", str(path)]) == 2
    assert "predicted.sensitivity" in capsys.readouterr().err
    assert main(["simulate-readings", str(tmp_path / "missing.json"), "-o", str(tmp_path / "r.csv")]) == 2
    assert not (tmp_path / "r.csv").exists()


@pytest.mark.parametrize("command", ["plan", "simulate-readings", "calibrate"])
def test_a_station_in_the_load_region_is_refused_by_every_calibration_command(tmp_path, capsys, command):
    """Prototype B (stations 20, 60, 100 mm; loads from 150 mm, Noh et al. 2025 Table 1) with its
    last station moved to 160 mm, inside the operating region: a load between the stations leaves
    the outer bridge no moment, so V_i = k_i F (x - d_i) (MODEL.md section 3) fails there. plot
    refused it; plan, simulate-readings and calibrate --design planned and simulated readings of
    the impossible sensor (exit 0). Now each says what plot says, exit 2, nothing written."""
    rec = record("b")
    rec["design"]["stations"][-1] = 0.160
    path = tmp_path / "design.json"
    path.write_text(json.dumps(rec))
    readings = tmp_path / "readings.csv"
    readings.write_text(_csv(B_HEADER, "20,200,0.1,0.2,0.3"))
    args = {"plan": ["plan", str(path)],
            "simulate-readings": ["simulate-readings", str(path), "-o", str(tmp_path / "r.csv")],
            "calibrate": ["calibrate", str(readings), "--design", str(path), "-o", str(tmp_path / "c.json")]}[command]
    assert main(args) == 2
    message = ("design.stations: the last station (160 mm) must lie before the operating region, which starts "
               "at 150 mm")
    assert message in capsys.readouterr().err
    assert main(["plot", str(path), "-o", str(tmp_path / "plots")]) == 2
    assert message in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["design.json", "readings.csv"])


def _exact_rows(calibration, loads):
    """Noise-free readings of ``calibration``'s sensor (``V_i = k_i F (x - d_i) + c_i``) at
    ``loads`` ((N, mm) pairs), as CSV rows."""
    from designer.model.estimator import bridge_voltages

    k, d, c = ([getattr(b, name) for b in calibration.bridges] for name in "kdc")
    return [",".join([f"{f:g}", f"{x:g}"] + [repr(float(v)) for v in bridge_voltages(k, d, c, f, x / 1e3)])
            for f, x in loads]


def test_measure_compares_what_it_can_and_prints_no_undefined_figure(tmp_path, capsys):
    """docs/spec.md §7 allows a load at the clamp (0 mm): its relative position error is undefined
    (it had printed "position inf %" and numpy's warning), so the mean is over the rows away from
    the clamp; a file with a force and no position is said not to be compared (it had been passed
    over in silence); a calibration without a noise figure prints no "± nan"."""
    _, dc, r = _clean_b()
    fitted = cal.calibrate(r, dc)
    cal_json = rd.write_calibration(tmp_path / "c.json", fitted)
    rows = _exact_rows(fitted, [(10.0, 300.0), (10.0, 0.0)])
    src = tmp_path / "r.csv"
    src.write_text(_csv("force_N,position_mm,V1,V2,V3", *rows))
    assert main(["measure", str(cal_json), str(src)]) == 0
    captured = capsys.readouterr()
    assert "inf" not in captured.out and captured.err == ""
    said = " ".join(captured.out.split())
    assert "position " in said and "(over the 1 of them away from the clamp)" in said
    src.write_text(_csv("force_N,V1,V2,V3", *(",".join(row.split(",")[:1] + row.split(",")[2:]) for row in rows)))
    assert main(["measure", str(cal_json), str(src)]) == 0
    assert "not compared with the estimates" in " ".join(capsys.readouterr().out.split())
    record = json.loads(Path(cal_json).read_text())
    record["noise"] = {}
    record["bridges"] = [dict(b, residuals=[]) for b in record["bridges"]]
    quiet = tmp_path / "quiet.json"
    quiet.write_text(json.dumps(record))
    assert main(["measure", str(quiet), str(src)]) == 0
    out = capsys.readouterr().out
    assert "nan" not in out and "±" not in out and "no noise estimate" in out


def test_calibrate_says_which_file_and_which_flag(tmp_path, capsys):
    """calibrate reads a readings CSV and, with --design, a design.json: a bad --design file is
    named ("spec: missing" had not said which JSON file), --noise design without --design names the
    flag, and counts with a --design that has no front-end say so (the hint had asked for --design
    when it was given)."""
    design = DATA / "cal_prototype_b.json"
    readings_csv = tmp_path / "r.csv"
    assert main(["simulate-readings", str(design), "-o", str(readings_csv), "--scheme", "9"]) == 0
    capsys.readouterr()
    wrong = tmp_path / "calibration.json"
    wrong.write_text(json.dumps({"version": 1}))
    out = tmp_path / "c.json"
    assert main(["calibrate", str(readings_csv), "-o", str(out), "--design", str(wrong)]) == 2
    assert capsys.readouterr().err.startswith(f"fpdesign: error: --design {wrong}: ")
    assert main(["calibrate", str(readings_csv), "-o", str(out), "--noise", "design"]) == 2
    assert capsys.readouterr().err.startswith("fpdesign: error: --noise: 'design' needs a design (--design ")
    counts = tmp_path / "counts.csv"
    counts.write_text(readings_csv.read_text().replace("V1,V2,V3", "C1,C2,C3"))
    assert main(["calibrate", str(counts), "-o", str(out), "--design", str(design)]) == 2
    assert f"--design {design} has no front-end of the catalogue" in capsys.readouterr().err
    assert not out.exists()
