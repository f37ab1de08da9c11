"""Trade-off fronts: the best error objective the search reaches against a deflection limit
(stiffness) or a natural-frequency floor (speed), one line per material, section or both."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from designer.errors import InputError, brief, describe_allowed
from designer.outputs.plots.common import C_GRID, ERROR_OBJECTIVE_LABEL, MATERIAL_COLOURS, SECTION_MARKERS, figure_axes
from designer.outputs.plots.sensor import is_number
from designer.spec.keys import plain_name

# The quantities a trade-off front can be drawn against: axis label, SI -> axis factor, file name.
TRADEOFF_AXES = {
    "max_deflection": ("free-end deflection (mm): the best design under each deflection limit", 1e3,
                       "tradeoff-deflection"),
    "min_frequency": ("first natural frequency (Hz): the best design above each frequency limit", 1.0,
                      "tradeoff-frequency"),
}
TRADEOFF_ALIASES = {"deflection": "max_deflection", "frequency": "min_frequency",
                    "natural_frequency": "min_frequency"}
TRADEOFF_GROUPS = ("material", "section", "both")


def plot_tradeoff(points: Sequence[Mapping], chosen: Mapping | None = None, x: str = "max_deflection",
                  ax=None, by: str = "material"):
    """Trade-off front: the best error objective the search reaches against a limit.

    ``points``: solved designs, each ``{"material", "section", "x": limit value (SI), "objective",
    "feasible": bool}`` and optionally ``"value"``, the design's own deflection or frequency
    (SI), where it is drawn (the deflection limit keeps room below ``x``, docs/model.md §4);
    ``x``: ``"max_deflection"`` (m, drawn in mm) or ``"min_frequency"`` (Hz);
    ``by``: one line per ``"material"`` (best section at each x, marked by its shape), per
    ``"section"`` (best material) or per material and section (``"both"``). The lower envelope of
    the feasible points is the front; ``chosen`` (``{"x", "objective"}``) is starred.
    """
    x = TRADEOFF_ALIASES.get(x, x)
    if x not in TRADEOFF_AXES:
        raise InputError(f"x: {x!r} is not allowed; must be {describe_allowed(TRADEOFF_AXES)}")
    if by not in TRADEOFF_GROUPS:
        raise InputError(f"by: {by!r} is not allowed; must be {describe_allowed(TRADEOFF_GROUPS)}")
    pts = tradeoff_points(points, x)
    label, scale, _ = TRADEOFF_AXES[x]
    fig, ax = figure_axes(ax, (10.5, 5.6))
    from matplotlib.lines import Line2D

    groups = _tradeoff_groups(pts, by)
    materials = sorted({p["material"] for p in pts})
    colour_of = {m: MATERIAL_COLOURS[i % len(MATERIAL_COLOURS)] for i, m in enumerate(materials)}
    section_colour = {"rectangle": "#1f77b4", "round": "#ff7f0e", "tube": "#2ca02c"}
    styles = ("-", "--", ":", "-.")
    sections = list(dict.fromkeys(_family(p["section"]) for p in pts))

    front = _front(pts)
    if front:
        fx, fy = zip(*front)
        ax.plot(np.array(fx) * scale, fy, color="#bbbbbb", linewidth=9, alpha=0.7, zorder=1,
                solid_capstyle="round", label="front: best of all")
    handles = []
    for name, series in groups.items():
        if by == "section":
            colour, style = section_colour.get(_family(name), "#555555"), "-"
        elif by == "both":
            material, section = name
            colour = colour_of[material]
            style = styles[sections.index(_family(section)) % len(styles)]
        else:
            colour, style = colour_of[name], "-"
        xs = np.array([_drawn_at(p) for p in series]) * scale
        ys = np.array([np.nan if p["objective"] is None else p["objective"] for p in series], float)
        ok = np.array([p["feasible"] for p in series])
        ax.plot(xs, np.where(ok, ys, np.nan), color=colour, linestyle=style, linewidth=1.6, zorder=3)
        ax.plot(xs, ys, color=colour, linestyle=":", linewidth=0.9, alpha=0.6, zorder=2)
        for xi, yi, oki, p in zip(xs, ys, ok, series):
            if np.isnan(yi):
                continue
            marker = SECTION_MARKERS.get(_family(p["section"]), "o")
            ax.plot([xi], [yi], marker=marker, markersize=6, linestyle="none", zorder=4,
                    color=colour, markerfacecolor=colour if oki else "white", markeredgewidth=1.2)
        handles.append(Line2D([], [], color=colour, linestyle=style, linewidth=1.6,
                              label=name if not isinstance(name, tuple) else f"{name[0]} · {name[1]}"))
    if by != "section":
        for sec in sections:
            handles.append(Line2D([], [], marker=SECTION_MARKERS.get(sec, "o"), color="#444444",
                                  linestyle="none", markersize=6, label=f"{sec} (best section)"
                                  if by == "material" else sec))
    handles.append(Line2D([], [], marker="o", color="#444444", markerfacecolor="white", linestyle="none",
                          markersize=6, label="infeasible (least-violating design)"))
    if front:
        handles.append(Line2D([], [], color="#bbbbbb", linewidth=7, alpha=0.7, label="front: best of all"))
    if chosen is not None and is_number(chosen.get("x")) and is_number(chosen.get("objective")):
        ax.plot([chosen["x"] * scale], [chosen["objective"]], marker="*", markersize=18, color="gold",
                markeredgecolor="black", linestyle="none", zorder=6)
        handles.append(Line2D([], [], marker="*", markersize=14, color="gold", markeredgecolor="black",
                              linestyle="none", label="chosen design"))

    objectives = [p["objective"] for p in pts if p["objective"] is not None]
    if objectives:
        lo, hi = min(objectives), max(objectives)
        feasible = [p["objective"] for p in pts if p["feasible"] and p["objective"] is not None]
        top = min(hi, 20 * max(feasible)) if feasible else hi
        if max(top, 1.0) / lo > 8:
            ax.set_yscale("log")
            ax.set_ylim(lo / 1.4, max(top, 1.0) * 1.6)
        else:
            ax.set_ylim(0.0, max(top, 1.0) * 1.12)
    ax.axhline(1.0, color="black", linestyle="--", linewidth=1.1, zorder=2)
    handles.append(Line2D([], [], color="black", linestyle="--", linewidth=1.1, label="e = 1: targets met below"))
    from matplotlib.ticker import FuncFormatter, LogLocator

    if ax.get_yscale() == "log":
        ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    ax.set_xlabel(label)
    ax.set_ylabel(ERROR_OBJECTIVE_LABEL, fontsize=9)
    what = "stiffness" if x == "max_deflection" else "speed"
    ax.set_title(f"Accuracy against {what}: best design per "
                 f"{'material and section' if by == 'both' else by}", fontsize=11)
    ax.grid(True, which="major", color=C_GRID, linewidth=0.6, zorder=0)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    return fig


def _family(section: str) -> str:
    """``rectangle+hole`` -> ``rectangle``."""
    return section.split("+", 1)[0]


# The largest figure a trade-off point may give (a deflection in m, a frequency in Hz, an error
# ratio): the spec's own ranges stop below it, and the plot's scales overflow far above it.
LARGEST_FIGURE = 1e10


# A trade-off point's keys (docs/spec.md, fpdesign plot): ``value`` is optional
POINT_KEYS = ("material", "section", "x", "objective", "feasible", "value")


def tradeoff_points(points, x: str) -> list[dict]:
    if not isinstance(points, Sequence) or isinstance(points, str):
        raise InputError(f"trade-off points for {x}: {brief(points)} must be a list of objects")
    out = []
    for i, p in enumerate(points):
        where = f"tradeoff.{x}[{i}]"
        if not isinstance(p, Mapping):
            raise InputError(f"{where}: {brief(p)} must be an object with material, section, x, objective, feasible")
        unknown = [k for k in p if k not in POINT_KEYS]
        if unknown:
            raise InputError(f"{where}: unknown key {brief(unknown[0], 40)}; allowed keys are "
                             f"{describe_allowed(POINT_KEYS)}")
        for key in ("material", "section"):
            plain_name(p.get(key), f"{where}.{key}", InputError)
        if not is_number(p.get("x")) or not 0 < p["x"] <= LARGEST_FIGURE:
            raise InputError(f"{where}.x: {p.get('x')!r} must be a positive number (SI units) up to "
                             f"{LARGEST_FIGURE:g}")
        objective = p.get("objective")
        if objective is not None and (not is_number(objective) or not 0 < objective <= LARGEST_FIGURE):
            raise InputError(f"{where}.objective: {objective!r} must be a positive number up to "
                             f"{LARGEST_FIGURE:g}, or null")
        if not isinstance(p.get("feasible"), bool):
            raise InputError(f"{where}.feasible: {p.get('feasible')!r} must be true or false")
        value = p.get("value")
        if value is not None and (not is_number(value) or not 0 < value <= LARGEST_FIGURE):
            raise InputError(f"{where}.value: {value!r} must be a positive number (SI units) up to "
                             f"{LARGEST_FIGURE:g}, or null")
        out.append({"material": p["material"], "section": p["section"], "x": float(p["x"]),
                    "value": None if value is None else float(value),
                    "objective": None if objective is None else float(objective),
                    "feasible": p["feasible"] and objective is not None})
    if not out:
        raise InputError(f"trade-off points for {x}: the list is empty")
    return out


def _best(points: list[dict]) -> dict:
    """The best of several designs at one x: feasible first, then the lowest objective."""
    def key(p):
        return (not p["feasible"], math.inf if p["objective"] is None else p["objective"])
    return min(points, key=key)


def _tradeoff_groups(pts: list[dict], by: str) -> dict:
    """{line name: [best point at each x, by increasing x]}."""
    if by == "both":
        name_of = lambda p: (p["material"], p["section"])  # noqa: E731
    elif by == "section":
        name_of = lambda p: _family(p["section"])  # noqa: E731
    else:
        name_of = lambda p: p["material"]  # noqa: E731
    buckets: dict = {}
    for p in pts:
        buckets.setdefault(name_of(p), {}).setdefault(p["x"], []).append(p)
    return {name: [_best(at[xv]) for xv in sorted(at)] for name, at in sorted(buckets.items())}


def _drawn_at(p: dict) -> float:
    """Where a point is drawn: the design's own deflection or frequency, else its limit."""
    value = p.get("value")
    return p["x"] if value is None else value


def _front(pts: list[dict]) -> list[tuple[float, float]]:
    """The best feasible design at each x value (limit level), drawn where it sits."""
    best: dict[float, dict] = {}
    for p in pts:
        if p["feasible"] and p["objective"] is not None:
            if p["x"] not in best or p["objective"] < best[p["x"]]["objective"]:
                best[p["x"]] = p
    return [(_drawn_at(p), p["objective"]) for _, p in sorted(best.items())]
