"""Calibration loads (the paper's schemes) and a plan's predicted effect on measurement."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.calibration.data import STANDARD_GRAVITY, LoadSet
from designer.calibration.design import DesignConstants
from designer.calibration.measurement import predicted_sigma
from designer.errors import InputError
from designer.names import SCHEMES

# --------------------------------------------------------------------- load schemes

#: The paper's section 4.3 Monte Carlo grid: 7 loads by 7 positions over the region.
GRID_POINTS = 7
#: Biaxial load angles of section 4.2.1: 0 to 90 degrees in 15 degree steps.
GRID_ANGLES_DEG = tuple(range(0, 91, 15))
#: Biaxial calibration loads each scheme point along both bending axes.
CALIBRATION_ANGLES_DEG = (0.0, 90.0)
#: The paper's Table 2: masses (g), positions (mm) and, for C, angles (degrees, section 4.2.1).
PAPER_TABLE2 = {
    "A": ((250, 500, 1000, 1500, 2000), tuple(range(150, 651, 50)), (0,)),
    "B": ((20, 50, 70, 100, 300, 500, 1500, 2000, 2500, 3000), tuple(range(150, 451, 50)), (0,)),
    "C": ((250, 500, 1000, 1500, 2000), tuple(range(100, 201, 20)), tuple(range(0, 91, 15))),
}


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
