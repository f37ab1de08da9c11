"""readings.csv and calibration.json on disk, and simulated readings (SPEC.md).

readings.csv: a header row, then one row per reading. Columns: ``force_N`` or ``mass_g`` (a
hung mass, ``F = m g_n``), ``position_mm`` (from the clamp face), for biaxial sensors
``angle_deg`` (the load's direction from the y axis towards z), then one column per bridge in
volts, ``V1, V2, ...`` numbered from the clamp (biaxial ``V1y, V1z, V2y, V2z, ...``). Lines
starting with ``#`` are comments. Every problem raises CsvError naming the line and column.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np

from designer.calibration.data import STANDARD_GRAVITY, Bridge, LoadSet, Readings, axis_force, bridges_for
from designer.calibration.design import design_constants
from designer.calibration.measurement import Measurement
from designer.calibration.schemes import SCHEMES, scheme_loads
from designer.calibration.record import Calibration
from designer.spec.units import RANGES
from designer.errors import CalibrationFileError, CsvError, InputError, read_text
from designer.model import estimator
from designer.result.designfile import load_design, read_json
from designer.outputs.files import atomic_write_json, atomic_write_text

LOAD_COLUMNS = ("force_N", "mass_g", "position_mm", "angle_deg")
_BRIDGE_COLUMN = re.compile(r"([VC])([1-9][0-9]*)([yz]?)")
#: Bridge offsets c_i of simulated sensors: uniform within +-5 mV at the amplifier output (a
#: bridge balanced by hand is never exact; "a few mV" after zeroing).
SIMULATED_OFFSET = 5e-3
#: Decimal digits written for loads and voltages: far below any noise (nV, ug, um).
_DIGITS = 10


# --------------------------------------------------------------------- reading readings.csv

def _allowed_columns() -> str:
    return ("force_N or mass_g, position_mm, angle_deg (biaxial) and V1, V2, ... in volts (biaxial V1y, V1z, ...) "
            "or C1, C2, ... in counts")


def _bridge_columns(names: list[str], where: str) -> tuple[Bridge, ...]:
    """The bridges that the columns ``names`` hold, in column order (V1, V2 ... or V1y, V1z ...,
    or the same in counts, C1, C2 ...)."""
    found = []
    for name in names:
        m = _BRIDGE_COLUMN.fullmatch(name)
        found.append(Bridge(int(m.group(2)), m.group(3)))
    if not found:
        raise CsvError(f"{where}: no bridge columns; expected V1, V2, ... (biaxial V1y, V1z, V2y, ...) in volts, "
                       "or C1, C2, ... in counts")
    if len({name[0] for name in names}) > 1:
        raise CsvError(f"{where}: bridge columns {names} mix volts (V1) and counts (C1); give one or the other")
    axes = {b.axis for b in found}
    biaxial = "" not in axes
    if not biaxial and axes != {""}:
        raise CsvError(f"{where}: bridge columns {names} mix one-axis (V1) and biaxial (V1y) names")
    expected = bridges_for(max(b.station for b in found), 2 if biaxial else 1)
    counts = names[0][0] == "C"   # (V in volts, C in counts)
    if set(found) != set(expected):
        raise CsvError(f"{where}: bridge columns {names} must be {[b.column(counts) for b in expected]}: every station "
                       "from the clamp without gaps" + (", with a y and a z bridge at each" if biaxial else ""))
    if expected[-1].station < 2:
        raise CsvError(f"{where}: bridge columns {names}: a sensor needs at least 2 stations "
                       f"({Bridge(1).column(counts)}, {Bridge(2).column(counts)}) to tell "
                       "force from position")
    return expected   # in column order whatever the file's order


def parse_readings(text: str, source: str = "readings.csv", need_loads: bool = False) -> Readings:
    """Readings from CSV text; CsvError names the line and column of the first problem.

    ``need_loads``: the force (or mass) and position columns must be present (calibration).
    """
    lines = [(i + 1, line) for i, line in enumerate(text.splitlines())
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise CsvError(f"{source}: the file is empty; expected a header row naming {_allowed_columns()}")
    try:
        rows = list(csv.reader([line for _, line in lines], skipinitialspace=True))
    except csv.Error as exc:
        raise CsvError(f"{source}: not readable as CSV: {exc}") from exc
    header_line, header = lines[0][0], [h.strip() for h in rows[0]]
    seen = set()
    for name in header:
        if name in seen:
            raise CsvError(f"{source}: line {header_line}, column {name!r}: appears twice in the header")
        seen.add(name)
        if name not in LOAD_COLUMNS and not _BRIDGE_COLUMN.fullmatch(name):
            raise CsvError(f"{source}: line {header_line}, column {name!r}: not a known column; columns are "
                           f"{_allowed_columns()}")
    if "force_N" in seen and "mass_g" in seen:
        raise CsvError(f"{source}: line {header_line}: give force_N or mass_g, not both")
    bridge_names = [h for h in header if _BRIDGE_COLUMN.fullmatch(h)]
    bridges = _bridge_columns(bridge_names, f"{source}: line {header_line}")
    axes = 2 if bridges[0].axis else 1
    force_column = "mass_g" if "mass_g" in seen else "force_N"
    if need_loads:
        missing = [c for c in (force_column, "position_mm") if c not in seen]
        if missing:
            raise CsvError(f"{source}: line {header_line}: column {missing[0]} missing; calibration needs the "
                           "known loads: force_N (or mass_g) and position_mm")
        if axes == 2 and "angle_deg" not in seen:
            raise CsvError(f"{source}: line {header_line}: column angle_deg missing; biaxial calibration needs "
                           "the direction of every load (0 = along the y bridges, 90 = along z)")
    if axes == 1 and "angle_deg" in seen:
        raise CsvError(f"{source}: line {header_line}, column angle_deg: only biaxial readings (V1y, V1z, ...) "
                       "have a load angle")
    data = rows[1:]
    if not data:
        raise CsvError(f"{source}: no data rows after the header (line {header_line})")
    values = np.empty((len(data), len(header)))
    for r, (row, (line_no, _)) in enumerate(zip(data, lines[1:])):
        if len(row) != len(header):
            raise CsvError(f"{source}: line {line_no}: {len(row)} cells but the header names {len(header)} columns")
        for j, (name, cell) in enumerate(zip(header, row)):
            values[r, j] = _cell(cell, source, line_no, name)
    col = {name: values[:, j] for j, name in enumerate(header)}
    line_numbers = tuple(n for n, _ in lines[1:])
    force = None
    if force_column in col:
        raw = col[force_column]
        if force_column == "mass_g":
            bad = np.nonzero(raw < 0)[0]
            if bad.size:
                raise CsvError(f"{source}: line {line_numbers[bad[0]]}, column mass_g: {raw[bad[0]]:g} is "
                               "negative; a hung mass is >= 0 g")
            force = raw * 1e-3 * STANDARD_GRAVITY
        else:
            force = raw.copy()
    position = None
    if "position_mm" in col:
        bad = np.nonzero(col["position_mm"] < 0)[0]
        if bad.size:
            raise CsvError(f"{source}: line {line_numbers[bad[0]]}, column position_mm: "
                           f"{col['position_mm'][bad[0]]:g} is negative; positions run from the clamp face (0) "
                           "toward the free end")
        position = col["position_mm"] * 1e-3
    angle = np.radians(col["angle_deg"]) if "angle_deg" in col else None
    counts = bridge_names[0][0] == "C"
    voltages = np.column_stack([col[b.column(counts)] for b in bridges])
    return Readings(bridges, voltages, force, position, angle, line_numbers, source, force_column == "mass_g",
                    counts)


def in_volts(readings: Readings, volts_per_count: float | None, where: str) -> Readings:
    """``readings`` in volts: counts (columns C1, C2, ...) times the front-end's volts per count
    (``DesignConstants.volts_per_count``, or a calibration's); CsvError when counts come without one."""
    if not readings.counts:
        return readings
    if volts_per_count is None:
        raise CsvError(f"{readings.source}: the bridge columns are counts (C1, C2, ...); converting them to volts "
                       f"needs the front-end's gain and reference: {where}")
    return replace(readings, voltages=readings.voltages * volts_per_count, counts=False, counted=True)


def in_counts(readings: Readings, volts_per_count: float) -> Readings:
    """``readings`` as the converter's whole counts (columns C1, C2, ...)."""
    return replace(readings, voltages=np.round(readings.voltages / volts_per_count), counts=True)


# A number as a CSV cell may write it (ASCII digits, a point, an exponent).
_DECIMAL = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)


def _cell(cell: str, source: str, line_no: int, name: str) -> float:
    text = cell.strip()
    if not text:
        raise CsvError(f"{source}: line {line_no}, column {name}: empty; every cell needs a number")
    try:
        value = float(text)
    except ValueError as exc:
        raise CsvError(f"{source}: line {line_no}, column {name}: {text!r} is not a number") from exc
    if not math.isfinite(value):
        raise CsvError(f"{source}: line {line_no}, column {name}: {text!r} is not a finite number")
    if not _DECIMAL.fullmatch(text):   # Python's float also reads "50_9" as 509 and other scripts' digits
        raise CsvError(f"{source}: line {line_no}, column {name}: {text!r} is not a number; write it with the "
                       "digits 0-9, a decimal point and an exponent (1.5e-3) only")
    largest = LARGEST[name] if name in LARGEST else LARGEST[name[0]]
    if abs(value) > largest:
        raise CsvError(f"{source}: line {line_no}, column {name}: {text!r} is beyond what a reading can be; "
                       f"its size must be at most {largest:g}")
    return value


# The largest size of a reading, per column (as the CSV holds it): loads, positions, angles and
# voltages (every V column) beyond these are typing errors, and would overflow the fit. The
# spec's ranges (spec.units.RANGES), in the CSV's units; counts (every C column) those of a
# 32-bit converter.
LARGEST = {"force_N": RANGES["force"][1], "mass_g": RANGES["mass"][1] * 1e3, "position_mm": RANGES["length"][1] * 1e3,
           "angle_deg": 360.0, "V": RANGES["voltage"][1], "C": 2.0 ** 31}


def read_readings(path, need_loads: bool = False) -> Readings:
    """``parse_readings`` of a file; a missing or unreadable file is a CsvError."""
    text = read_text(path, CsvError, encoding="utf-8-sig")
    return parse_readings(text, str(path), need_loads)


# --------------------------------------------------------------------- writing CSVs

def _fmt(value: float) -> str:
    return f"{value:.{_DIGITS}g}"


def _csv_text(header: list[str], rows: list[list[str]], comments: tuple[str, ...] = ()) -> str:
    buf = io.StringIO()
    for line in comments:
        buf.write(f"# {line}\n")
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return buf.getvalue()


def format_readings(readings: Readings, comments: tuple[str, ...] = ()) -> str:
    """readings.csv text: loads (mass_g or force_N, position_mm, angle_deg) then the bridges."""
    header, columns = [], []
    if readings.force is not None:
        if readings.mass:
            header.append("mass_g")
            columns.append(readings.force / STANDARD_GRAVITY * 1e3)
        else:
            header.append("force_N")
            columns.append(readings.force)
    if readings.position is not None:
        header.append("position_mm")
        columns.append(readings.position * 1e3)
    if readings.angle is not None and readings.axes == 2:
        header.append("angle_deg")
        columns.append(np.degrees(readings.angle))
    header += [b.column(readings.counts) for b in readings.bridges]
    columns += list(readings.voltages.T)
    rows = [[_fmt(v) for v in row] for row in np.column_stack(columns)]
    return _csv_text(header, rows, comments)


def write_readings(path, readings: Readings, comments: tuple[str, ...] = ()) -> Path:
    return atomic_write_text(path, format_readings(readings, comments))


def format_results(measurement: Measurement) -> str:
    """results.csv text: one row per reading, force in N, position in mm, angle in degrees."""
    header = ["row", "force_N", "sigma_force_N", "position_mm", "sigma_position_mm"]
    cols = [measurement.force, measurement.sigma_force, measurement.position * 1e3,
            measurement.sigma_position * 1e3]
    if measurement.angle is not None:
        header += ["angle_deg", "sigma_angle_deg"]
        cols += [np.degrees(measurement.angle), np.degrees(measurement.sigma_angle)]
    header.append("outside_calibration")
    rows = []
    for i, values in enumerate(np.column_stack(cols)):
        rows.append([str(i + 1)] + ["" if not math.isfinite(v) else f"{v:.6g}" for v in values]
                    + [str(int(measurement.outside[i]))])
    return _csv_text(header, rows)


def write_results(path, measurement: Measurement) -> Path:
    return atomic_write_text(path, format_results(measurement))


def format_plan(plan) -> str:
    """plan.csv text: every loading of both schemes, in grams and millimetres."""
    biaxial = plan.design.axes == 2
    header = ["scheme", "point", "repeat", "mass_g", "force_N", "position_mm"] + (["angle_deg"] if biaxial else [])
    rows = []
    for s in plan.schemes:
        for i in range(len(s.loads)):
            for r in range(s.repeats):
                row = [s.scheme, str(i + 1), str(r + 1), f"{s.loads.force[i] / STANDARD_GRAVITY * 1e3:.6g}",
                       f"{s.loads.force[i]:.6g}", f"{s.loads.position[i] * 1e3:.6g}"]
                if biaxial:
                    row.append(f"{math.degrees(s.loads.angle[i]):.6g}")
                rows.append(row)
    return _csv_text(header, rows, (f"calibration plan for {plan.design.name}",))


def write_plan(path, plan) -> Path:
    return atomic_write_text(path, format_plan(plan))


# --------------------------------------------------------------------- design.json, calibration.json

def read_design(path) -> dict:
    """A validated design.json record (SPEC.md)."""
    return load_design(path)


def read_calibration(path) -> Calibration:
    record = read_json(path, CalibrationFileError)
    try:
        return Calibration.from_dict(record)
    except CalibrationFileError as exc:
        raise CalibrationFileError(f"{path}: {exc}") from exc


def write_calibration(path, calibration: Calibration) -> Path:
    return atomic_write_json(path, calibration.to_dict())


# --------------------------------------------------------------------- simulated readings

def simulate_readings(design: dict, forces, positions, rng, angles=None, offsets=None) -> Readings:
    """Noisy bridge readings of a design.json record's sensor under known loads (SI).

    ``forces`` (N), ``positions`` (m) and ``angles`` (rad, biaxial only; default 0) broadcast
    to one row per load. ``V = c + k F_axis (x - d) + noise`` with sigma_V per channel
    (MODEL.md section 3). ``offsets`` are the bridge offsets c (V) in column order; by default
    they are drawn from ``rng`` first (uniform within +-SIMULATED_OFFSET).
    """
    constants = design_constants(design)
    bridges = constants.bridges
    force, position = np.broadcast_arrays(np.asarray(forces, dtype=float), np.asarray(positions, dtype=float))
    force, position = force.ravel(), position.ravel()
    angle = None
    if constants.axes == 2:
        angle = np.broadcast_to(np.asarray(0.0 if angles is None else angles, dtype=float), force.shape).copy()
    if offsets is None:
        offsets = rng.uniform(-SIMULATED_OFFSET, SIMULATED_OFFSET, len(bridges))
    offsets = np.asarray(offsets, dtype=float)
    if offsets.shape != (len(bridges),):
        raise InputError(f"offsets: {offsets.size} values for {len(bridges)} bridges; give one per bridge")
    k, d = constants.bridge_k(), constants.bridge_d()
    clean = np.empty((len(force), len(bridges)))
    for axis in sorted({b.axis for b in bridges}):   # each axis's bridges see their force component
        cols = [i for i, b in enumerate(bridges) if b.axis == axis]
        clean[:, cols] = estimator.bridge_voltages(k[cols], d[cols], offsets[cols], axis_force(force, angle, axis),
                                                   position)
    voltages = clean + rng.normal(0.0, constants.noise, clean.shape)
    return Readings(bridges, voltages, force, position, angle, (), constants.name, True)


def simulated_sensor_offsets(design: dict, seed: int) -> np.ndarray:
    """The bridge offsets of the simulated sensor named by ``seed`` (the same for every scheme)."""
    rng = np.random.default_rng([seed, 0])
    return rng.uniform(-SIMULATED_OFFSET, SIMULATED_OFFSET, len(design_constants(design).bridges))


def simulated_scheme_readings(design: dict, scheme: str = "paper", seed: int = 0, repeats: int = 1) -> Readings:
    """Readings at a scheme's loads (``calibration.scheme_loads``), each load ``repeats`` times.

    The seed names a simulated sensor: the same seed gives the same bridge offsets for every
    scheme, and each scheme its own independent noise.
    """
    if scheme not in SCHEMES:
        raise InputError(f"scheme: {scheme!r} is not allowed; must be one of {list(SCHEMES)}")
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise InputError(f"repeats: {repeats!r} must be a whole number >= 1")
    loads: LoadSet = scheme_loads(design_constants(design), scheme).repeated(repeats)
    rng = np.random.default_rng([seed, 1 + SCHEMES.index(scheme), repeats])
    return simulate_readings(design, loads.force, loads.position, rng, loads.angle,
                             simulated_sensor_offsets(design, seed))


def write_simulated_readings(design: dict, path, scheme: str = "paper", seed: int = 0, repeats: int = 1,
                             counts: bool = False) -> Path:
    """Write noisy readings of ``design`` at the loads of ``scheme`` to ``path`` (readings.csv), in
    volts, or with ``counts`` in the front-end's counts (a design with electronics.adc)."""
    readings = simulated_scheme_readings(design, scheme, seed, repeats)
    constants = design_constants(design)
    largest = float(np.max(np.abs(readings.voltages)))
    if largest > LARGEST["V"]:   # the file would be refused by calibrate and measure
        raise InputError(f"predicted.noise_voltage: {constants.noise!r} V makes the simulated readings reach "
                         f"{largest:.4g} V, beyond the {LARGEST['V']:g} V a readings file holds; the design's "
                         "noise and sensitivity give no readable sensor")
    comments = (f"simulated readings of {constants.name}: scheme {scheme}, seed {seed}, repeats {repeats}, "
                f"sigma_V {constants.noise * 1e3:.3g} mV per channel",)
    if counts:
        if constants.volts_per_count is None:
            raise InputError("--counts: the design has no front-end of the catalogue (electronics.adc); its "
                             "readings can only be written in volts")
        readings = in_counts(readings, constants.volts_per_count)
        comments += (f"counts of the front-end: {constants.volts_per_count:.6g} V per count at the amplifier output",)
    return write_readings(path, readings, comments)
