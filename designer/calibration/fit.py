"""Calibration and measurement: from bridge readings to force and position.

Pure computation (no files, no printing). The model is MODEL.md section 3:

- each bridge reads ``V = c + k F (x - d)``; with ``z1 = F x`` and ``z2 = F`` this is the
  multiple regression ``V = b0 + b1 z1 + b2 z2`` of the paper's eq. 27, and the constants
  follow from eqs. 28-30: ``c = b0``, ``k = b1``, ``d = -b2 / b1``;
- a measurement solves the bridges' equations for ``(z1, z2)`` by least squares
  (``designer.estimator``), so ``F = z2`` and ``x = z1 / z2`` (eqs. 11-12 for two bridges);
- a biaxial sensor (two axes) has one bridge per axis at every station; each axis is its own
  one-dimensional problem on the force component ``F_y = F cos(theta)``, ``F_z = F sin(theta)``.

Uncertainty is propagated linearly (GUM). A measurement's ``(z1, z2)`` of one axis has

    Cov(z) = sigma_V^2 M  +  M S M,    M = (A^T A)^-1,  rows A_i = [k_i, -k_i d_i],
    S = A^T diag(u^T C_i u) A,         u = (1, z1, z2),  C_i = Cov(b0, b1, b2) of bridge i,

the first term from the noise of the reading, the second from the calibration constants
(to first order a constant error ``db_i`` shifts bridge ``i``'s reading by ``u . db_i``).
Bridges of one axis share the calibration loads, so ``C_i = sigma_V^2 (X^T X)^-1`` for all of
them and the second term reduces to ``sigma_V^2 h M`` with the regression leverage
``h = u^T (X^T X)^-1 u``: the familiar prediction-interval factor ``(1 + h)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from designer.model import estimator
from designer.errors import CsvError, DesignFileError, InputError

# --------------------------------------------------------------------- named constants

#: Unknowns per bridge in eq. 27 (b0, b1, b2): the least number of calibration loads.
MIN_POINTS = 3
#: The paper's recommended minimum: the four corners of the operational region (section 3.3).
RECOMMENDED_POINTS = 4
#: The lowest calibration R^2 in the paper's Table 3 is 0.99917; a fit below 0.999 is worse
#: than every prototype's and is reported.
MIN_R2 = 0.999
#: Residual degrees of freedom from which the residual RMS is trusted as the noise estimate:
#: its relative standard error is about 1/sqrt(2 dof), 22 % at 10.
MIN_NOISE_DOF = 10
#: Significance of the test "residuals larger than the design's noise" (chi-square, one-sided).
NOISE_TEST_P = 1e-3
#: A residual this many standard deviations from the fit marks its row as a likely bad load
#: (two-sided normal probability 6e-5 per residual).
OUTLIER_SIGMAS = 4.0
#: Bridges of one design are nominally identical (MODEL.md: the same feature at every station).
#: Gauge-factor tolerance (about 1 %), placement and bonding give a few per cent of spread
#: between bridges; more than 5 % beyond what the design predicts points to a bad gauge or bridge.
K_SPREAD_TOLERANCE = 0.05
#: The design's k is built from E, G, gain, excitation and the section (the paper's "stack-up"
#: of section 3.3); a common scale error beyond 25 % suggests a wrong gain or wiring.
K_SCALE_TOLERANCE = 0.25
#: A fitted station d further than this from the design's (hand placement of a gauge), m.
D_TOLERANCE = 2e-3
#: Calibration loads must reach each edge of the design's region to within this fraction of
#: the region's span (section 3.3: the points should span the whole region).
SPAN_TOLERANCE = 0.05
#: Loads and positions closer than this count as the same (m and N alike, far below any use).
SAME_VALUE = 1e-9
#: Above this (column-scaled) condition number the calibration loads do not determine k, d, c.
MAX_CONDITION = 1e8
#: A significance threshold for "k or d differs": three standard errors.
SIGNIFICANT_SIGMAS = 3.0

#: Noise sources for standard errors and measurement uncertainty.
NOISE_CHOICES = ("auto", "residual", "design")


class CalibrationFileError(InputError):
    """A calibration.json that is missing keys or holds impossible values."""


# --------------------------------------------------------------------- bridges and loads

@dataclass(frozen=True)
class Bridge:
    """One Wheatstone bridge: its station (1 = nearest the clamp) and axis ('' for 1 axis)."""

    station: int
    axis: str = ""

    @property
    def name(self) -> str:
        """The readings.csv column: ``V1``, ``V2`` ... or ``V1y``, ``V1z`` ... (SPEC.md)."""
        return f"V{self.station}{self.axis}"


def bridges_for(stations: int, axes: int) -> tuple[Bridge, ...]:
    """The bridges of a sensor in column order."""
    letters = ("",) if axes == 1 else ("y", "z")
    return tuple(Bridge(s, a) for s in range(1, stations + 1) for a in letters)


def axis_force(force, angle, axis: str):
    """The force component a bridge of ``axis`` sees: F, F cos(theta) or F sin(theta)."""
    force = np.asarray(force, dtype=float)
    if axis == "":
        return force
    angle = np.zeros_like(force) if angle is None else np.asarray(angle, dtype=float)
    return force * (np.cos(angle) if axis == "y" else np.sin(angle))


@dataclass(frozen=True)
class LoadSet:
    """Point loads: force (N), position (m) and, for biaxial sensors, angle (rad), per row."""

    force: np.ndarray
    position: np.ndarray
    angle: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.force)

    def repeated(self, repeats: int) -> "LoadSet":
        """Every load ``repeats`` times in a row (r1 r1 r1 r2 r2 r2 ...)."""
        angle = None if self.angle is None else np.repeat(self.angle, repeats)
        return LoadSet(np.repeat(self.force, repeats), np.repeat(self.position, repeats), angle)


@dataclass(frozen=True)
class Readings:
    """A table of bridge readings, SI, as read from readings.csv or simulated.

    ``force``, ``position`` and ``angle`` are the known loads (None when the file gives only
    voltages); ``lines`` are the file lines of the rows, used to name rows in messages.
    """

    bridges: tuple[Bridge, ...]
    voltages: np.ndarray                 # (rows, bridges), V
    force: np.ndarray | None = None      # N
    position: np.ndarray | None = None   # m
    angle: np.ndarray | None = None      # rad
    lines: tuple[int, ...] = ()
    source: str = "readings"
    mass: bool = True                    # the loads are hung masses (written back as mass_g)

    def __len__(self) -> int:
        return self.voltages.shape[0]

    @property
    def axes(self) -> int:
        return 2 if any(b.axis for b in self.bridges) else 1

    @property
    def stations(self) -> int:
        return max(b.station for b in self.bridges)

    @property
    def force_column(self) -> str:
        return "mass_g" if self.mass else "force_N"

    def row(self, i: int) -> str:
        """``"line 7"`` (or ``"row 7"`` when there is no file) for messages."""
        return f"line {self.lines[i]}" if self.lines else f"row {i + 1}"

    @property
    def loads(self) -> LoadSet | None:
        if self.force is None or self.position is None:
            return None
        return LoadSet(self.force, self.position, self.angle)


# --------------------------------------------------------------------- the design's constants

@dataclass(frozen=True)
class DesignConstants:
    """What calibration and measurement need from a design.json (SI)."""

    name: str
    stations: tuple[float, ...]        # d_i, m
    sensitivity: tuple[float, ...]     # k_i, V/(N m), per station (both axes alike)
    noise: float                       # sigma_V per channel at the amplifier output, V
    axes: int
    force_range: tuple[float, float]   # F_min, F_max, N
    position_range: tuple[float, float]  # x_min, x_max, m
    prototype: str | None = None       # 'A', 'B' or 'C' when the beam is one of the paper's

    @property
    def bridges(self) -> tuple[Bridge, ...]:
        return bridges_for(len(self.stations), self.axes)

    def bridge_k(self) -> np.ndarray:
        """k per bridge in column order."""
        return np.repeat(np.asarray(self.sensitivity, dtype=float), self.axes)

    def bridge_d(self) -> np.ndarray:
        return np.repeat(np.asarray(self.stations, dtype=float), self.axes)


#: The paper's Table 1 sections, to recognise its prototypes (m): A, B and C.
PROTOTYPE_SECTIONS = {
    "A": ("rectangle", {"width": 0.050, "height": 0.00318}),
    "B": ("rectangle", {"width": 0.0127, "height": 0.0127}),
    "C": ("tube", {"diameter": 0.0127, "wall": 0.00165}),
}
#: Section sizes within this of Table 1 are taken as the prototype (m): 0.05 mm.
PROTOTYPE_MATCH = 5e-5
#: The paper's Table 2: masses (g), positions (mm) and, for C, angles (degrees, section 4.2.1).
PAPER_TABLE2 = {
    "A": ((250, 500, 1000, 1500, 2000), tuple(range(150, 651, 50)), (0,)),
    "B": ((20, 50, 70, 100, 300, 500, 1500, 2000, 2500, 3000), tuple(range(150, 451, 50)), (0,)),
    "C": ((250, 500, 1000, 1500, 2000), tuple(range(100, 201, 20)), tuple(range(0, 91, 15))),
}


def _number(value, key: str, positive: bool = False, error: type = DesignFileError) -> float:
    """``value`` as a float, or ``error`` naming ``key`` (a design.json or calibration.json key)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise error(f"{key}: {value!r} must be a finite number (SI units)")
    if positive and value <= 0:
        raise error(f"{key}: {value!r} must be positive")
    return float(value)


def _require(obj, key: str, where: str):
    if not isinstance(obj, dict) or obj.get(key) is None:
        raise DesignFileError(f"{where + '.' if where else ''}{key}: missing; it is required")
    return obj[key]


def _pair(value, key: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise DesignFileError(f"{key}: {value!r} must be a pair [min, max]")
    lo, hi = (_number(v, f"{key}[{i}]", positive=True) for i, v in enumerate(value))
    if not lo < hi:
        raise DesignFileError(f"{key}: {value!r} must increase (min < max)")
    return lo, hi


_BRIDGE_N = {"quarter": 1, "half": 2, "full": 4}


def _noise_from(record: dict) -> float:
    """sigma_V: predicted.noise_voltage, else from spec.electronics (MODEL.md section 3)."""
    predicted = record.get("predicted") or {}
    if predicted.get("noise_voltage") is not None:
        return _number(predicted["noise_voltage"], "predicted.noise_voltage", positive=True)
    spec = record["spec"]
    e = _require(spec, "electronics", "spec")
    if e.get("noise") is not None:
        return _number(e["noise"], "spec.electronics.noise", positive=True)
    if e.get("noise_rti") is not None:
        return (_number(e["noise_rti"], "spec.electronics.noise_rti", positive=True)
                * _number(_require(e, "gain", "spec.electronics"), "spec.electronics.gain", positive=True))
    if e.get("noise_strain") is not None:
        gauge = spec.get("gauge") or record["design"].get("gauge") or {}
        bridge = spec.get("bridge", record["design"].get("bridge"))
        if bridge not in _BRIDGE_N:
            raise DesignFileError(f"spec.bridge: {bridge!r} is not allowed; must be one of {list(_BRIDGE_N)}")
        return (_number(_require(e, "excitation", "spec.electronics"), "spec.electronics.excitation", True)
                * _number(_require(gauge, "factor", "spec.gauge"), "spec.gauge.factor", True)
                * _number(_require(e, "gain", "spec.electronics"), "spec.electronics.gain", True)
                * _BRIDGE_N[bridge]
                * _number(e["noise_strain"], "spec.electronics.noise_strain", True) / 4)
    raise DesignFileError("predicted.noise_voltage: missing, and spec.electronics gives none of "
                          "noise, noise_rti, noise_strain; one is required")


def _prototype(section) -> str | None:
    if not isinstance(section, dict):
        return None
    for letter, (kind, dims) in PROTOTYPE_SECTIONS.items():
        if section.get("kind") == kind and all(
                isinstance(section.get(k), (int, float)) and abs(section[k] - v) <= PROTOTYPE_MATCH
                for k, v in dims.items()):
            return letter
    return None


def design_constants(record: dict) -> DesignConstants:
    """The constants of a design.json record; DesignFileError names a missing or bad key."""
    if not isinstance(record, dict):
        raise DesignFileError("design.json: must be a JSON object with keys 'spec', 'design' and 'predicted'")
    spec = _require(record, "spec", "")
    design = _require(record, "design", "")
    predicted = _require(record, "predicted", "")
    raw_stations = _require(design, "stations", "design")
    if not isinstance(raw_stations, list) or len(raw_stations) < 2:
        raise DesignFileError(f"design.stations: {raw_stations!r} must be a list of at least 2 positions (m)")
    stations = tuple(_number(s, f"design.stations[{i}]", positive=True) for i, s in enumerate(raw_stations))
    if any(b <= a for a, b in zip(stations, stations[1:])):
        raise DesignFileError(f"design.stations: {list(stations)!r} must increase from the clamp outwards")
    raw_k = predicted.get("sensitivity")
    if not isinstance(raw_k, list) or len(raw_k) != len(stations):
        raise DesignFileError(f"predicted.sensitivity: {raw_k!r} must list k (V/(N m)) for each of the "
                              f"{len(stations)} stations")
    k = tuple(_number(v, f"predicted.sensitivity[{i}]", positive=True) for i, v in enumerate(raw_k))
    axes = design.get("axes", spec.get("axes", 1))
    if axes not in (1, 2):
        raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
    load = _require(spec, "load", "spec")
    force = _pair(_require(load, "force", "spec.load"), "spec.load.force")
    position = _pair(_require(load, "position", "spec.load"), "spec.load.position")
    name = spec.get("name") or "design"
    return DesignConstants(str(name), stations, k, _noise_from(record), int(axes), force, position,
                           _prototype(design.get("section")))


# --------------------------------------------------------------------- load schemes

SCHEMES = ("paper", "4", "9", "grid")
#: The paper's section 4.3 Monte Carlo grid: 7 loads by 7 positions over the region.
GRID_POINTS = 7
#: Biaxial load angles of section 4.2.1: 0 to 90 degrees in 15 degree steps.
GRID_ANGLES_DEG = tuple(range(0, 91, 15))
#: Biaxial calibration loads each scheme point along both bending axes.
CALIBRATION_ANGLES_DEG = (0.0, 90.0)
#: Standard gravity, m/s^2 (ISO 80000-3): a hung mass m pulls with F = m g_n.
STANDARD_GRAVITY = 9.80665


def _product(forces, positions, angles_deg, axes: int) -> LoadSet:
    angles = angles_deg if axes == 2 else (0.0,)
    f, x, a = np.meshgrid(np.asarray(forces, float), np.asarray(positions, float),
                          np.radians(np.asarray(angles, float)), indexing="ij")
    return LoadSet(f.ravel(), x.ravel(), a.ravel() if axes == 2 else None)


def scheme_loads(design: DesignConstants, scheme: str) -> LoadSet:
    """The loads of a scheme, rows ordered by force, then position, then angle.

    - ``4``: the 2 x 2 corners of the design's region (the paper's minimum, section 3.3);
    - ``9``: the 3 x 3 grid of the region's edges and middles (section 4.2.2);
    - ``grid``: 7 forces by 7 positions spaced evenly over the region (section 4.3);
    - ``paper``: the paper's Table 2 for its Prototypes A, B and C, else ``grid``.
    Biaxial sensors: ``4`` and ``9`` load every point along both axes (0 and 90 degrees);
    ``grid`` and ``paper`` turn the beam through 0, 15, ... 90 degrees.
    """
    (f0, f1), (x0, x1) = design.force_range, design.position_range
    if scheme == "4":
        return _product((f0, f1), (x0, x1), CALIBRATION_ANGLES_DEG, design.axes)
    if scheme == "9":
        return _product((f0, (f0 + f1) / 2, f1), (x0, (x0 + x1) / 2, x1), CALIBRATION_ANGLES_DEG, design.axes)
    if scheme == "paper" and design.prototype in PAPER_TABLE2:
        masses, positions_mm, angles = PAPER_TABLE2[design.prototype]
        forces = np.asarray(masses, float) * 1e-3 * STANDARD_GRAVITY
        return _product(forces, np.asarray(positions_mm, float) * 1e-3, angles, design.axes)
    if scheme in ("paper", "grid"):
        return _product(np.linspace(f0, f1, GRID_POINTS), np.linspace(x0, x1, GRID_POINTS),
                        GRID_ANGLES_DEG, design.axes)
    raise InputError(f"scheme: {scheme!r} is not allowed; must be one of {list(SCHEMES)}")


# --------------------------------------------------------------------- regression (eq. 27)

def design_matrix(force, position) -> np.ndarray:
    """Rows ``(1, F x, F)`` of eq. 27; shape (rows, 3)."""
    f = np.asarray(force, dtype=float)
    return np.stack([np.ones_like(f), f * np.asarray(position, dtype=float), f], axis=-1)


@dataclass(frozen=True)
class Regression:
    """Least squares of eq. 27 for bridges that share one set of calibration loads.

    Vectorised: ``voltages`` may carry leading axes (e.g. Monte Carlo draws).
    """

    coefficients: np.ndarray          # (..., bridges, 3): b0, b1, b2
    unscaled_covariance: np.ndarray   # (3, 3): (X^T X)^-1; Cov(b) = sigma_V^2 times this
    leverage: np.ndarray              # (rows,): h_ii, the diagonal of X (X^T X)^-1 X^T
    residuals: np.ndarray             # (..., rows, bridges), V
    r2: np.ndarray                    # (..., bridges)

    @property
    def dof(self) -> int:
        return self.residuals.shape[-2] - 3

    @property
    def rss(self) -> np.ndarray:
        return np.sum(self.residuals ** 2, axis=-2)

    @property
    def k(self):
        return self.coefficients[..., 1]

    @property
    def c(self):
        return self.coefficients[..., 0]

    @property
    def d(self):
        return -self.coefficients[..., 2] / self.coefficients[..., 1]

    def standard_errors(self, sigma_v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(se_k, se_d, se_c) for noise ``sigma_v``; se_d by the delta method on d = -b2/b1."""
        sigma_v = np.asarray(sigma_v, dtype=float)[..., None] * np.ones(self.coefficients.shape[:-1])
        U = self.unscaled_covariance
        b1, b2 = self.coefficients[..., 1], self.coefficients[..., 2]
        # d = -b2/b1: dd/db1 = b2/b1^2, dd/db2 = -1/b1
        j1, j2 = b2 / b1 ** 2, -1.0 / b1
        var_d = j1 * j1 * U[1, 1] + 2 * j1 * j2 * U[1, 2] + j2 * j2 * U[2, 2]
        return sigma_v * math.sqrt(U[1, 1]), sigma_v * np.sqrt(var_d), sigma_v * math.sqrt(U[0, 0])


def regress(force, position, voltages) -> Regression:
    """Fit ``V = b0 + b1 F x + b2 F`` to every bridge (column) of ``voltages``.

    ``force`` is the force component the bridges see (N), ``position`` in m, ``voltages`` in V
    with shape (..., rows, bridges). The caller checks that the loads determine the fit
    (``rank_problem``).
    """
    X = design_matrix(force, position)
    V = np.asarray(voltages, dtype=float)
    U = np.linalg.inv(X.T @ X)
    b = np.einsum("ij,nj,...nm->...mi", U, X, V)
    residuals = V - np.einsum("nj,...mj->...nm", X, b)
    tss = np.sum((V - V.mean(axis=-2, keepdims=True)) ** 2, axis=-2)
    with np.errstate(divide="ignore", invalid="ignore"):
        r2 = np.where(tss > 0, 1.0 - np.sum(residuals ** 2, axis=-2) / tss, np.nan)
    leverage = np.einsum("ni,ij,nj->n", X, U, X)
    return Regression(b, U, leverage, residuals, r2)


def rank_problem(force, position) -> tuple[str, str] | None:
    """Why loads cannot determine ``c, k, d``: ``(column, words)`` for a message, or None."""
    f = np.asarray(force, dtype=float)
    x = np.asarray(position, dtype=float)
    loaded = np.abs(f) > SAME_VALUE
    if not loaded.any():
        return "force", "no row loads the beam (every force is zero)"
    if np.ptp(x[loaded]) <= SAME_VALUE:
        return "position", (f"every loaded row is at one position ({x[loaded][0] * 1e3:g} mm), so k and d "
                            "cannot be told apart; load at least two positions")
    if np.ptp(f) <= SAME_VALUE:
        return "force", (f"every row has the same force ({f[0]:g} N), so the offset c and the term k d F "
                         "cannot be told apart; use at least two loads")
    X = design_matrix(f, x)
    scale = np.linalg.norm(X, axis=0)
    if np.linalg.cond(X / scale) > MAX_CONDITION:
        return "position", "the loads are too close to one another to determine k, d and c"
    return None


# --------------------------------------------------------------------- the calibration

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
        }

    @classmethod
    def from_dict(cls, record) -> "Calibration":
        """The inverse of ``to_dict``; CalibrationFileError names a missing or bad key."""
        return _calibration_from_dict(record)


CALIBRATION_VERSION = 1


def _cal_number(obj, key: str, where: str, optional: bool = False, positive: bool = False):
    if not isinstance(obj, dict):
        raise CalibrationFileError(f"{where}: {obj!r} must be an object")
    value = obj.get(key)
    if value is None:
        if optional:
            return None
        raise CalibrationFileError(f"{where}.{key}: missing; it is required")
    return _number(value, f"{where}.{key}", positive, CalibrationFileError)


def _cal_count(obj: dict, key: str, where: str) -> int:
    value = obj.get(key, 0)
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise CalibrationFileError(f"{where + '.' if where else ''}{key}: {value!r} must be a whole number >= 0")
    return value


def _calibration_from_dict(record) -> Calibration:
    if not isinstance(record, dict) or not isinstance(record.get("bridges"), list) or not record["bridges"]:
        raise CalibrationFileError("bridges: missing; a calibration.json lists its bridges "
                                   "(written by `fpdesign calibrate`)")
    if record.get("version") != CALIBRATION_VERSION:
        raise CalibrationFileError(f"version: {record.get('version')!r} is not allowed; must be "
                                   f"{CALIBRATION_VERSION}")
    bridges = []
    for i, raw in enumerate(record["bridges"]):
        where = f"bridges[{i}]"
        if not isinstance(raw, dict):
            raise CalibrationFileError(f"{where}: {raw!r} must be an object")
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
        residuals = raw.get("residuals", [])
        bridges.append(BridgeCalibration(
            Bridge(station, axis), _cal_number(raw, "k", where), _cal_number(raw, "d", where),
            _cal_number(raw, "c", where), _cal_number(raw, "se_k", where, True),
            _cal_number(raw, "se_d", where, True), _cal_number(raw, "se_c", where, True),
            _cal_number(raw, "r2", where, True), _cal_number(raw, "residual_rms", where, True) or 0.0,
            tuple(float(r) for r in residuals) if isinstance(residuals, list) else (),
            tuple(tuple(float(v) for v in row) for row in cov_arr),
            _cal_number(raw, "design_k", where, True), _cal_number(raw, "design_d", where, True)))
        if bridges[-1].k == 0:
            raise CalibrationFileError(f"{where}.k: 0 must be non-zero")
    expected = bridges_for(max(b.bridge.station for b in bridges), 2 if any(b.bridge.axis for b in bridges) else 1)
    if tuple(b.bridge for b in bridges) != expected:
        raise CalibrationFileError(f"bridges: {[b.name for b in bridges]} must be "
                                   f"{[b.name for b in expected]} (every station, in order)")
    noise = record.get("noise") or {}
    span = record.get("span") or {}
    for key, value in (("noise", noise), ("span", span)):
        if not isinstance(value, dict):
            raise CalibrationFileError(f"{key}: {value!r} must be an object")

    def span_pair(key):
        value = span.get(key)
        if not isinstance(value, list) or len(value) != 2:
            raise CalibrationFileError(f"span.{key}: {value!r} must be a pair [min, max] (SI)")
        return tuple(_number(v, f"span.{key}[{j}]", error=CalibrationFileError) for j, v in enumerate(value))

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
        tuple(str(w) for w in record.get("warnings") or []), str(record.get("source", "")))


def _mm(value: float) -> str:
    return f"{value * 1e3:.4g} mm"


def _mv(value: float) -> str:
    return f"{value * 1e3:.3g} mV"


def calibrate(readings: Readings, design: DesignConstants | None = None, noise: str = "auto") -> Calibration:
    """Fit eq. 27 to every bridge and derive c, k, d (eqs. 28-30) with standard errors.

    ``noise`` chooses sigma_V for the standard errors and later measurements: ``residual``
    (the pooled residual RMS), ``design`` (the design's sigma_V) or ``auto`` (the residual RMS
    when it has at least MIN_NOISE_DOF degrees of freedom, else the design's, else the residual
    RMS with a warning). Bad readings raise CsvError naming the row and column.
    """
    if noise not in NOISE_CHOICES:
        raise InputError(f"noise: {noise!r} is not allowed; must be one of {list(NOISE_CHOICES)}")
    loads = readings.loads
    if loads is None:
        raise CsvError(f"{readings.source}: calibration needs the known loads: a force_N or mass_g column "
                       "and a position_mm column")
    n = len(readings)
    if n < MIN_POINTS:
        raise CsvError(f"{readings.source}: {n} data row{'s' if n != 1 else ''}; calibration needs at least "
                       f"{MIN_POINTS} (eq. 27 has 3 unknowns per bridge) and the paper recommends the "
                       f"{RECOMMENDED_POINTS} corners of the region (fpdesign plan)")
    if readings.axes == 2 and loads.angle is None:
        raise CsvError(f"{readings.source}: biaxial readings ({readings.bridges[0].name}, ...) need an angle_deg "
                       "column giving the direction of every load")
    if design is not None and tuple(b.name for b in readings.bridges) != tuple(b.name for b in design.bridges):
        raise CsvError(f"{readings.source}: header: the bridge columns {[b.name for b in readings.bridges]} do not "
                       f"match the design's {len(design.stations)} station(s) x {design.axes} axis/axes: "
                       f"expected {[b.name for b in design.bridges]}")
    axis_names = ("",) if readings.axes == 1 else ("y", "z")
    fits = {}
    for axis in axis_names:
        f_axis = axis_force(loads.force, loads.angle, axis)
        problem = rank_problem(f_axis, loads.position)
        if problem:
            column = {"force": readings.force_column, "position": "position_mm"}[problem[0]]
            what = f" for the {axis} axis (component F {'cos' if axis == 'y' else 'sin'}(angle))" if axis else ""
            raise CsvError(f"{readings.source}: {readings.row(0)} to {readings.row(n - 1)}, column "
                           f"{column}{what}: {problem[1]}")
        cols = [i for i, b in enumerate(readings.bridges) if b.axis == axis]
        fits[axis] = (cols, regress(f_axis, loads.position, readings.voltages[:, cols]))

    dof_total = sum(fit.dof * len(cols) for cols, fit in fits.values())
    rss_total = sum(float(np.sum(fit.rss)) for _, fit in fits.values())
    residual_noise = math.sqrt(rss_total / dof_total) if dof_total > 0 else None
    design_noise = design.noise if design is not None else None
    sigma, source, warnings = _choose_noise(noise, residual_noise, dof_total, design_noise, n, readings.source)

    results: dict[int, BridgeCalibration] = {}
    for axis, (cols, fit) in fits.items():
        se = fit.standard_errors(sigma) if sigma is not None else (None, None, None)
        for j, col in enumerate(cols):
            bridge = readings.bridges[col]
            dk = float(design.bridge_k()[col]) if design is not None else None
            dd = float(design.bridge_d()[col]) if design is not None else None
            results[col] = BridgeCalibration(
                bridge, float(fit.k[j]), float(fit.d[j]), float(fit.c[j]),
                *(None if s is None else float(s[j]) for s in se),
                None if not np.isfinite(fit.r2[j]) else float(fit.r2[j]),
                float(np.sqrt(np.mean(fit.residuals[:, j] ** 2))),
                tuple(float(r) for r in fit.residuals[:, j]),
                tuple(tuple(float(v) for v in row) for row in fit.unscaled_covariance), dk, dd)
    bridges = tuple(results[i] for i in range(len(readings.bridges)))

    magnitude = np.abs(loads.force)
    loaded = magnitude > SAME_VALUE
    force_span = (float(magnitude[loaded].min()), float(magnitude[loaded].max()))
    position_span = (float(loads.position[loaded].min()), float(loads.position[loaded].max()))
    warnings += _fit_warnings(readings, bridges, fits, sigma, residual_noise, dof_total, design,
                              force_span, position_span)
    return Calibration(bridges, n, sigma, source, residual_noise, dof_total, design_noise, force_span,
                       position_span, design.name if design is not None else None, tuple(warnings),
                       readings.source)


def _choose_noise(choice: str, residual_noise, dof: int, design_noise, n: int, source: str):
    """``(sigma_V or None, its source, warnings)`` for the noise ``choice`` (see ``calibrate``)."""
    if choice == "residual":
        if residual_noise is None:
            raise CsvError(f"{source}: {n} rows leave no residual to estimate the noise from; add calibration "
                           "points or choose the design's noise")
        return residual_noise, "residual", []
    if choice == "design":
        if design_noise is None:
            raise InputError("noise: 'design' needs a design (--design design.json)")
        return design_noise, "design", []
    if residual_noise is not None and dof >= MIN_NOISE_DOF:
        return residual_noise, "residual", []
    if design_noise is not None:
        return design_noise, "design", []
    if residual_noise is not None:
        return residual_noise, "residual", [
            f"the noise estimate ({_mv(residual_noise)}) rests on only {dof} residual degrees of freedom; "
            f"standard errors are rough (give --design, or use {MIN_NOISE_DOF}+ residual dof)"]
    return None, "none", [f"{n} rows fit exactly: no noise estimate, so no standard errors; give --design or "
                          "calibrate with more points"]


def _fit_warnings(readings, bridges, fits, sigma, residual_noise, dof_total, design, force_span,
                  position_span) -> list[str]:
    from scipy import stats

    n = len(readings)
    out = []
    if n < RECOMMENDED_POINTS:
        out.append(f"only {n} calibration points: fewer than the paper's minimum scheme, the "
                   f"{RECOMMENDED_POINTS} corners of the region (section 3.3); the fit is exact and its "
                   "residuals say nothing about noise or linearity")
    for b in bridges:
        if b.r2 is not None and n > MIN_POINTS and b.r2 < MIN_R2:
            out.append(f"{b.name}: R² = {b.r2:.5f} is below {MIN_R2} (the paper's Table 3 has no calibration "
                       "below 0.99917): the bridge is not linear in F·x and F over these loads; look for a "
                       "misplaced load, a slipping clamp or a large deflection")
        if b.k <= 0:
            out.append(f"{b.name}: k = {b.k:.4g} V/(N·m) is not positive: the bridge reads the load with the "
                       "opposite sign (reversed wiring or a gauge on the other face); measurements still work")
    if design is not None and residual_noise is not None:
        limit = stats.chi2.ppf(1 - NOISE_TEST_P, dof_total) / dof_total
        if (residual_noise / design.noise) ** 2 > limit:
            out.append(f"the residuals ({_mv(residual_noise)} RMS) are larger than the design's noise "
                       f"sigma_V = {_mv(design.noise)} (chi-square test, p < {NOISE_TEST_P:g}): the bridges "
                       "do not follow V = c + k F (x - d) over these loads, or the electronics are noisier "
                       "than designed")
    if sigma is not None:
        for axis, (cols, fit) in fits.items():
            if fit.dof < 1:
                continue
            scale = sigma * np.sqrt(np.clip(1 - fit.leverage, 1e-12, None))[:, None]
            z = np.abs(fit.residuals) / scale
            for row, j in zip(*np.nonzero(z > OUTLIER_SIGMAS)):
                out.append(_outlier_message(readings, row, readings.bridges[cols[j]].name,
                                            fit.residuals[row, j], z[row, j]))
    out += _k_warnings(bridges, design)
    if design is not None:
        for b in bridges:
            if b.design_d is None:
                continue
            tol = max(D_TOLERANCE, SIGNIFICANT_SIGMAS * (b.se_d or 0.0))
            if abs(b.d - b.design_d) > tol:
                out.append(f"{b.name}: the fitted station d = {_mm(b.d)} is {_mm(abs(b.d - b.design_d))} from the "
                           f"design's {_mm(b.design_d)} (more than {_mm(tol)}): check where the gauge sits")
        out += _span_warnings(design, force_span, position_span)
    return out


def _outlier_message(readings, row, name, residual, z) -> str:
    loads = readings.loads
    where = (f"{readings.row(row)} (force {loads.force[row]:.4g} N, position {loads.position[row] * 1e3:.4g} mm)"
             if loads is not None else readings.row(row))
    return (f"{where}, column {name}: residual {_mv(residual)} is {z:.1f} standard deviations from the fit: "
            "a misplaced or mis-recorded load?")


def _k_warnings(bridges, design) -> list[str]:
    """Bridges whose k differ from one another more than the design predicts."""
    k = np.array([b.k for b in bridges])
    se = np.array([b.se_k if b.se_k is not None else 0.0 for b in bridges])
    expected = (np.array([b.design_k for b in bridges]) if design is not None else np.ones_like(k))
    ratio = k / expected
    scale = float(np.median(ratio))   # the common scale; the median leaves one odd bridge out
    if scale == 0:
        return []
    out = []
    for b, r, s, e in zip(bridges, ratio, se, expected):
        rel = r / scale - 1
        if abs(rel) > K_SPREAD_TOLERANCE and abs(rel) > SIGNIFICANT_SIGMAS * s / e / abs(scale):
            basis = "the design's k for its station" if design is not None else "the nominally equal bridges"
            out.append(f"{b.name}: k = {b.k:.4g} V/(N·m) differs by {rel:+.1%} from {basis} (after the common "
                       f"scale), more than {K_SPREAD_TOLERANCE:.0%}: check this gauge, its bonding and its bridge")
    if design is not None and abs(scale - 1) > K_SCALE_TOLERANCE:
        out.append(f"the calibrated k are on average {scale - 1:+.0%} from the design's prediction "
                   f"({np.mean(expected):.4g} V/(N·m)): check the gain, excitation, gauge factor and material")
    return out


def _span_warnings(design: DesignConstants, force_span, position_span) -> list[str]:
    out = []
    for label, unit, factor, (lo, hi), (clo, chi) in (
            ("force", "N", 1.0, design.force_range, force_span),
            ("position", "mm", 1e3, design.position_range, position_span)):
        tol = SPAN_TOLERANCE * (hi - lo)
        if clo > lo + tol or chi < hi - tol:
            out.append(f"the calibration loads span {label} {clo * factor:.4g}-{chi * factor:.4g} {unit} but the "
                       f"design's region is {lo * factor:.4g}-{hi * factor:.4g} {unit}: measurements outside the "
                       "calibrated span are extrapolated; add loads at the region's corners (fpdesign plan)")
    return out


# --------------------------------------------------------------------- measurement

def axis_covariance(k, d, z1, z2, sigma_v, calibration_covariance=None):
    """Covariance ``(c11, c12, c22)`` of one axis's ``(z1, z2)`` estimate (module docstring).

    ``k``, ``d``: (..., bridges); ``z1``, ``z2``: broadcastable leading shape;
    ``calibration_covariance``: Cov(b0, b1, b2) per bridge, (..., bridges, 3, 3), or None to
    leave out the calibration's own uncertainty.
    """
    k = np.asarray(k, dtype=float)
    d = np.asarray(d, dtype=float)
    m11, m12, m22 = estimator.normal_matrix_inverse(k, d)
    m11, m12, m22 = (np.asarray(m) for m in (m11, m12, m22))
    z1 = np.asarray(z1, dtype=float)
    z2 = np.asarray(z2, dtype=float)
    c11, c12, c22 = sigma_v ** 2 * m11, sigma_v ** 2 * m12, sigma_v ** 2 * m22
    if calibration_covariance is None:
        return c11 * np.ones_like(z1), c12 * np.ones_like(z1), c22 * np.ones_like(z1)
    u = np.stack(np.broadcast_arrays(np.ones_like(z1), z1, z2), axis=-1)[..., None, :]  # (..., 1, 3)
    C = np.asarray(calibration_covariance, dtype=float)
    e = np.einsum("...i,...ij,...j->...", u, C, u)                                   # (..., bridges)
    w = e * k * k
    s11 = np.sum(w, axis=-1)
    s12 = -np.sum(w * d, axis=-1)
    s22 = np.sum(w * d * d, axis=-1)
    # M S M for symmetric 2 x 2 M = [[m11, m12], [m12, m22]], S = [[s11, s12], [s12, s22]]
    p11, p12 = m11 * s11 + m12 * s12, m11 * s12 + m12 * s22
    p21, p22 = m12 * s11 + m22 * s12, m12 * s12 + m22 * s22
    return (c11 + p11 * m11 + p12 * m12, c12 + p11 * m12 + p12 * m22, c22 + p21 * m12 + p22 * m22)


@dataclass(frozen=True)
class Measurement:
    """Force, position and (biaxial) angle per row with their predicted 1-sigma (SI, rad)."""

    force: np.ndarray
    position: np.ndarray
    sigma_force: np.ndarray
    sigma_position: np.ndarray
    angle: np.ndarray | None = None
    sigma_angle: np.ndarray | None = None
    outside: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))  # beyond the calibrated span

    def __len__(self) -> int:
        return len(self.force)


def combine(z: dict, cov: dict) -> tuple:
    """``(F, x, theta, sigma_F, sigma_x, sigma_theta)`` from per-axis ``z = (z1, z2)`` and ``cov``.

    One axis (key ''): ``F = z2``, ``x = z1/z2``. Two axes ('y', 'z'): ``F = hypot(F_y, F_z)``,
    ``theta = atan2(F_z, F_y)``, ``x = (F_y z1_y + F_z z1_z) / F^2`` (the projection of the
    moments onto the force direction). theta and sigma_theta are None for one axis.
    """
    with np.errstate(divide="ignore", invalid="ignore"):   # a row with no load has no position
        return _combine(z, cov)


def _combine(z: dict, cov: dict) -> tuple:
    if "" in z:
        z1, z2 = z[""]
        c11, c12, c22 = cov[""]
        x = z1 / z2
        return (z2, x, None, np.sqrt(c22), np.sqrt(np.clip(c11 - 2 * x * c12 + x * x * c22, 0, None)) / np.abs(z2),
                None)
    (z1y, fy), (z1z, fz) = z["y"], z["z"]
    f2 = fy * fy + fz * fz
    force = np.sqrt(f2)
    angle = np.arctan2(fz, fy)
    x = (fy * z1y + fz * z1z) / f2
    var_f = (fy * fy * cov["y"][2] + fz * fz * cov["z"][2]) / f2
    var_a = (fz * fz * cov["y"][2] + fy * fy * cov["z"][2]) / (f2 * f2)
    var_x = 0.0
    for (z1a, fa), (c11, c12, c22) in ((z["y"], cov["y"]), (z["z"], cov["z"])):
        g1, g2 = fa / f2, (z1a - 2 * fa * x) / f2      # dx/dz1_a, dx/dz2_a
        var_x = var_x + g1 * g1 * c11 + 2 * g1 * g2 * c12 + g2 * g2 * c22
    return force, x, angle, np.sqrt(var_f), np.sqrt(np.clip(var_x, 0, None)), np.sqrt(var_a)


def measure(calibration: Calibration, voltages, noise: float | None = None,
            include_calibration: bool = True) -> Measurement:
    """Force and position (and angle) for every row of ``voltages`` (rows, bridges), in V.

    ``noise`` overrides the calibration's sigma_V. The predicted 1-sigma combines the reading's
    noise with the calibration constants' uncertainty (``include_calibration``); it is NaN when
    the calibration has no noise estimate and none is given.
    """
    V = np.atleast_2d(np.asarray(voltages, dtype=float))
    if V.shape[-1] != len(calibration.bridges):
        raise CsvError(f"readings have {V.shape[-1]} bridge columns; the calibration has "
                       f"{list(calibration.bridge_names)}")
    sigma = calibration.noise if noise is None else float(noise)
    z, cov = {}, {}
    for axis in calibration.axis_names:
        cols = [i for i, b in enumerate(calibration.bridges) if b.bridge.axis == axis]
        bs = [calibration.bridges[i] for i in cols]
        k = np.array([b.k for b in bs])
        d = np.array([b.d for b in bs])
        c = np.array([b.c for b in bs])
        f_axis, x_axis = estimator.estimate(V[:, cols], k, d, c)
        z[axis] = (f_axis * x_axis, f_axis)
        if sigma is None:
            cov[axis] = tuple(np.full(len(V), np.nan) for _ in range(3))
            continue
        ccov = (sigma ** 2 * np.array([b.unscaled_covariance for b in bs])) if include_calibration else None
        cov[axis] = axis_covariance(k, d, z[axis][0], z[axis][1], sigma, ccov)
    force, x, angle, sf, sx, sa = combine(z, cov)
    (f0, f1), (x0, x1) = calibration.force_span, calibration.position_span
    tol_f, tol_x = SPAN_TOLERANCE * (f1 - f0), SPAN_TOLERANCE * (x1 - x0)
    outside = ((np.abs(force) < f0 - tol_f) | (np.abs(force) > f1 + tol_f) | (x < x0 - tol_x) | (x > x1 + tol_x))
    return Measurement(force, x, sf, sx, angle, sa, outside)


def measure_readings(calibration: Calibration, readings: Readings, noise: float | None = None,
                     include_calibration: bool = True) -> Measurement:
    """``measure`` for a table of readings whose bridge columns must be the calibration's."""
    if tuple(b.name for b in readings.bridges) != calibration.bridge_names:
        raise CsvError(f"{readings.source}: header: bridge columns {[b.name for b in readings.bridges]} do not "
                       f"match the calibration's {list(calibration.bridge_names)}")
    return measure(calibration, readings.voltages, noise, include_calibration)


def predicted_sigma(k, d, loads: LoadSet, sigma_v: float, calibration_loads: LoadSet | None = None,
                    axes: int = 1):
    """Predicted 1-sigma ``(sigma_F, sigma_x, sigma_theta)`` at true ``loads`` (no data needed).

    ``k``, ``d`` per station. With ``calibration_loads`` (the rows of a calibration, repeats
    included) the calibration constants' uncertainty is added, for the same sigma_V.
    """
    k = np.asarray(k, dtype=float)
    d = np.asarray(d, dtype=float)
    z, cov = {}, {}
    for axis in (("",) if axes == 1 else ("y", "z")):
        fa = axis_force(loads.force, loads.angle, axis)
        z[axis] = (fa * loads.position, fa)
        ccov = None
        if calibration_loads is not None:
            X = design_matrix(axis_force(calibration_loads.force, calibration_loads.angle, axis),
                              calibration_loads.position)
            ccov = np.broadcast_to(sigma_v ** 2 * np.linalg.inv(X.T @ X), k.shape + (3, 3))
        cov[axis] = axis_covariance(k, d, z[axis][0], z[axis][1], sigma_v, ccov)
    _, _, _, sf, sx, sa = combine(z, cov)
    return sf, sx, sa


# --------------------------------------------------------------------- the calibration plan

@dataclass(frozen=True)
class SchemePrediction:
    """One calibration scheme and its predicted effect on later measurements (worst case)."""

    scheme: str                   # "4" | "9"
    loads: LoadSet                # the distinct loads (each hung ``repeats`` times)
    repeats: int
    force_error: float            # max sigma_F/F over the region, reading noise only
    force_error_calibrated: float  # ... with the calibration constants' uncertainty
    position_error: float         # max sigma_x over the region, m
    position_error_calibrated: float
    angle_error: float | None = None          # max sigma_theta, rad (biaxial)
    angle_error_calibrated: float | None = None

    @property
    def loadings(self) -> int:
        return len(self.loads) * self.repeats


@dataclass(frozen=True)
class CalibrationPlan:
    design: DesignConstants
    schemes: tuple[SchemePrediction, ...]


#: Region samples per side for the worst-case search of a plan (corners included).
PLAN_GRID = 21


def plan(design: DesignConstants, repeats: int = 1) -> CalibrationPlan:
    """The 4- and 9-point schemes of section 3.3 and their predicted effect on measurement.

    Worst cases are over a PLAN_GRID x PLAN_GRID grid of the design's region (and, biaxial, the
    angles 0-90 degrees), with and without the calibration constants' uncertainty, each load of
    the scheme hung ``repeats`` times.
    """
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise InputError(f"repeats: {repeats!r} must be a whole number >= 1")
    (f0, f1), (x0, x1) = design.force_range, design.position_range
    region = _product(np.linspace(f0, f1, PLAN_GRID), np.linspace(x0, x1, PLAN_GRID), GRID_ANGLES_DEG,
                      design.axes)
    k, d, sigma = design.sensitivity, design.stations, design.noise
    plain = predicted_sigma(k, d, region, sigma, axes=design.axes)
    out = []
    for scheme in ("4", "9"):
        loads = scheme_loads(design, scheme)
        cal = predicted_sigma(k, d, region, sigma, loads.repeated(repeats), axes=design.axes)
        angle = (float(np.max(plain[2])), float(np.max(cal[2]))) if design.axes == 2 else (None, None)
        out.append(SchemePrediction(scheme, loads, repeats,
                                    float(np.max(plain[0] / region.force)), float(np.max(cal[0] / region.force)),
                                    float(np.max(plain[1])), float(np.max(cal[1])), *angle))
    return CalibrationPlan(design, tuple(out))
