"""Readings CSVs, calibration JSON and simulated readings (issue 6): round trips and seeds."""

from __future__ import annotations


import numpy as np
import pytest

from designer import calibration as cal
from designer.calibration import readings as rd

from shared_inputs import calibration_record as record, calibration_constants as constants, clean_prototype_b as _clean_b

G_N = 9.80665  # standard gravity, m/s^2 (ISO 80000-3)


def test_simulated_readings_are_reproducible_and_share_the_sensor_offsets(tmp_path):
    rec = record("b")
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    rd.write_simulated_readings(rec, a, scheme="paper", seed=9)
    rd.write_simulated_readings(rec, b, scheme="paper", seed=9)
    assert a.read_text() == b.read_text()
    rd.write_simulated_readings(rec, b, scheme="paper", seed=10)
    assert a.read_text() != b.read_text()
    # the same seed is the same sensor: calibrations from two schemes agree on c within errors
    c4 = cal.calibrate(rd.simulated_scheme_readings(rec, "4", seed=9, repeats=5), constants("b"))
    c9 = cal.calibrate(rd.simulated_scheme_readings(rec, "9", seed=9, repeats=5), constants("b"))
    offsets = rd.simulated_sensor_offsets(rec, 9)
    assert np.max(np.abs(offsets)) <= rd.SIMULATED_OFFSET
    for b4, b9, c in zip(c4.bridges, c9.bridges, offsets):
        assert abs(b4.c - c) < 3 * b4.se_c and abs(b9.c - c) < 3 * b9.se_c
    readings = rd.read_readings(a, need_loads=True)
    assert readings.mass and len(readings) == 70
    assert sorted(set(np.round(readings.force / G_N * 1e3, 6))) == [20, 50, 70, 100, 300, 500, 1500, 2000, 2500,
                                                                     3000]


def test_readings_csv_round_trip_keeps_the_numbers():
    r = rd.simulated_scheme_readings(record("c"), "9", seed=1)
    back = rd.parse_readings(rd.format_readings(r), need_loads=True)
    assert back.bridges == r.bridges
    assert back.voltages == pytest.approx(r.voltages, rel=1e-9, abs=1e-15)
    assert back.force == pytest.approx(r.force, rel=1e-9)
    assert back.angle == pytest.approx(r.angle, rel=1e-9, abs=1e-12)
    forces = rd.parse_readings("force_N,position_mm,V1,V2\n2.5,150,0.1,0.05\n", need_loads=True)
    assert forces.force[0] == 2.5 and not forces.mass
    swapped = rd.parse_readings("# a comment\nV2, V1\n\n0.05, 0.1\n")    # any column order, spaces, blank lines
    assert [b.name for b in swapped.bridges] == ["V1", "V2"] and swapped.voltages.tolist() == [[0.1, 0.05]]
    assert swapped.lines == (4,)


def test_calibration_json_round_trip(tmp_path):
    rec, dc, r = _clean_b()
    c = cal.calibrate(r, dc)
    path = rd.write_calibration(tmp_path / "c.json", c)
    back = rd.read_calibration(path)
    assert back.to_dict() == c.to_dict()
    v = rd.simulated_scheme_readings(rec, "paper", seed=2).voltages
    assert cal.measure(back, v).force == pytest.approx(cal.measure(c, v).force, rel=1e-15)


def test_simulated_readings_that_no_readings_file_could_hold_are_refused(tmp_path):
    """docs/spec.md §4 allows predicted.noise_voltage up to 1000 V, the largest reading a readings
    file holds (§7); with 900 V of noise the draws pass it (a 1-sigma of 900 V: about a third of the
    draws of one row beyond 1000 V), and calibrate then refused the file simulate-readings had
    written. Refused before writing, naming the key."""
    import json

    from designer.errors import InputError

    edited = record("b")
    edited["predicted"]["noise_voltage"] = 900.0
    with pytest.raises(InputError, match=r"^predicted.noise_voltage: 900.0 V makes the simulated readings reach "):
        rd.write_simulated_readings(json.loads(json.dumps(edited)), tmp_path / "r.csv", scheme="9")
    assert list(tmp_path.iterdir()) == []
    edited["predicted"]["noise_voltage"] = 1e-3
    rd.write_simulated_readings(edited, tmp_path / "r.csv", scheme="9")
    assert rd.read_readings(tmp_path / "r.csv").voltages.shape == (9, 3)
