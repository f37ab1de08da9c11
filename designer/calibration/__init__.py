"""Calibration of a built sensor and measurement with it (SPEC.md, MODEL.md section 3).

``data`` (bridges, loads, readings) and ``design`` (what a design.json predicts) feed
``regression`` (eq. 27), ``fit`` (calibrate: constants, noise, warnings, into a ``record``),
``measurement`` (force, position, angle and their 1-sigma) and ``schemes`` (calibration loads
and the plan of their predicted effect). ``readings`` reads and writes the files (readings.csv,
calibration.json, plan and results CSVs) and simulates readings; it is imported on its own, being
the only module here that touches files.

The names below are the package's public interface; inside the package, modules import from
the module that defines a name.
"""

import types as _types

from designer.calibration.data import STANDARD_GRAVITY, Bridge, LoadSet, Readings, axis_force, bridges_for
from designer.calibration.design import PROTOTYPE_MATCH, PROTOTYPE_SECTIONS, DesignConstants, design_constants
from designer.calibration.fit import (D_TOLERANCE, K_SCALE_TOLERANCE, K_SPREAD_TOLERANCE, MIN_NOISE_DOF,
                                      MIN_POINTS, MIN_RESPONSE, MIN_R2, NOISE_CHOICES, NOISE_TEST_P, OUTLIER_ALPHA,
                                      RECOMMENDED_POINTS, Outlier, calibrate, outlier_rows)
from designer.calibration.measurement import (Measurement, axis_covariance, combine, measure, measure_readings,
                                              predicted_sigma)
from designer.calibration.schemes import (CALIBRATION_ANGLES_DEG, GRID_ANGLES_DEG, GRID_POINTS, PAPER_TABLE2,
                                          PLAN_GRID, SCHEMES, CalibrationPlan, SchemePrediction, plan, scheme_loads)
from designer.calibration.record import (CALIBRATION_VERSION, COVARIANCE_ROUNDING, LARGEST_K, LARGEST_STATION,
                                         SIGNIFICANT_SIGMAS, SPAN_TOLERANCE, BridgeCalibration, Calibration)
from designer.calibration.regression import (MAX_CONDITION, SAME_VALUE, Regression, design_matrix, rank_problem,
                                             regress)
from designer.errors import CalibrationFileError

__all__ = [name for name, value in dict(globals()).items()
           if not name.startswith("_") and not isinstance(value, _types.ModuleType)]
