"""The operating region (the paper's Fig. 3): the moment isolines of the strain and stress
limits and of the smallest detectable signal that bound the measurable region, and its chart."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from designer.outputs.plots.common import (C_GAUGE, C_GRID, C_REGION, C_SIGNAL, C_STRAIN, C_STRESS, design_title,
                                           figure_axes, fmt_number, log_force_axis, region_outline)
from designer.outputs.plots.sensor import SensorData


@dataclass(frozen=True)
class MomentLimit:
    """A limit that is a moment isoline ``F (x - pivot) = moment`` in the (x, F) plane."""

    name: str       # gauge_strain | stress_root | stress_feature | min_signal
    label: str
    moment: float   # N m
    pivot: float    # m: the point the moment is taken about

    def force(self, x):
        """The force on the isoline at position ``x`` (N); ``x`` must lie beyond the pivot."""
        return self.moment / (np.asarray(x, dtype=float) - self.pivot)


@dataclass(frozen=True)
class OperatingRegion:
    """The paper's Fig. 3: the specified region and the moment isolines that bound the
    measurable one (MODEL.md section 4, the paper's eqs. 13-22)."""

    force_min: float
    force_max: float
    position_min: float
    position_max: float
    stations: tuple[float, ...]
    upper: tuple[MomentLimit, ...]   # maximum-moment isolines: the strain and stress limits
    lower: MomentLimit               # minimum-moment isoline: the smallest detectable signal

    def upper_force(self, x):
        """The largest force the limits allow at ``x`` (N)."""
        return np.min([lim.force(x) for lim in self.upper], axis=0)

    @property
    def governing(self) -> MomentLimit:
        """The upper limit that sets the largest force at x_max."""
        return min(self.upper, key=lambda lim: float(lim.force(self.position_max)))

    @property
    def force_max_allowed(self) -> float:
        """Upper corner: the largest force at x_max (eq. 14 solved for F_max)."""
        return float(self.upper_force(self.position_max))

    @property
    def force_min_allowed(self) -> float:
        """Lower corner: the smallest detectable force at x_min (eq. 16 solved for F_min)."""
        return float(self.lower.force(self.position_min))

    @property
    def moment_max(self) -> float:
        """M_max = F_max (x_max - d_1) with the largest allowed F_max (eq. 14), N m."""
        return self.force_max_allowed * (self.position_max - self.stations[0])

    @property
    def moment_min(self) -> float:
        """M_min = F_min (x_min - d_N) (eq. 16), N m."""
        return self.lower.moment

    @property
    def strain_ratio(self) -> float:
        """R_eps = M_max / M_min (eq. 20)."""
        return self.moment_max / self.moment_min

    @property
    def force_ratio(self) -> float:
        """R_F the limits allow: R_eps (x_min - d_N) / (x_max - d_1) (eq. 21)."""
        return self.strain_ratio * (self.position_min - self.stations[-1]) / \
            (self.position_max - self.stations[0])

    @property
    def specified_force_ratio(self) -> float:
        return self.force_max / self.force_min


def operating_region(design: Mapping) -> OperatingRegion:
    """The moment isolines of a design (MODEL.md section 4).

    Every limit is linear in the load, so each one's moment is its value under F_max at x_max
    scaled to its bound: the gauge strain ``eps_1`` about ``d_1``, the root stress about the
    clamp and the stress at the first feature's edge about that edge. The smallest signal,
    ``k_N F (x - d_N) = min_snr sigma_V``, is a moment about ``d_N``.
    """
    s = SensorData.from_design(design)
    lever = s.position_max - s.stations[0]
    upper = [MomentLimit("gauge_strain", "gauge strain limit",
                         s.force_max * lever * s.max_strain / s.gauge_strain, s.stations[0]),
             MomentLimit("stress_root", "stress limit at the root",
                         s.force_max * s.position_max * s.stress_allowable / s.stress_root, 0.0)]
    if s.stress_feature is not None and s.feature != "none":
        upper.append(MomentLimit("stress_feature", f"stress limit at the {s.feature} edge",
                                 s.force_max * (s.position_max - s.feature_edge) * s.stress_feature_allowable
                                 / s.stress_feature, s.feature_edge))
    lower = MomentLimit("min_signal", f"smallest signal ({s.min_snr:g} × noise)",
                        s.min_snr * s.noise / s.sensitivity[-1], s.stations[-1])
    return OperatingRegion(s.force_min, s.force_max, s.position_min, s.position_max, s.stations,
                           tuple(upper), lower)


def plot_operating_region(design: Mapping, ax=None):
    """The paper's Fig. 3 for this design: force (N, log) against position (mm) with the
    maximum-moment isolines (gauge strain, stress), the minimum-moment isoline (smallest
    detectable signal), F_min, F_max, x_min, x_max, the operating region and the gauge stations.
    The force ratio the limits allow (eq. 21) is written on the chart."""
    s = SensorData.from_design(design)
    region = operating_region(design)
    fig, ax = figure_axes(ax, (9.0, 5.8))

    f_hi_allowed, f_lo_allowed = region.force_max_allowed, region.force_min_allowed
    y_lo = min(f_lo_allowed, s.force_min) / 3
    at_end = [float(lim.force(s.position_max)) for lim in region.upper]
    y_hi = max(min(max(at_end), 10 * f_hi_allowed) * 1.5, s.force_max * 3)
    x_end = max(s.length, s.position_max)
    # dense near each pivot, where the isolines climb steeply
    pivots = sorted({lim.pivot for lim in region.upper} | {region.lower.pivot})
    x = np.unique(np.concatenate([np.linspace(0.0, x_end, 1200)[1:]] +
                                 [p + np.geomspace(1e-5 * x_end, x_end - p, 400) for p in pivots]))

    # measurable but outside the operating region (the paper's hatching)
    beyond = x > s.stations[-1] + 1e-9
    upper = region.upper_force(x)
    lower = np.where(beyond, region.lower.force(np.where(beyond, x, np.inf)), np.inf)
    ax.fill_between(x * 1e3, np.clip(lower, y_lo, y_hi), np.clip(upper, y_lo, y_hi),
                    where=beyond & (upper > lower), facecolor="none", edgecolor="#b0b0b0",
                    hatch="///", linewidth=0, zorder=1,
                    label="measurable, outside the operating region")
    ax.fill_between([s.position_min * 1e3, s.position_max * 1e3], s.force_min, s.force_max,
                    facecolor=C_REGION, edgecolor="none", zorder=2)
    region_outline(ax, s, label="operating region (specified)", zorder=5)

    styles = {"gauge_strain": (C_STRAIN, "-"), "stress_root": (C_STRESS, "--"),
              "stress_feature": (C_STRESS, ":")}
    for lim in region.upper:
        colour, style = styles[lim.name]
        xs = x[x > lim.pivot + 1e-9]
        ax.plot(xs * 1e3, lim.force(xs), color=colour, linestyle=style, linewidth=2, zorder=6,
                label=f"{lim.label}:  {_moment_text(lim)} = {fmt_number(lim.moment)} N·m")
    xs = x[beyond]
    ax.plot(xs * 1e3, region.lower.force(xs), color=C_SIGNAL, linewidth=2, zorder=6,
            label=f"{region.lower.label}:  F·(x − d{len(s.stations)}) = {fmt_number(region.lower.moment)} N·m")

    # design limits: F_min, F_max (labelled on the right, as in the paper), x_min, x_max
    for value, name in ((s.force_min, "F_min"), (s.force_max, "F_max")):
        ax.axhline(value, color="#555555", linestyle="--", linewidth=0.9, zorder=3)
        ax.annotate(f"{name} = {fmt_number(value)} N", (1.0, value), xycoords=("axes fraction", "data"),
                    xytext=(4, 0), textcoords="offset points", va="center", fontsize=9)
    for value, name in ((s.position_min, "x_min"), (s.position_max, "x_max")):
        ax.axvline(value * 1e3, color="#555555", linestyle="-.", linewidth=0.9, zorder=3)
        ax.annotate(f"{name}\n{value * 1e3:g} mm", (value * 1e3, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(0, 4), textcoords="offset points", ha="center", va="bottom", fontsize=9)

    # the corners the isolines set (the paper: they fix the largest and smallest design forces)
    gov = region.governing
    ax.plot([s.position_max * 1e3], [f_hi_allowed], "o", color=C_STRAIN if gov.name == "gauge_strain"
            else C_STRESS, markersize=7, markeredgecolor="black", zorder=8)
    ax.annotate(f"largest force at x_max\n{fmt_number(f_hi_allowed)} N ({gov.label})",
                (s.position_max * 1e3, f_hi_allowed), xytext=(-10, 8), textcoords="offset points",
                ha="right", va="bottom", fontsize=8.5, zorder=9,
                bbox=dict(boxstyle="round,pad=0.2", facecolor="white", edgecolor="none", alpha=0.8))
    ax.plot([s.position_min * 1e3], [f_lo_allowed], "o", color=C_SIGNAL, markersize=7,
            markeredgecolor="black", zorder=8)
    ax.annotate(f"smallest force at x_min\n{fmt_number(f_lo_allowed)} N", (s.position_min * 1e3, f_lo_allowed),
                xytext=(10, -4), textcoords="offset points", ha="left", va="top", fontsize=8.5, zorder=9,
                bbox=dict(boxstyle="round,pad=0.2", facecolor="white", edgecolor="none", alpha=0.8))

    # gauge stations on the position axis
    for i, d in enumerate(s.stations, start=1):
        ax.axvline(d * 1e3, color=C_GAUGE, linewidth=1.0, alpha=0.6, zorder=1)
        ax.plot([d * 1e3], [0.0], marker="^", markersize=11, color=C_GAUGE, markeredgecolor="black",
                transform=ax.get_xaxis_transform(), clip_on=False, zorder=10,
                label="gauge stations" if i == 1 else None)
        ax.annotate(f"d{i}", (d * 1e3, 0.0), xycoords=("data", "axes fraction"), xytext=(0, 9),
                    textcoords="offset points", ha="center", fontsize=9, fontweight="bold")

    ratio = region.force_ratio
    verdict = "fits" if (f_hi_allowed >= s.force_max and f_lo_allowed <= s.force_min) else "does NOT fit"
    ax.text(0.985, 0.03,
            f"force ratio the limits allow (eq. 21):  R_F = {fmt_number(ratio)}\n"
            f"  = {fmt_number(f_hi_allowed)} N ÷ {fmt_number(f_lo_allowed)} N\n"
            f"specified F_max/F_min = {fmt_number(region.specified_force_ratio)}: the load range {verdict}",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=9, zorder=11,
            bbox=dict(boxstyle="round,pad=0.4", facecolor="white", edgecolor="#999999"))

    log_force_axis(ax, y_lo, y_hi)
    ax.set_xlim(0.0, x_end * 1e3)
    ax.set_xlabel("load position x from the clamp (mm)")
    ax.set_ylabel("force F (N)")
    ax.set_title(f"Operating region: {design_title(s)}", pad=30, fontsize=11)
    ax.grid(True, which="major", color=C_GRID, linewidth=0.6, zorder=0)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=2, fontsize=8, frameon=False)
    return fig


def _moment_text(lim: MomentLimit) -> str:
    if lim.name == "gauge_strain":
        return "F·(x − d1)"
    if lim.name == "stress_root":
        return "F·x"
    return f"F·(x − {lim.pivot * 1e3:.4g} mm)"
