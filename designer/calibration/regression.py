"""The calibration regression of the paper's eq. 27 (MODEL.md section 3).

Each bridge reads ``V = c + k F (x - d)``; with ``z1 = F x`` and ``z2 = F`` this is the
multiple regression ``V = b0 + b1 z1 + b2 z2``, and the constants follow from eqs. 28-30:
``c = b0``, ``k = b1``, ``d = -b2 / b1``. Pure numpy; used by calibration and by the
large-deflection check's simulated linear calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Loads and positions closer than this count as the same (m and N alike, far below any use).
SAME_VALUE = 1e-9
#: Above this (column-scaled) condition number the calibration loads do not determine k, d, c.
MAX_CONDITION = 1e8


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
