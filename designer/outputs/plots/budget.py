"""The error budget's chart: every contribution at the region's worst points (docs/model.md §13)."""

from __future__ import annotations

from collections.abc import Mapping

from designer.errors import DesignFileError
from designer.outputs.plots.common import C_GRID, design_title, fmt_number
from designer.outputs.plots.sensor import SensorData

C_KIND = {"random": "#4c72b0", "systematic": "#dd8452"}


def plot_budget(design: Mapping, fig=None):
    """Two panels of horizontal bars, force (u/F, %) and position (u, mm): each term's standard
    uncertainty at the corner of the region where that quantity's combined uncertainty is
    largest, coloured random or systematic, with its share of the variance; the combined 1σ and
    the target as lines."""
    s = SensorData.from_design(design)
    b = (design.get("predicted") or {}).get("budget")
    if not isinstance(b, Mapping):
        raise DesignFileError("predicted.budget: missing; the error budget's chart needs a design with an environment")
    if fig is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(13.0, 5.2), layout="constrained")
    axes = fig.subplots(1, 2, sharey=True)
    panels = (("force", 100.0, "%", "u(F) / F (%)", s.force_target),
              ("position", 1e3, "mm", "u(x) (mm)", s.position_target))
    for ax, (key, scale, unit, label, target) in zip(axes, panels):
        part = b[key]
        terms = part["terms"]
        names = [t["name"] for t in terms]
        values = [t["u"] * scale for t in terms]
        y = list(range(len(terms)))
        ax.barh(y, values, color=[C_KIND.get(t["kind"], "#7f7f7f") for t in terms], height=0.65, zorder=3)
        right = max(values + [part["combined"] * scale, (target or 0.0) * scale]) * 1.35
        for yi, t, v in zip(y, terms, values):
            if t["share"] >= 0.005:
                ax.text(v, yi, f"  {fmt_number(v)} {unit} ({t['share']:.0%})", va="center", fontsize=8)
        ax.axvline(part["combined"] * scale, color="black", linewidth=1.4, zorder=4,
                   label=f"combined 1σ {fmt_number(part['combined'] * scale)} {unit}")
        if target is not None:
            ax.axvline(target * scale, color="#c44e52", linestyle="--", linewidth=1.2, zorder=4,
                       label=f"target {fmt_number(target * scale)} {unit}")
        at = part["at"]
        ax.set_title(f"{key} at {fmt_number(at['force'])} N, {fmt_number(at['position'] * 1e3)} mm "
                     "(its worst corner)", fontsize=10)
        ax.set_xlabel(label)
        ax.set_xlim(0, right)
        ax.set_yticks(y, names, fontsize=9)
        ax.set_ylim(len(terms) - 0.4, -0.6)
        ax.grid(axis="x", color=C_GRID, linewidth=0.6, zorder=0)
        from matplotlib.patches import Patch

        handles, _ = ax.get_legend_handles_labels()
        handles += [Patch(color=c, label=k) for k, c in C_KIND.items()]
        ax.legend(handles=handles, loc="lower right", fontsize=8)
    fig.suptitle(f"Error budget (JCGM 100: bounds a count as u = a/√3; shares of the variance): {design_title(s)}",
                 fontsize=11.5)
    return fig
