"""The bridges' voltage isolines (the paper's Fig. 2): noise-free bridge outputs over the
operating region, and where the isolines of one example load's readings cross."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from designer.model import estimator
from designer.outputs.plots.common import (C_BRIDGES, C_GRID, design_title, figure_axes, fmt_number, log_force_axis,
                                           nice_levels, region_outline)
from designer.outputs.plots.sensor import SensorData


def bridge_map(design: Mapping, force, position) -> np.ndarray:
    """Noise-free bridge outputs V_i (V) on a grid, indexed [force, position, station]."""
    s = SensorData.from_design(design)
    f, x = np.meshgrid(np.asarray(force, float), np.asarray(position, float), indexing="ij")
    return estimator.bridge_voltages(s.sensitivity, s.stations, s.offsets, f, x)


def example_load(design: Mapping) -> tuple[float, float]:
    """A representative load inside the region for Fig. 2: (x, F), m and N; the middle position
    (to 1 mm) and the geometric mean force (to 2 significant figures)."""
    s = SensorData.from_design(design)
    x = round((s.position_min + s.position_max) / 2, 3)
    f = float(f"{math.sqrt(s.force_min * s.force_max):.2g}")
    return x, min(max(f, s.force_min), s.force_max)


def plot_voltage_isolines(design: Mapping, ax=None, load=None):
    """The paper's Fig. 2: each bridge's voltage isolines (mV) over the operating region. A
    reading of every bridge picks one isoline each; the load is where they cross, shown for one
    example load (``load=(x, F)`` in m and N, by default ``example_load(design)``)."""
    s = SensorData.from_design(design)
    fig, ax = figure_axes(ax, (8.5, 5.8))
    span = s.position_max - s.position_min
    x_lo = max(s.position_min - 0.08 * span, s.stations[-1] + 0.25 * (s.position_min - s.stations[-1]))
    x_hi = s.position_max + 0.04 * span
    f_lo, f_hi = s.force_min / 1.25, s.force_max * 1.25
    force = np.geomspace(f_lo, f_hi, 241)
    position = np.linspace(x_lo, x_hi, 241)
    volts = bridge_map(design, force, position) * 1e3  # mV
    xg, fg = np.meshgrid(position * 1e3, force)

    x_e, f_e = load if load is not None else example_load(design)
    v_e = estimator.bridge_voltages(s.sensitivity, s.stations, s.offsets, f_e, x_e) * 1e3

    region_outline(ax, s, zorder=3)
    ax.fill_between([s.position_min * 1e3, s.position_max * 1e3], s.force_min, s.force_max,
                    facecolor="#f2f6fb", edgecolor="none", zorder=0)
    from matplotlib.lines import Line2D

    handles = []
    shown = sorted({0, len(s.stations) - 1})
    for j, i in enumerate(shown):
        colour = C_BRIDGES[j % len(C_BRIDGES)]
        levels = nice_levels(float(volts[..., i].min()), float(volts[..., i].max()), (1, 2, 5))
        cs = ax.contour(xg, fg, volts[..., i], levels=levels, colors=colour, linewidths=1.0,
                        linestyles="-" if j == 0 else "--", zorder=4)
        ax.clabel(cs, fmt=lambda v: f"{v:g}", fontsize=7.5, inline_spacing=2)
        ax.contour(xg, fg, volts[..., i], levels=[v_e[i]], colors=colour, linewidths=2.6, zorder=5)
        handles.append(Line2D([], [], color=colour, linestyle="-" if j == 0 else "--",
                              label=f"V{i + 1} isolines, mV (bridge at d{i + 1} = {s.stations[i] * 1e3:g} mm)"))
        handles.append(Line2D([], [], color=colour, linewidth=2.6,
                              label=f"V{i + 1} = {fmt_number(v_e[i])} mV for the example load"))
    ax.plot([x_e * 1e3], [f_e], "o", color="black", markersize=8, zorder=7)
    ax.annotate(f"example load\nx = {x_e * 1e3:g} mm, F = {fmt_number(f_e)} N", (x_e * 1e3, f_e),
                xytext=(12, 12), textcoords="offset points", fontsize=9, zorder=8,
                bbox=dict(boxstyle="round,pad=0.3", facecolor="white", edgecolor="#999999"))
    handles.append(Line2D([], [], color="black", linewidth=1.6, label="operating region"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=len(shown) + 1,
              fontsize=8, frameon=False)  # one column per bridge

    log_force_axis(ax, f_lo, f_hi)
    ax.set_xlim(x_lo * 1e3, x_hi * 1e3)
    ax.set_xlabel("load position x from the clamp (mm)")
    ax.set_ylabel("force F (N)")
    ax.set_title(f"Bridge voltage isolines: {design_title(s)}\n"
                 "each reading fixes one curve per bridge; the load is where they cross (eqs. 11-12)",
                 fontsize=10.5)
    ax.grid(True, which="major", color=C_GRID, linewidth=0.6, zorder=0)
    return fig
