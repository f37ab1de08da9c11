"""A calibration's constants per bridge, and calibration.json's record of them (SPEC.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from designer.calibration.data import Bridge, bridges_for
from designer.calibration.design import json_number
from designer.calibration.regression import SAME_VALUE
from designer.errors import CalibrationFileError, brief
from designer.spec.units import RANGES

#: Calibration loads must reach each edge of the design's region to within this fraction of
#: the region's span (section 3.3: the points should span the whole region).
SPAN_TOLERANCE = 0.05
#: A significance threshold for "k or d differs" and "k is not zero": three standard errors.
SIGNIFICANT_SIGMAS = 3.0
#: The farthest a bridge's station d may lie from the clamp, m: the spec's largest length
#: (spec.units.RANGES). A fitted d beyond it means the bridge reads the force, not its moment.
LARGEST_STATION = RANGES["length"][1]
#: The largest |k|, V/(N m): the largest reading under the smallest load at the shortest lever
#: arm the spec handles (spec.units.RANGES). A k beyond it is a typing error (and one large
#: enough overflows the estimator's k^2 d^2 into NaN).
LARGEST_K = RANGES["voltage"][1] / (RANGES["force"][0] * RANGES["length"][0])
#: How far below zero an eigenvalue of the calibration covariance, scaled to a unit diagonal (its
#: correlation matrix, eigenvalues 0 to 3), may fall by rounding of (X^T X)^-1.
COVARIANCE_ROUNDING = 1e-9


@dataclass(frozen=True)
class BridgeCalibration:
    """Calibration constants of one bridge (SI) with their standard errors and fit quality."""

    bridge: Bridge
    k: float                          # V/(N m)
    d: float                          # m
    c: float                          # V
    se_k: float | None
    se_d: float | None
    se_c: float | None
    r2: float | None
    residual_rms: float               # sqrt(mean residual^2), V
    residuals: tuple[float, ...]      # V, per calibration row
    unscaled_covariance: tuple[tuple[float, float, float], ...]  # (X^T X)^-1 for (b0, b1, b2)
    design_k: float | None = None
    design_d: float | None = None

    @property
    def name(self) -> str:
        return self.bridge.name

    @property
    def coefficients(self) -> np.ndarray:
        """(b0, b1, b2) = (c, k, -k d) of eq. 27."""
        return np.array([self.c, self.k, -self.k * self.d])


@dataclass(frozen=True)
class Calibration:
    """The result of ``calibrate``: constants per bridge, the noise estimate and warnings."""

    bridges: tuple[BridgeCalibration, ...]
    points: int                               # calibration rows
    noise: float | None                       # sigma_V used for standard errors and measurement, V
    noise_source: str                         # residual | design | none
    residual_noise: float | None              # pooled residual RMS over all bridges, dof-corrected
    residual_dof: int
    design_noise: float | None
    force_span: tuple[float, float]           # calibrated loads (magnitude), N
    position_span: tuple[float, float]        # m
    design_name: str | None = None
    warnings: tuple[str, ...] = ()
    source: str = ""
    volts_per_count: float | None = None      # the design's front-end: readings in counts are converted

    @property
    def axes(self) -> int:
        return 2 if any(b.bridge.axis for b in self.bridges) else 1

    @property
    def bridge_names(self) -> tuple[str, ...]:
        return tuple(b.name for b in self.bridges)

    def axis(self, axis: str) -> tuple[BridgeCalibration, ...]:
        return tuple(b for b in self.bridges if b.bridge.axis == axis)

    @property
    def axis_names(self) -> tuple[str, ...]:
        return ("",) if self.axes == 1 else ("y", "z")

    def to_dict(self) -> dict:
        def opt(v):
            return None if v is None or not math.isfinite(v) else float(v)

        return {
            "version": CALIBRATION_VERSION,
            "axes": self.axes,
            "stations": max(b.bridge.station for b in self.bridges),
            "points": self.points,
            "noise": {"sigma_v": opt(self.noise), "source": self.noise_source,
                      "residual": opt(self.residual_noise), "residual_dof": self.residual_dof,
                      "design": opt(self.design_noise)},
            "span": {"force": [float(v) for v in self.force_span],
                     "position": [float(v) for v in self.position_span]},
            "design": self.design_name,
            "source": self.source,
            "bridges": [{
                "name": b.name, "station": b.bridge.station, "axis": b.bridge.axis or None,
                "k": b.k, "d": b.d, "c": b.c, "se_k": opt(b.se_k), "se_d": opt(b.se_d),
                "se_c": opt(b.se_c), "r2": opt(b.r2), "residual_rms": b.residual_rms,
                "design_k": opt(b.design_k), "design_d": opt(b.design_d),
                "residuals": [float(r) for r in b.residuals],
                "unscaled_covariance": [[float(v) for v in row] for row in b.unscaled_covariance],
            } for b in self.bridges],
            "warnings": list(self.warnings),
            "volts_per_count": opt(self.volts_per_count),
        }

    @classmethod
    def from_dict(cls, record) -> "Calibration":
        """The inverse of ``to_dict``; CalibrationFileError names a missing or bad key."""
        return _calibration_from_dict(record)


CALIBRATION_VERSION = 1


def _cal_number(obj, key: str, where: str, optional: bool = False, positive: bool = False):
    if not isinstance(obj, dict):
        raise CalibrationFileError(f"{where}: {brief(obj)} must be an object")
    value = obj.get(key)
    if value is None:
        if optional:
            return None
        raise CalibrationFileError(f"{where}.{key}: missing; it is required")
    return json_number(value, f"{where}.{key}", positive, CalibrationFileError)


def _cal_count(obj: dict, key: str, where: str) -> int:
    value = obj.get(key, 0)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise CalibrationFileError(f"{where + '.' if where else ''}{key}: {value!r} must be a whole number >= 0")
    return value


def _calibration_from_dict(record) -> Calibration:
    if not isinstance(record, dict) or not isinstance(record.get("bridges"), list) or not record["bridges"]:
        raise CalibrationFileError("bridges: missing; a calibration.json lists its bridges "
                                   "(written by `fpdesign calibrate`)")
    if isinstance(record.get("version"), bool) or record.get("version") != CALIBRATION_VERSION:   # (True == 1)
        raise CalibrationFileError(f"version: {record.get('version')!r} is not allowed; must be "
                                   f"{CALIBRATION_VERSION}")
    bridges = []
    for i, raw in enumerate(record["bridges"]):
        where = f"bridges[{i}]"
        if not isinstance(raw, dict):
            raise CalibrationFileError(f"{where}: {brief(raw)} must be an object")
        station = raw.get("station")
        axis = raw.get("axis") or ""
        if isinstance(station, bool) or not isinstance(station, int) or station < 1:
            raise CalibrationFileError(f"{where}.station: {station!r} must be a whole number >= 1")
        if axis not in ("", "y", "z"):
            raise CalibrationFileError(f"{where}.axis: {axis!r} is not allowed; must be one of [null, y, z]")
        cov = raw.get("unscaled_covariance")
        try:
            cov_arr = np.asarray(cov, dtype=float)
        except (TypeError, ValueError) as exc:
            raise CalibrationFileError(f"{where}.unscaled_covariance: {cov!r} must be a 3 x 3 matrix") from exc
        if cov_arr.shape != (3, 3) or not np.all(np.isfinite(cov_arr)):
            raise CalibrationFileError(f"{where}.unscaled_covariance: {cov!r} must be a 3 x 3 matrix")
        _check_covariance(cov_arr, cov, where)
        residuals = raw.get("residuals", [])
        if not isinstance(residuals, list) or not all(
                isinstance(r, (int, float)) and not isinstance(r, bool) and math.isfinite(r) for r in residuals):
            raise CalibrationFileError(f"{where}.residuals: {brief(residuals)} must be a list of numbers (V)")
        bridges.append(BridgeCalibration(
            Bridge(station, axis), _cal_number(raw, "k", where), _cal_number(raw, "d", where),
            _cal_number(raw, "c", where), _cal_number(raw, "se_k", where, True),
            _cal_number(raw, "se_d", where, True), _cal_number(raw, "se_c", where, True),
            _cal_number(raw, "r2", where, True), _cal_number(raw, "residual_rms", where, True) or 0.0,
            tuple(float(r) for r in residuals),
            tuple(tuple(float(v) for v in row) for row in cov_arr),
            _cal_number(raw, "design_k", where, True), _cal_number(raw, "design_d", where, True)))
        _check_constants(bridges[-1], raw, where)
    expected = bridges_for(max(b.bridge.station for b in bridges), 2 if any(b.bridge.axis for b in bridges) else 1)
    if tuple(b.bridge for b in bridges) != expected:
        raise CalibrationFileError(f"bridges: {[b.name for b in bridges]} must be "
                                   f"{[b.name for b in expected]} (every station, in order)")
    derived = 2 if expected[-1].axis else 1
    axes = record.get("axes", derived)
    if isinstance(axes, bool) or axes != derived:
        raise CalibrationFileError(f"axes: {axes!r} does not match the bridges {[b.name for b in bridges]}, which "
                                   f"are those of {'2 axes' if derived == 2 else '1 axis'}")
    if expected[-1].station < 2:
        raise CalibrationFileError(f"bridges: {[b.name for b in bridges]}: a calibration needs at least 2 stations "
                                   "(V1, V2) to tell force from position")
    same = coincident_stations(bridges)
    if same:
        keys = ", ".join(f"bridges[{i}].d" for i in same)
        raise CalibrationFileError(f"{keys}: all {bridges[same[0]].d!r} m; the bridges of an axis must sit at two "
                                   "different distances from the clamp at least, or force and position cannot be "
                                   "told apart; calibrate again")
    noise = record.get("noise") or {}
    span = record.get("span") or {}
    for key, value in (("noise", noise), ("span", span)):
        if not isinstance(value, dict):
            raise CalibrationFileError(f"{key}: {brief(value)} must be an object")

    def span_pair(key):
        value = span.get(key)
        if not isinstance(value, list) or len(value) != 2:
            raise CalibrationFileError(f"span.{key}: {value!r} must be a pair [min, max] (SI)")
        pair = tuple(json_number(v, f"span.{key}[{j}]", error=CalibrationFileError) for j, v in enumerate(value))
        if not pair[0] <= pair[1]:
            raise CalibrationFileError(f"span.{key}: {value!r} is reversed; the first value must not exceed the second")
        return pair

    source = noise.get("source", "none")
    if source not in ("residual", "design", "none"):
        raise CalibrationFileError(f"noise.source: {source!r} is not allowed; must be one of "
                                   "[residual, design, none]")
    return Calibration(
        tuple(bridges), _cal_count(record, "points", ""),
        _cal_number(noise, "sigma_v", "noise", True, True), source,
        _cal_number(noise, "residual", "noise", True), _cal_count(noise, "residual_dof", "noise"),
        _cal_number(noise, "design", "noise", True, True), span_pair("force"), span_pair("position"),
        None if record.get("design") is None else str(record["design"]),
        tuple(str(w) for w in record.get("warnings") or []), str(record.get("source", "")),
        _cal_number(record, "volts_per_count", "calibration", True, True))


def coincident_stations(bridges) -> tuple[int, ...]:
    """The indices of an axis's bridges whose stations d all coincide (within SAME_VALUE), which
    leaves force and position undetermined (eqs. 11-12 divide by their spread); () when none."""
    for axis in sorted({b.bridge.axis for b in bridges}):
        index = [i for i, b in enumerate(bridges) if b.bridge.axis == axis]
        d = [bridges[i].d for i in index]
        if max(d) - min(d) <= SAME_VALUE:
            return tuple(index)
    return ()


def _check_constants(b: BridgeCalibration, raw: dict, where: str) -> None:
    """k and d that a measurement can use: k non-zero, beyond SIGNIFICANT_SIGMAS standard errors
    of zero when the file gives one, at most LARGEST_K; d within LARGEST_STATION of the clamp."""
    if b.k == 0:
        raise CalibrationFileError(f"{where}.k: 0 must be non-zero")
    if abs(b.k) > LARGEST_K:
        raise CalibrationFileError(f"{where}.k: {raw['k']!r} is beyond what a bridge can read; its size must be at "
                                   f"most {LARGEST_K:g} V/(N·m)")
    if b.se_k is not None and abs(b.k) <= SIGNIFICANT_SIGMAS * b.se_k:
        raise CalibrationFileError(f"{where}.k: {raw['k']!r} is within {SIGNIFICANT_SIGMAS:g} standard errors "
                                   f"(se_k = {raw['se_k']!r}) of zero: the bridge did not respond to the load; "
                                   "check its wiring and calibrate again")
    if abs(b.d) > LARGEST_STATION:
        raise CalibrationFileError(f"{where}.d: {raw['d']!r} must lie within {LARGEST_STATION:g} m of the clamp")


def _check_covariance(cov: np.ndarray, raw, where: str) -> None:
    """(X^T X)^-1 is symmetric positive definite: positive variances on the diagonal and, scaled
    to a unit diagonal, no eigenvalue below -COVARIANCE_ROUNDING (its symmetric part)."""
    sym = (cov + cov.T) / 2
    variances = np.diag(sym)
    if np.any(variances <= 0):
        raise CalibrationFileError(f"{where}.unscaled_covariance: {brief(raw)} has a diagonal entry (a variance) "
                                   "that is not positive; it must be (X^T X)^-1 of the calibration loads, positive "
                                   "definite")
    if np.linalg.eigvalsh(sym / np.sqrt(np.outer(variances, variances)))[0] < -COVARIANCE_ROUNDING:
        raise CalibrationFileError(f"{where}.unscaled_covariance: {brief(raw)} is not positive semi-definite (it "
                                   "would give negative variances); it must be (X^T X)^-1 of the calibration loads")
