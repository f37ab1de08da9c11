"""Calibration: fit every bridge's c, k and d to readings at known loads (eqs. 27-30).

Pure computation (no files, no printing): the regression itself is ``regression.regress``;
this module chooses the noise sigma_V for the standard errors and says what looks wrong
(poor fits, outliers, odd bridges, loads that do not span the design's region).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from designer.calibration.data import Readings, axis_force
from designer.calibration.design import DesignConstants
from designer.calibration.record import (LARGEST_STATION, SIGNIFICANT_SIGMAS, SPAN_TOLERANCE, BridgeCalibration,
                                         Calibration, coincident_stations)
from designer.calibration.regression import SAME_VALUE, rank_problem, regress
# CalibrationFileError lives in designer.errors; it stays importable from here, its old home.
from designer.errors import CalibrationFileError, CsvError, InputError  # noqa: F401
from designer.names import NOISE_CHOICES
from designer.spec.units import RANGES

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
#: False-alarm rate of the outlier test: the probability that clean readings (normal noise of
#: equal sigma_V on every channel, the bridges linear in F and F x) flag any row of a calibration.
#: Each row is tested at OUTLIER_ALPHA / (rows x axes) (Bonferroni), so the rate is at most this.
OUTLIER_ALPHA = 0.01
#: Bridges of one design are nominally identical (MODEL.md: the same feature at every station).
#: Gauge-factor tolerance (about 1 %), placement and bonding give a few per cent of spread
#: between bridges; more than 5 % beyond what the design predicts points to a bad gauge or bridge.
K_SPREAD_TOLERANCE = 0.05
#: The design's k is built from E, G, gain, excitation and the section (the paper's "stack-up"
#: of section 3.3); a common scale error beyond 25 % suggests a wrong gain or wiring.
K_SCALE_TOLERANCE = 0.25
#: A fitted station d further than this from the design's (hand placement of a gauge), m.
D_TOLERANCE = 2e-3

#: Calibration loads whose moments F·x span less than this share of the largest are blamed rather
#: than the bridge when a bridge's k cannot be told from zero (the schemes span 0.9 and more)
MOMENT_SPREAD = 0.1
#: A bridge column whose readings span less than this over the calibration loads does not respond
#: to them (V): the smallest voltage fpdesign handles (spec.units.RANGES), far below the step of
#: any converter (a 32-bit converter over +-1 mV: 0.5 pV).
MIN_RESPONSE = RANGES["voltage"][0]


def _mm(value: float) -> str:
    return f"{value * 1e3:.4g} mm"


def _mv(value: float) -> str:
    return f"{value * 1e3:.3g} mV"


def calibrate(readings: Readings, design: DesignConstants | None = None, noise: str = "auto",
              design_option: str | None = None) -> Calibration:
    """Fit eq. 27 to every bridge and derive c, k, d (eqs. 28-30) with standard errors.

    ``noise`` chooses sigma_V for the standard errors and later measurements: ``residual``
    (the pooled residual RMS), ``design`` (the design's sigma_V) or ``auto`` (the residual RMS
    when it has at least MIN_NOISE_DOF degrees of freedom, else the design's, else the residual
    RMS with a warning). Bad readings raise CsvError naming the row and column.
    ``design_option``: how the caller lets a user give the design (a command-line flag), named
    in the advice of messages; by default they say "a design".
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
        raise CsvError(f"{readings.source}: biaxial readings ({readings.column(0)}, ...) need an angle_deg "
                       "column giving the direction of every load")
    if design is not None and tuple(b.name for b in readings.bridges) != tuple(b.name for b in design.bridges):
        raise CsvError(f"{readings.source}: header: the bridge columns "
                       f"{[readings.column(j) for j in range(len(readings.bridges))]} do not "
                       f"match the design's {len(design.stations)} station(s) x {design.axes} axis/axes: "
                       f"expected {[b.column(readings.file_counts) for b in design.bridges]}")
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
    _refuse_constant_columns(readings)

    dof_total = sum(fit.dof * len(cols) for cols, fit in fits.values())
    rss_total = sum(float(np.sum(fit.rss)) for _, fit in fits.values())
    residual_noise = math.sqrt(rss_total / dof_total) if dof_total > 0 else None
    design_noise = design.noise if design is not None else None
    sigma, source, warnings = _choose_noise(noise, residual_noise, dof_total, design_noise, n, readings.source,
                                            design_option)
    _refuse_unresponsive(readings, fits, None if source == "residual" else sigma)

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
    same = coincident_stations(bridges)
    if same:
        raise CsvError(f"{readings.source}: {readings.row(0)} to {readings.row(n - 1)}, columns "
                       f"{', '.join(bridges[i].name for i in same)}: all fit one station, "
                       f"d = {bridges[same[0]].d:.6g} m, "
                       "so force and position cannot be told apart; check that they are not one bridge read twice")

    magnitude = np.abs(loads.force)
    loaded = magnitude > SAME_VALUE
    force_span = (float(magnitude[loaded].min()), float(magnitude[loaded].max()))
    position_span = (float(loads.position[loaded].min()), float(loads.position[loaded].max()))
    warnings += _fit_warnings(readings, bridges, fits, residual_noise, dof_total, design,
                              force_span, position_span)
    return Calibration(bridges, n, sigma, source, residual_noise, dof_total, design_noise, force_span,
                       position_span, design.name if design is not None else None, tuple(warnings),
                       readings.source)


def _refuse_constant_columns(readings: Readings) -> None:
    """CsvError for a bridge column that does not change with the load: the same value in every
    row (a disconnected bridge or amplifier, a column of zeros), or values that span less than
    MIN_RESPONSE. Such a column carries no k, and d = -b2/b1 would be 0/0."""
    n = len(readings)
    for j, bridge in enumerate(readings.bridges):
        column = readings.voltages[:, j]
        spread = float(np.ptp(column))
        if spread >= MIN_RESPONSE:
            continue
        why = (("it reads the same count in every row" if readings.counted else
                f"it reads {float(column[0])!r} V in every row") if spread == 0 else
               f"its readings span only {spread:.3g} V, less than the {MIN_RESPONSE:g} V fpdesign resolves")
        raise CsvError(f"{readings.source}: {readings.row(0)} to {readings.row(n - 1)}, column {readings.column(j)}: "
                       f"does not respond to the load: {why}, and a bridge's reading must change with the load; "
                       "check the bridge's wiring")


def _refuse_unresponsive(readings: Readings, fits: dict, sigma: float | None) -> None:
    """CsvError for a bridge whose fitted k cannot be told from zero: within SIGNIFICANT_SIGMAS
    standard errors of it (a bridge that reads noise, not the load), or so small that
    d = -b2/k is not a number.

    The standard error is ``s sqrt((X^T X)^-1_11)`` with ``s`` the larger of ``sigma`` (a given
    or the design's sigma_V; None for the residuals') and the bridge's own residual RMS
    (``sqrt(RSS / dof)``), so that a bridge reading pure noise is refused whether or not that
    noise is the design's, and a bridge is not judged by the residuals pooled from another (a
    bad reading in one column). A real bridge's k lies
    hundreds of standard errors from zero at the design's noise; within three, k is not known
    to 33 % and no measurement could use it.
    """
    n = len(readings)
    moment = np.abs(np.asarray(readings.force) * np.asarray(readings.position))
    spread = float(np.ptp(moment) / np.max(moment)) if np.max(moment) > 0 else 0.0
    for cols, fit in fits.values():
        own = np.sqrt(fit.rss / fit.dof) if fit.dof > 0 else np.zeros(len(cols))
        se_k = np.maximum(own, sigma or 0.0) * math.sqrt(fit.unscaled_covariance[1, 1])
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            d = fit.d
        for j, col in enumerate(cols):
            k, se = float(fit.k[j]), float(se_k[j])
            if abs(k) > SIGNIFICANT_SIGMAS * se and abs(d[j]) <= LARGEST_STATION:
                continue
            if spread < MOMENT_SPREAD:
                # a moment F·x that barely changes from row to row leaves k unknown whatever the
                # bridge: the loads are at fault, not the wiring
                raise CsvError(f"{readings.source}: {readings.row(0)} to {readings.row(n - 1)}, column "
                               f"{readings.column(col)}: its k cannot be told from zero, and the loads' moments "
                               f"F·x span {spread:.2g} of the largest: the loads cannot determine k and d; load at "
                               "moments further apart (fpdesign plan gives the 4- and 9-point schemes)")
            why = (f"its fitted k = {k:.3g} V/(N·m) is within {SIGNIFICANT_SIGMAS:g} standard errors "
                   f"({se:.2g} V/(N·m)) of zero" if abs(k) <= SIGNIFICANT_SIGMAS * se else
                   f"its fitted k = {k:.3g} V/(N·m) places its station d = -b2/k at {d[j]:.3g} m, beyond the "
                   f"{LARGEST_STATION:g} m a beam can be")
            bad = [o for o in outlier_rows(fit, OUTLIER_ALPHA / (n * len(fits))) if o.bridge == j]
            check = ("check the bridge's wiring and its gauges" if not bad else
                     f"{readings.row(bad[0].row)} lies {abs(bad[0].t):.0f} standard deviations off the fit of the "
                     "other rows: check that reading, then the bridge's wiring")
            raise CsvError(f"{readings.source}: {readings.row(0)} to {readings.row(n - 1)}, column "
                           f"{readings.column(col)}: does not respond to the load: {why}, and a bridge's "
                           f"reading must follow the load's moment F·x; {check}")


def _choose_noise(choice: str, residual_noise, dof: int, design_noise, n: int, source: str,
                  design_option: str | None = None):
    """``(sigma_V or None, its source, warnings)`` for the noise ``choice`` (see ``calibrate``)."""
    give = design_option or "a design"
    if choice == "residual":
        if residual_noise is None:
            raise CsvError(f"{source}: {n} rows leave no residual to estimate the noise from; add calibration "
                           "points or choose the design's noise")
        return residual_noise, "residual", []
    if choice == "design":
        if design_noise is None:
            where = f"{design_option} design.json" if design_option else "a design.json"
            key = "--noise" if design_option else "noise"   # (the command line's flag, or the call's argument)
            raise InputError(f"{key}: 'design' needs a design ({where})")
        return design_noise, "design", []
    if residual_noise is not None and dof >= MIN_NOISE_DOF:
        return residual_noise, "residual", []
    if design_noise is not None:
        return design_noise, "design", []
    if residual_noise is not None:
        return residual_noise, "residual", [
            f"the noise estimate ({_mv(residual_noise)}) rests on only {dof} residual degrees of freedom; "
            f"standard errors are rough (give {give}, or use {MIN_NOISE_DOF}+ residual dof)"]
    return None, "none", [f"{n} rows fit exactly: no noise estimate, so no standard errors; give {give} or "
                          "calibrate with more points"]


def _fit_warnings(readings, bridges, fits, residual_noise, dof_total, design, force_span,
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
    tests = n * len(fits)
    for axis, (cols, fit) in fits.items():
        for o in outlier_rows(fit, OUTLIER_ALPHA / tests):
            out.append(_outlier_message(readings, o, readings.column(cols[o.bridge]), tests))
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


@dataclass(frozen=True)
class Outlier:
    """A calibration row that the leave-one-out test flags (``outlier_rows``)."""

    row: int
    statistic: float     # F of the row's mean shift, F(m, m (n - p - 1)) for a clean row
    p_value: float
    bridge: int          # the fit's column (bridge) whose deleted residual is largest
    residual: float      # that bridge's deleted residual e / (1 - h), V
    t: float             # ... externally studentized: e / (s_(i) sqrt(1 - h))


def outlier_rows(fit, alpha: float) -> list[Outlier]:
    """The rows of one regression (eq. 27 fitted to m bridges over the same n loads) whose
    readings lie off the fit of the other rows, at significance ``alpha`` per row.

    The mean-shift outlier test with leave-one-out (externally studentized) residuals (Cook &
    Weisberg 1982, *Residuals and Influence in Regression*, §2.2.2; Montgomery, Peck & Vining
    2012, *Introduction to Linear Regression Analysis*, 5th ed., §4.2.1, "R-student"), pooled
    over the m bridges, whose noise is independent with one sigma_V: giving row i a shift of
    its own in every bridge lowers the residual sum of squares by
    ``Q_i = sum_j e_ij^2 / (1 - h_ii)``; the fit without row i keeps
    ``RSS_(i) = RSS - Q_i`` on ``m (n - p - 1)`` degrees of freedom, independent of ``Q_i``; so
    ``F_i = (Q_i / m) / (RSS_(i) / (m (n - p - 1)))`` follows F(m, m (n - p - 1)) for a clean
    row (for m = 1, the square of the externally studentized residual, t(n - p - 1)). The spread
    is that of the other rows, so a bad row cannot hide by inflating it (a residual scored
    against its own fit's spread is bounded by sqrt(n - p): 2.45 for the 9-point scheme).
    A row misplaced by dx shifts bridge j by k_j F dx, and F_i then follows the noncentral F with
    ``lambda = (1 - h_ii) sum_j (k_j F dx)^2 / sigma_V^2``.
    """
    from scipy import stats

    e = np.asarray(fit.residuals, dtype=float)
    n, m = e.shape
    p = n - fit.dof
    dof = m * (n - p - 1)
    if dof < 1:
        return []
    h = np.asarray(fit.leverage, dtype=float)
    testable = 1 - h > 1e-9                          # a row the fit passes through exactly has no test
    q = np.where(testable, np.sum(e ** 2, axis=1) / np.where(testable, 1 - h, 1.0), 0.0)
    s2 = np.clip(float(np.sum(e ** 2)) - q, 0.0, None) / dof    # the spread without row i
    testable &= s2 > 0
    f = np.where(testable, (q / m) / np.where(testable, s2, 1.0), 0.0)
    p_values = np.where(testable, stats.f.sf(f, m, dof), 1.0)
    out = []
    for i in np.nonzero(p_values < alpha)[0]:
        t = e[i] / np.sqrt(s2[i] * (1 - h[i]))
        j = int(np.argmax(np.abs(t)))
        out.append(Outlier(int(i), float(f[i]), float(p_values[i]), j, float(e[i, j] / (1 - h[i])), float(t[j])))
    return out


def _outlier_message(readings, o: Outlier, name: str, tests: int) -> str:
    loads = readings.loads
    row = o.row
    where = (f"{readings.row(row)} (force {loads.force[row]:.4g} N, position {loads.position[row] * 1e3:.4g} mm)"
             if loads is not None else readings.row(row))
    return (f"{where}, column {name}: the row lies off the fit of the other rows: leave-one-out residual "
            f"{_mv(o.residual)}, {abs(o.t):.1f} standard deviations from the fit (outlier test p = {o.p_value:.2g}, "
            f"below {OUTLIER_ALPHA:g}/{tests}): a misplaced or mis-recorded load?")


def _k_warnings(bridges, design) -> list[str]:
    """Bridges whose k differ from one another more than the design predicts, in size: a reversed
    bridge (k < 0, wired the other way round) has its own warning and measures all the same."""
    k = np.abs([b.k for b in bridges])
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
