"""Measurement: force, position and (biaxial) angle from bridge readings, with their 1-sigma.

A measurement solves the bridges' equations for ``(z1, z2) = (F x, F)`` by least squares
(``designer.model.estimator``), so ``F = z2`` and ``x = z1 / z2`` (eqs. 11-12 for two
bridges). A biaxial sensor (two axes) has one bridge per axis at every station; each axis is
its own one-dimensional problem on the force component ``F_y = F cos(theta)``,
``F_z = F sin(theta)``, and the two are combined by ``estimator.combine_axes``.

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

from designer.calibration.data import LoadSet, Readings, axis_force
from designer.calibration.record import SPAN_TOLERANCE, Calibration
from designer.calibration.regression import design_matrix
from designer.errors import CsvError
from designer.model import estimator


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

    One axis (key ''): ``F = z2``, ``x = z1/z2``. Two axes ('y', 'z'): ``estimator.combine_axes``
    and ``estimator.combine_axes_sigmas``. theta and sigma_theta are None for one axis.
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
    force, angle, x = estimator.combine_axes(z["y"], z["z"])
    sigma_f, sigma_a, sigma_x = estimator.combine_axes_sigmas(z["y"], z["z"], cov["y"], cov["z"])
    return force, x, angle, sigma_f, sigma_x, sigma_a


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


# The RMS of a measurement's errors against known loads in units of their predicted 1-sigma
# (``error_ratios``) above which the readings do not fit the calibration. Over 1800 simulated
# sensors measured as they were calibrated (the weigh-bar example, Prototypes B and C, 4- and
# 9-point schemes, sigma_V from the residuals) the largest ratio stayed within 0.58-2.38; with one
# bridge's zero moved by 10 sigma_V it was 4.0-10.4, with Prototype C turned by 3 degrees 5.2-15
# (benchmarks/measure_ratio_check.md).
CONSISTENT_RATIO = 3.0


def error_ratios(m: Measurement, force, position, angle=None) -> tuple[float, ...]:
    """The RMS, over the rows with a load, of the force's and the position's error against the
    known ``force`` and ``position`` in units of their predicted 1-sigma: about 1 when the readings
    are of the calibrated sensor and its noise is the calibration's sigma_V (each row's 1-sigma
    holds the reading's noise and the calibration's own uncertainty); NaN without a 1-sigma.

    A biaxial measurement with the known ``angle`` (rad) gives the angle's third (its error taken
    the short way round the circle): a sensor turned in its clamp since calibrating reads the
    force and position right and only the angle wrong."""
    force, position = np.asarray(force, dtype=float), np.asarray(position, dtype=float)
    loaded = np.abs(force) > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        z = [(m.force - force) / m.sigma_force, (m.position - position) / m.sigma_position]
        if m.angle is not None and angle is not None:
            z.append(np.angle(np.exp(1j * (m.angle - np.asarray(angle, dtype=float)))) / m.sigma_angle)
    return tuple(float(np.sqrt(np.mean(e[loaded] ** 2))) if np.isfinite(e[loaded]).all() and loaded.any()
                 else math.nan for e in z)


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
