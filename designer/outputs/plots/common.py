"""What every plot shares: colours and marks (passed explicitly to every artist, no global
style), the error objective's axis label, number formats, round contour levels, the log force
axis, the operating region's outline and the design's title. matplotlib is imported only
inside the functions that draw."""

from __future__ import annotations

import math

from designer.outputs.plots.sensor import SensorData

# Colours and marks, passed explicitly to every artist (no global style).
C_STRAIN = "#c0392b"      # gauge strain limit (maximum moment)
C_STRESS = "#8e44ad"      # stress limits
C_SIGNAL = "#1f5fa8"      # minimum detectable signal (minimum moment)
C_REGION = "#cfe2f3"      # operating region fill
C_GAUGE = "#d4a017"       # gauge stations (gold, as in the paper's figures)
C_GRID = "#d9d9d9"
C_BRIDGES = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2")
C_STATUS = {"optimal": "#2e8b57", "feasible": "#2e8b57", "infeasible": "#c0392b", "failed": "#7f7f7f"}
SECTION_MARKERS = {"rectangle": "s", "round": "o", "tube": "D"}
MATERIAL_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
                    "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")

ERROR_OBJECTIVE_LABEL = ("error objective  e = max(σ_F/F_min ÷ target, σ_x ÷ target)\n"
                         "e ≤ 1 meets both targets")


def figure_axes(ax, figsize):
    """``(figure, axes)``: the caller's axes, or a new pyplot-free figure."""
    if ax is not None:
        return ax.figure, ax
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    return fig, fig.add_subplot()


def fmt_number(value: float, digits: int = 3) -> str:
    """A number to ``digits`` significant figures, without a trailing exponent for usual sizes."""
    if value == 0 or not math.isfinite(value):
        return f"{value:g}"
    places = max(0, digits - 1 - math.floor(math.log10(abs(value))))
    text = f"{value:.{places}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def nice_levels(lo: float, hi: float, mantissas=(1, 1.5, 2, 3, 5, 7)) -> list[float]:
    """Round contour levels from a 1-1.5-2-3-5-7 series that bracket [lo, hi]."""
    if not (lo > 0 and hi > lo):
        return [lo, hi] if hi > lo else [lo * 0.9, lo * 1.1]
    ladder = [m * 10.0 ** e for e in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 2)
              for m in mantissas]
    below = max(v for v in ladder if v <= lo)
    above = min(v for v in ladder if v >= hi)
    levels = [v for v in ladder if below <= v <= above]
    if len(levels) > 14 and len(mantissas) > 3:
        return nice_levels(lo, hi, (1, 2, 5))
    if len(levels) > 14:
        return nice_levels(lo, hi, (1,))
    return levels


def log_force_axis(ax, lo: float, hi: float) -> None:
    from matplotlib.ticker import FuncFormatter, LogLocator

    ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_minor_locator(LogLocator(base=10, subs=tuple(range(1, 10))))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))


def region_outline(ax, s: SensorData, label: str | None = "operating region", zorder: float = 4):
    from matplotlib.patches import Rectangle

    ax.add_patch(Rectangle((s.position_min * 1e3, s.force_min),
                           (s.position_max - s.position_min) * 1e3, s.force_max - s.force_min,
                           fill=False, edgecolor="black", linewidth=1.6, zorder=zorder, label=label))


def design_title(s: SensorData) -> str:
    status = f" ({s.status})" if s.status and s.status not in ("optimal", "feasible") else ""
    axes = ", per axis" if s.axes > 1 else ""
    return f"{s.name}: {s.label}{axes}{status}"
