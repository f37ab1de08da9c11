"""Monte Carlo of the estimator (the paper's section 4.3), vectorised with numpy.

At every point of a grid over the operating region, ``draws`` sets of bridge outputs get
independent Gaussian noise of ``sigma_V`` per channel; force and position are estimated by
least squares and their spread is set beside the analytic 1-sigma of MODEL.md section 3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.model import estimator

CHUNK = 250_000  # draws per batch: bounds memory at a few tens of MB


@dataclass(frozen=True)
class SimulationResult:
    force: np.ndarray            # grid forces, N (flattened grid)
    position: np.ndarray         # grid positions, m
    sigma_force_mc: np.ndarray   # standard deviation of the force estimate, N
    sigma_force: np.ndarray      # analytic
    sigma_position_mc: np.ndarray
    sigma_position: np.ndarray
    mean_abs_force_error: np.ndarray     # mean |F_hat - F| / F (the paper's percent error)
    mean_abs_position_error: np.ndarray  # mean |x_hat - x| / x
    draws: int
    angle: float | None = None           # biaxial: load angle, rad
    sigma_angle_mc: np.ndarray | None = None
    sigma_angle: np.ndarray | None = None

    @property
    def worst_ratio(self) -> float:
        """Largest |MC / analytic - 1| over the grid, force and position."""
        r = np.concatenate([self.sigma_force_mc / self.sigma_force, self.sigma_position_mc / self.sigma_position])
        if self.sigma_angle is not None:
            r = np.concatenate([r, self.sigma_angle_mc / self.sigma_angle])
        return float(np.max(np.abs(r - 1)))


def grid(f_min, f_max, x_min, x_max, n_force=7, n_position=7):
    """The paper's 7 x 7 grid: evenly spaced forces and positions, as flat arrays."""
    F, X = np.meshgrid(np.linspace(f_min, f_max, n_force), np.linspace(x_min, x_max, n_position), indexing="ij")
    return F.ravel(), X.ravel()


def simulate(k, d, sigma_v, forces, positions, draws=100_000, seed=0, angle=None) -> SimulationResult:
    """Monte Carlo at each (force, position); ``angle`` (rad) makes it biaxial (two axes)."""
    rng = np.random.default_rng(seed)
    k = np.asarray(k, dtype=float)
    d = np.asarray(d, dtype=float)
    zeros = np.zeros_like(k)
    n = len(forces)
    out = {name: np.empty(n) for name in ("sf", "sx", "ef", "ex", "sa")}
    # Noise buffers reused at every grid point (two axes need two).
    buffers = np.empty((1 if angle is None else 2, min(CHUNK, draws), len(k)))
    for i, (F, x) in enumerate(zip(forces, positions)):
        f_hat, x_hat, a_hat = _draw(rng, k, d, zeros, sigma_v, F, x, draws, angle, buffers)
        out["sf"][i] = f_hat.std()
        out["sx"][i] = x_hat.std()
        out["ef"][i] = np.mean(np.abs(f_hat - F)) / F
        out["ex"][i] = np.mean(np.abs(x_hat - x)) / x
        # the angle's spread about the load's, each estimate within half a turn of it: at 180 deg
        # the estimates fall on both sides of -180/180 deg, and their own spread was a whole turn
        out["sa"][i] = np.angle(np.exp(1j * (a_hat - angle))).std() if a_hat is not None else np.nan
    sigma_f = np.full(n, estimator.sigma_force(k, d, sigma_v))
    sigma_x = estimator.sigma_position(k, d, sigma_v, np.asarray(forces), np.asarray(positions))
    biaxial = angle is not None
    return SimulationResult(np.asarray(forces), np.asarray(positions), out["sf"], sigma_f, out["sx"], sigma_x,
                            out["ef"], out["ex"], draws, angle,
                            out["sa"] if biaxial else None,
                            sigma_f / np.asarray(forces) if biaxial else None)


def _noisy(rng, out, sigma_v, clean):
    """``clean`` outputs plus Gaussian noise of ``sigma_v``, written into ``out``.

    The same numbers as ``clean + rng.normal(0, sigma_v, out.shape)``, without its temporaries.
    """
    rng.standard_normal(out=out)
    out *= sigma_v
    out += clean
    return out


def _draw(rng, k, d, c, sigma_v, F, x, draws, angle, buffers):
    f_parts, x_parts, a_parts = [], [], []
    for start in range(0, draws, CHUNK):
        m = min(CHUNK, draws - start)
        if angle is None:
            v = _noisy(rng, buffers[0, :m], sigma_v, estimator.bridge_voltages(k, d, c, F, x))
            f_hat, x_hat = estimator.estimate(v, k, d, c)
            f_parts.append(f_hat)
            x_parts.append(x_hat)
            continue
        fy, fz = F * np.cos(angle), F * np.sin(angle)
        vy = _noisy(rng, buffers[0, :m], sigma_v, estimator.bridge_voltages(k, d, c, fy, x))
        vz = _noisy(rng, buffers[1, :m], sigma_v, estimator.bridge_voltages(k, d, c, fz, x))
        f_mag, a_hat, x_hat = estimate_biaxial(vy, vz, k, d, c, c)
        f_parts.append(f_mag)
        x_parts.append(x_hat)
        a_parts.append(a_hat)
    if len(f_parts) == 1:
        return f_parts[0], x_parts[0], a_parts[0] if a_parts else None
    a = np.concatenate(a_parts) if a_parts else None
    return np.concatenate(f_parts), np.concatenate(x_parts), a


def estimate_biaxial(vy, vz, k, d, cy, cz):
    """Force magnitude, angle (rad, from the y axis) and position from two axes of bridges.

    Each axis is a 1-D least-squares problem giving ``(F_y x, F_y)`` and ``(F_z x, F_z)``, combined
    by ``estimator.combine_axes`` (the position is the projection on the force direction).
    """
    fy, xy = estimator.estimate(vy, k, d, cy)
    fz, xz = estimator.estimate(vz, k, d, cz)
    return estimator.combine_axes((fy * xy, fy), (fz * xz, fz))
