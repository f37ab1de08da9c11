"""Large deflection: the elastica of the cantilever under a hung (always vertical) load.

Linear beam theory (MODEL.md section 3) takes the moment at ``s`` as ``F (x - s)``. Once the
free end drops by more than about a tenth of the length, the load's lever arm shrinks as the
beam bends: the moment at ``s`` is ``F (X_F - X(s))``, with ``X`` the horizontal coordinate of
the deformed beam and ``X_F`` that of the load point (the material point at arc length ``x``,
where the string hangs in its groove). With ``theta`` the slope below the horizontal and ``W``
the downward deflection, along the arc length ``s``:

    theta' = F (X_F - X(s)) / EI(s)   for s < x,   theta' = 0 beyond,
    X' = cos(theta),   W' = sin(theta),   theta(0) = X(0) = W(0) = 0,

with ``EI(s)`` piecewise as in the beam model (``model.rigidity_segments``: the reduced section
over each feature). The unknown ``X_F`` is found by shooting: integrate for a guess and solve
``X(x) = X_F`` with Brent's method.

``large_deflection(record)`` applies this to a design: the free end under ``F_max`` at
``x_max`` and the nonlinearity the bending of the beam puts into a linearly calibrated
sensor, simulated over a grid of the load region.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from designer.errors import DesignFileError, InputError, SolverError
from designer.model import is_large_deflection

# Integration tolerances: far below the 1e-4 relative accuracy the results are quoted to.
ODE_RTOL = 1e-11
ODE_ATOL = 1e-14
# Brent's method on X_F, as a fraction of the load position.
SHOOT_XTOL = 1e-13
# Loads x positions in the simulated calibration grid (the paper's Monte Carlo grid is 7 x 7).
GRID_FORCES = 7
GRID_POSITIONS = 7


@dataclass(frozen=True)
class Elastica:
    """The deformed cantilever for one load; SI, deflections downward positive."""

    force: float
    position: float              # arc length of the load point, m
    free_length: float
    load_x: float                # X_F: horizontal coordinate of the load point, m
    tip_vertical: float          # downward deflection of the free end, m
    tip_horizontal: float        # horizontal shortening of the free end, free_length - X(tip), m
    tip_angle: float             # slope of the free end below the horizontal, rad
    stations: tuple              # arc lengths where X and theta are reported
    station_x: tuple             # X(s_i)
    station_angle: tuple         # theta(s_i)
    station_drop: tuple          # W(s_i), downward

    def moment(self, i: int) -> float:
        """Bending moment at station ``i``: ``F (X_F - X(s_i))`` (zero beyond the load)."""
        return self.force * max(self.load_x - self.station_x[i], 0.0) if self.stations[i] < self.position else 0.0

    def axial(self, i: int) -> float:
        """Axial tension at station ``i``: the hung load's component along the bent beam."""
        return self.force * math.sin(self.station_angle[i]) if self.stations[i] < self.position else 0.0


def _segments(free_length: float, rigidity) -> list[tuple[float, float, float]]:
    """``[(s0, s1, EI)]`` covering ``0..free_length`` from a float or such a list."""
    if isinstance(rigidity, (int, float)):
        return [(0.0, free_length, float(rigidity))]
    segs = sorted((float(a), float(b), float(ei)) for a, b, ei in rigidity)
    if abs(segs[0][0]) > 1e-12 or abs(segs[-1][1] - free_length) > 1e-9 * free_length or any(
            abs(p[1] - q[0]) > 1e-12 for p, q in zip(segs, segs[1:])):
        raise InputError(f"flexural rigidity segments {segs!r} must cover 0 .. {free_length!r} without gaps")
    return segs


def solve_elastica(force: float, position: float, free_length: float, rigidity,
                   stations=()) -> Elastica:
    """The elastica of a cantilever with a vertical point load ``force`` at arc length ``position``.

    ``rigidity``: ``EI`` in N m^2, one number or ``[(s0, s1, EI), ...]`` segments covering the
    free length. ``stations``: arc lengths where ``X`` and ``theta`` are wanted.
    """
    from scipy.integrate import solve_ivp
    from scipy.optimize import brentq

    if not 0 < position <= free_length:
        raise InputError(f"load position {position!r} m must lie on the beam (0, {free_length!r}]")
    segs = _segments(free_length, rigidity)
    stations = tuple(float(s) for s in stations)
    # integration breaks where EI jumps; stations are read from the dense solution
    breaks = sorted({0.0, position} | {a for a, _, _ in segs if a < position} | {b for _, b, _ in segs if b < position})

    def rigidity_at(s):
        for a, b, ei in segs:
            if a <= s < b:
                return ei
        return segs[-1][2]

    def shoot(load_x: float, dense: bool = False):
        state = np.zeros(3)                          # theta, X, W
        pieces = []
        for a, b in zip(breaks, breaks[1:]):
            ei = rigidity_at(0.5 * (a + b))

            def rhs(s, y, ei=ei):
                return [force * (load_x - y[1]) / ei, math.cos(y[0]), math.sin(y[0])]

            sol = solve_ivp(rhs, (a, b), state, method="DOP853", rtol=ODE_RTOL, atol=ODE_ATOL * free_length,
                            dense_output=dense)
            if not sol.success:
                raise SolverError(f"the elastica integration failed ({sol.message})")
            state = sol.y[:, -1]
            pieces.append((a, b, sol.sol))
        return state, pieces

    if force == 0:
        load_x, end, pieces = position, np.array([0.0, position, 0.0]), None
    else:
        def residual(load_x):
            return shoot(load_x)[0][1] - load_x

        lo, hi = 0.0, position
        while residual(lo) <= 0:       # the load would pull the beam past the clamp: look further back
            lo -= position
            if lo < -100 * free_length:
                raise SolverError(f"no elastica found for {force!r} N at {position!r} m")
        load_x = brentq(residual, lo, hi, xtol=SHOOT_XTOL * position, rtol=4 * np.finfo(float).eps, maxiter=200)
        end, pieces = shoot(load_x, dense=True)

    theta_f, x_f, w_f = end
    rest = free_length - position
    tip_x = x_f + rest * math.cos(theta_f)
    tip_w = w_f + rest * math.sin(theta_f)

    def at(s):
        if pieces is None:
            return 0.0, s, 0.0
        if s >= position:
            return theta_f, x_f + (s - position) * math.cos(theta_f), w_f + (s - position) * math.sin(theta_f)
        for a, b, dense in pieces:
            if a <= s <= b:
                y = dense(s)
                return float(y[0]), float(y[1]), float(y[2])
        raise SolverError(f"the elastica has no solution at arc length {s!r} m")  # pragma: no cover

    read = [at(s) for s in stations]
    return Elastica(force=float(force), position=float(position), free_length=float(free_length),
                    load_x=float(load_x), tip_vertical=float(tip_w), tip_horizontal=float(free_length - tip_x),
                    tip_angle=float(theta_f), stations=stations, station_x=tuple(r[1] for r in read),
                    station_angle=tuple(r[0] for r in read), station_drop=tuple(r[2] for r in read))


def prismatic_tip_load(alpha: float) -> tuple[float, float, float]:
    """A prismatic cantilever with a vertical tip load, ``alpha = F L^2 / (E I)``.

    Returns ``(vertical deflection / L, horizontal shortening / L, tip slope in rad)``, the
    figures tabulated by Bisshopp & Drucker (1945).
    """
    e = solve_elastica(alpha, 1.0, 1.0, 1.0)
    return e.tip_vertical, e.tip_horizontal, e.tip_angle


# ----------------------------------------------------------------- a design

@dataclass(frozen=True)
class LargeDeflection:
    """Large-deflection figures of one design under the spec's load region (SI)."""

    free_length: float
    force: float                 # F_max
    position: float              # x_max
    linear_deflection: float     # Euler-Bernoulli free-end deflection, m
    deflection: float            # elastica: vertical drop of the free end, m
    load_deflection: float       # elastica: vertical drop of the load point, m
    shortening: float            # elastica: horizontal pull-in of the free end, m
    tip_angle: float             # rad
    moment_ratio: tuple          # elastica / linear moment at each station under F_max at x_max
    force_error_max: float       # worst |F_hat - F| / F over the grid after a linear calibration
    force_error_rms: float
    position_error_max: float    # worst |x_hat - x|, m
    position_error_rms: float
    force_error_mean: float      # mean |F_hat - F| / F, as the paper's Table 4 reports errors
    position_error_mean: float   # mean |x_hat - x| / x
    grid: tuple                  # (forces, positions) of the simulated calibration
    bridge: str

    @property
    def linear_ratio(self) -> float:
        return self.linear_deflection / self.free_length

    @property
    def ratio(self) -> float:
        return self.deflection / self.free_length

    @property
    def applies(self) -> bool:
        """Linear theory's free-end deflection is past ``model.LARGE_DEFLECTION_RATIO`` of the free length."""
        return is_large_deflection(self.linear_deflection, self.free_length)

    def summary(self) -> str:
        return (f"large deflection: under F_max at x_max the elastica's free end drops "
                f"{self.deflection * 1e3:.1f} mm ({self.ratio:.1%} of the free length; linear theory "
                f"{self.linear_deflection * 1e3:.1f} mm, {self.linear_ratio:.1%}) and pulls in "
                f"{self.shortening * 1e3:.1f} mm; the gauge moments fall to "
                f"{', '.join(f'{r:.3f}' for r in self.moment_ratio)} of linear theory's. Calibrated linearly "
                f"over the load region, the bending leaves force errors up to {self.force_error_max:.2%} "
                f"(RMS {self.force_error_rms:.2%}) and position errors up to "
                f"{self.position_error_max * 1e3:.2f} mm (RMS {self.position_error_rms * 1e3:.2f} mm; mean "
                f"{self.position_error_mean:.2%} of the position)")

    def as_dict(self) -> dict:
        return {"free_length": self.free_length, "force": self.force, "position": self.position,
                "linear_deflection": self.linear_deflection, "linear_ratio": self.linear_ratio,
                "deflection": self.deflection, "deflection_ratio": self.ratio, "shortening": self.shortening,
                "load_deflection": self.load_deflection,
                "tip_angle": self.tip_angle, "moment_ratio": list(self.moment_ratio),
                "force_error_max": self.force_error_max, "force_error_rms": self.force_error_rms,
                "position_error_max": self.position_error_max, "position_error_rms": self.position_error_rms,
                "force_error_mean": self.force_error_mean, "position_error_mean": self.position_error_mean,
                "grid": list(self.grid), "bridge": self.bridge, "applies": self.applies}


def large_deflection(design: dict, forces: int = GRID_FORCES, positions: int = GRID_POSITIONS) -> LargeDeflection:
    """The elastica of a design.json record and the nonlinearity it puts into the sensor.

    The bridges are simulated with the moment from the deformed geometry,
    ``M(s_i) = F (X_F - X(s_i))`` (plus, for a quarter bridge, the axial strain of the hung
    load's component along the bent beam, which half and full bridges cancel), over a
    ``forces x positions`` grid of the load region; the linear model
    ``V = k F x - k d F + c`` is calibrated on it by least squares per bridge and the
    force and position read back with the least-squares estimator.
    """
    from designer import model
    from designer.calibration.regression import regress
    from designer.model.estimator import estimate
    from designer.result.designfile import parse_design

    record = parse_design(design)
    spec, d = record.spec, record.design
    g = d.geometry
    E = float(d.material.E)
    props = model.section_properties(g)
    segs = model.rigidity_segments(g, props, E)
    load = spec.load
    if load.position_max > float(g.length):
        raise DesignFileError(f"spec.load.position: x_max {load.position_max!r} m lies beyond the free length "
                              f"{float(g.length)!r} m")
    stations = tuple(float(s) for s in g.stations)
    y_g, I_s, A_s = float(props.y_g), float(props.I_s), float(props.A_s)
    quarter = spec.bridge == "quarter"

    def bridge_moments(e: Elastica) -> np.ndarray:
        """What each bridge reads, as the bending moment that would give the same output."""
        m = np.array([e.moment(i) for i in range(len(stations))])
        if quarter:  # eps = M y/(E I) + N/(E A) on the one active gauge
            m = m + np.array([e.axial(i) for i in range(len(stations))]) * I_s / (A_s * y_g)
        return m

    top = solve_elastica(load.force_max, load.position_max, float(g.length), segs, stations + (load.position_max,))
    # linear theory on the elastica's own EI(s): the features' reduced sections and the wire channels
    linear = (model.tip_deflection(g, props, E, load.force_max, load.position_max)
              + model.channel_deflection(g, props, E, load.force_max, load.position_max))
    moment_ratio = tuple(float(top.moment(i) / (load.force_max * (load.position_max - s)))
                         for i, s in enumerate(stations))

    fs = np.linspace(load.force_min, load.force_max, forces)
    xs = np.linspace(load.position_min, load.position_max, positions)
    F, X = (a.ravel() for a in np.meshgrid(fs, xs, indexing="ij"))
    V = np.array([bridge_moments(solve_elastica(f, x, float(g.length), segs, stations)) for f, x in zip(F, X)])
    # calibrate each bridge by eq. 27, V_i = c + k F x - k d F, as a sensor would be
    fit = regress(F, X, V)
    F_hat, x_hat = estimate(V, fit.k, fit.d, fit.c)
    rel_force = (F_hat - F) / F
    pos = x_hat - X
    return LargeDeflection(
        free_length=float(g.length), force=load.force_max, position=load.position_max,
        linear_deflection=float(linear), deflection=top.tip_vertical, load_deflection=top.station_drop[-1],
        shortening=top.tip_horizontal,
        tip_angle=top.tip_angle, moment_ratio=moment_ratio,
        force_error_max=float(np.max(np.abs(rel_force))), force_error_rms=float(np.sqrt(np.mean(rel_force ** 2))),
        position_error_max=float(np.max(np.abs(pos))), position_error_rms=float(np.sqrt(np.mean(pos ** 2))),
        force_error_mean=float(np.mean(np.abs(rel_force))), position_error_mean=float(np.mean(np.abs(pos) / X)),
        grid=(forces, positions), bridge=spec.bridge)
