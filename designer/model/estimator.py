"""Least-squares force and position estimation from N >= 2 bridges (docs/model.md §3).

Rows ``V_i - c_i = k_i z1 - k_i d_i z2`` with ``z1 = F x`` and ``z2 = F``; then
``F = z2`` and ``x = z1 / z2``. For two stations this is exactly the paper's eqs. 11-12.
Everything here is vectorised with numpy over any leading shape.
"""

from __future__ import annotations

import numpy as np

from designer.model.ops import NUMERIC, Ops


def normal_matrix_inverse(k, d):
    """``(A^T A)^-1`` entries ``(m11, m12, m22)`` for rows ``A_i = [k_i, -k_i d_i]``.

    ``k`` and ``d`` have the station on the last axis. ``Cov(z) = sigma_V^2 (A^T A)^-1``.
    Written with plain arithmetic so that casadi expressions pass through unchanged.
    """
    s0 = sum(ki * ki for ki in _stations(k))
    s1 = sum(ki * ki * di for ki, di in zip(_stations(k), _stations(d)))
    s2 = sum(ki * ki * di * di for ki, di in zip(_stations(k), _stations(d)))
    det = s0 * s2 - s1 * s1
    # A^T A = [[s0, -s1], [-s1, s2]]  ->  inverse = [[s2, s1], [s1, s0]] / det
    return s2 / det, s1 / det, s0 / det


def _stations(values):
    if isinstance(values, np.ndarray):
        return [values[..., i] for i in range(values.shape[-1])]
    return list(values)


def sigma_force(k, d, sigma_v, ops: Ops = NUMERIC):
    """1-sigma of the force estimate, N (independent of the load and its position):
    ``sigma_V sqrt(Cov22)`` with ``Cov = (A^T A)^-1`` (docs/model.md §3)."""
    return _sigma_force(normal_matrix_inverse(k, d), sigma_v, ops)


def sigma_position(k, d, sigma_v, force, position, ops: Ops = NUMERIC):
    """1-sigma of the position estimate at ``(force, position)``, m (linear propagation):
    ``sigma_V sqrt(Cov11 - 2 x Cov12 + x^2 Cov22) / F`` (docs/model.md §3)."""
    return _sigma_position(normal_matrix_inverse(k, d), sigma_v, force, position, ops)


def sigmas(k, d, sigma_v, force, position, ops: Ops = NUMERIC):
    """``(sigma_F, sigma_x(force, position))`` from one normal matrix (one casadi subgraph)."""
    m = normal_matrix_inverse(k, d)
    return _sigma_force(m, sigma_v, ops), _sigma_position(m, sigma_v, force, position, ops)


def _sigma_force(m, sigma_v, ops):
    return sigma_v * ops.sqrt(m[2])


def _sigma_position(m, sigma_v, force, position, ops):
    m11, m12, m22 = m
    return sigma_v * ops.sqrt(m11 - 2 * position * m12 + position * position * m22) / force


def bridge_voltages(k, d, c, force, position):
    """Noise-free bridge outputs ``V_i = k_i F (x - d_i) + c_i``; station on the last axis."""
    k, d, c = (np.asarray(a, dtype=float) for a in (k, d, c))
    force = np.asarray(force, dtype=float)[..., None]
    position = np.asarray(position, dtype=float)[..., None]
    return k * force * (position - d) + c


def estimate(voltages, k, d, c):
    """Least-squares ``(F, x)`` from bridge outputs with the station on the last axis."""
    v = np.asarray(voltages, dtype=float)
    c = np.asarray(c, dtype=float)
    k = np.asarray(k, dtype=float)
    d = np.asarray(d, dtype=float)
    m11, m12, m22 = normal_matrix_inverse(k, d)
    # A^T (v - c) = [sum k (v - c), -sum k d (v - c)]
    if k.ndim == d.ndim == c.ndim == 1:
        # One calibration for every reading: matrix products, with no temporary of the readings'
        # size; numpy's element-wise work over a short last axis is about 10x slower.
        kd = k * d
        b1 = v @ k - c @ k
        b2 = c @ kd - v @ kd
    else:
        v = v - c
        b1 = np.sum(k * v, axis=-1)
        b2 = -np.sum(k * d * v, axis=-1)
    z1 = m11 * b1 + m12 * b2
    z2 = m12 * b1 + m22 * b2
    return z2, z1 / z2


# ----------------------------------------------------------------- two bending axes (biaxial)

def combine_axes(y, z):
    """Force magnitude, angle (rad, from the y axis towards z) and position from the two axes of
    a biaxial sensor, each given as its estimate ``(z1, z2) = (F_a x, F_a)``:
    ``F = hypot(F_y, F_z)``, ``theta = atan2(F_z, F_y)`` and ``x = (F_y z1_y + F_z z1_z) / F^2``,
    the projection of the moments onto the force direction. Numpy, any leading shape."""
    (z1y, fy), (z1z, fz) = y, z
    f2 = fy * fy + fz * fz
    return np.sqrt(f2), np.arctan2(fz, fy), (fy * z1y + fz * z1z) / f2


def combine_axes_sigmas(y, z, cov_y, cov_z):
    """1-sigma ``(sigma_F, sigma_theta, sigma_x)`` of ``combine_axes`` by linear propagation from
    each axis's covariance ``(c11, c12, c22)`` of its ``(z1, z2)``, the two axes independent."""
    (_, fy), (_, fz) = y, z
    f2 = fy * fy + fz * fz
    x = combine_axes(y, z)[2]
    var_f = (fy * fy * cov_y[2] + fz * fz * cov_z[2]) / f2
    var_a = (fz * fz * cov_y[2] + fy * fy * cov_z[2]) / (f2 * f2)
    var_x = 0.0
    for (z1a, fa), (c11, c12, c22) in ((y, cov_y), (z, cov_z)):
        g1, g2 = fa / f2, (z1a - 2 * fa * x) / f2      # dx/dz1_a, dx/dz2_a
        var_x = var_x + g1 * g1 * c11 + 2 * g1 * g2 * c12 + g2 * g2 * c22
    return np.sqrt(var_f), np.sqrt(var_a), np.sqrt(np.clip(var_x, 0, None))
