"""The candidates chart: every material and section family the search tried, ranked as
MODEL.md section 5 ranks designs, coloured by status, the chosen design outlined."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from designer import model
from designer.errors import DesignFileError, brief
from designer.outputs.plots.common import C_GRID, C_STATUS, ERROR_OBJECTIVE_LABEL, figure_axes, fmt_number
from designer.outputs.plots.sensor import SensorData, is_number, optional_number


def plot_candidates(design: Mapping, ax=None):
    """Every material x section family the search tried, ranked by its objective (horizontal
    bars, best at the top), coloured by status; infeasible ones hatched, the chosen design
    outlined. A design without candidates (``evaluate``) shows itself alone."""
    s = SensorData.from_design(design)
    rows = _candidate_rows(design, s)
    fig, ax = figure_axes(ax, (10.0, max(3.0, 0.36 * len(rows) + 1.8)))
    kind = s.objective_kind
    scale, axis_label = {"error": (1.0, ERROR_OBJECTIVE_LABEL),
                         "deflection": (1e3, "objective: free-end deflection under F_max at x_max (mm)"),
                         "mass": (1e3, "objective: mass of the free length (g)")}.get(kind, (1.0, "objective"))
    values = [r["objective"] * scale if r["objective"] is not None else None for r in rows]
    bounds = [r["bound"] * scale if _bounded(r) else None for r in rows]
    known = [v for v in values + bounds if v is not None and v > 0]
    log = bool(known) and max(known) / min(known) > 30
    bottom = min(known) / 2 if log else 0.0
    missing_at = (max(known) if known else 1.0)

    y = np.arange(len(rows))
    labels = []   # (annotation, its bar's end)
    for yi, row, value, bound in zip(y, rows, values, bounds):
        colour = C_STATUS.get(row["status"], "#7f7f7f")
        infeasible = row["status"] in ("infeasible", "failed")
        if bound is not None:  # outranked: a faint bar to its answer before rounding (no bound on its designs)
            ax.barh(yi, bound - bottom, left=bottom, height=0.7, color=colour, alpha=0.35, edgecolor=colour,
                    linewidth=0.6, zorder=3)
            labels.append((_label(ax, bound, yi, _missing_text(row, scale), color="#555555"), bound))
            continue
        if value is None:
            at = bottom if log else 0.0
            labels.append((_label(ax, at, yi, _missing_text(row, scale), color=colour), at))
            continue
        ax.barh(yi, value - bottom, left=bottom, height=0.7, color=colour, alpha=0.45 if infeasible else 0.85,
                hatch="xx" if infeasible else None, edgecolor="black" if row["chosen"] else colour,
                linewidth=2.2 if row["chosen"] else 0.6, zorder=3)
        detail = [f"{fmt_number(row['deflection'] * 1e3)} mm" if row.get("deflection") is not None else "",
                  f"{fmt_number(row['mass'] * 1e3)} g" if row.get("mass") is not None else ""]
        detail = ", ".join(d for d in detail if d)
        text = fmt_number(value, 4) + (f"  ({detail})" if detail and kind == "error" else "") + \
            ("   ◀ chosen" if row["chosen"] else "")
        labels.append((_label(ax, value, yi, text, fontweight="bold" if row["chosen"] else "normal"), value))
    ax.set_yticks(y, [_candidate_label(r) for r in rows], fontsize=8.5)
    for tick, row in zip(ax.get_yticklabels(), rows):
        if row["chosen"]:
            tick.set_fontweight("bold")
    ax.set_ylim(len(rows) - 0.3, -0.7)  # best at the top
    if log:
        ax.set_xscale("log")
    if kind == "error":
        ax.axvline(1.0, color="black", linestyle="--", linewidth=1.2, zorder=5)
    right = max(known + [1.0 if kind == "error" else missing_at]) * (3.0 if log else 1.45)
    ax.set_xlim(bottom if log else 0.0, right)
    ax.set_xlabel(axis_label, fontsize=9)
    from matplotlib.patches import Patch

    statuses = list(dict.fromkeys(r["status"] for r in rows))
    handles = [Patch(facecolor=C_STATUS.get(st, "#7f7f7f"), alpha=0.45 if st in ("infeasible", "failed") else 0.85,
                     hatch="xx" if st in ("infeasible", "failed") else None, label=STATUS_LEGEND.get(st, st))
               for st in statuses]
    handles.append(Patch(facecolor="white", edgecolor="black", linewidth=2.2, label="chosen design"))
    if kind == "error":
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], color="black", linestyle="--", linewidth=1.2,
                              label="e = 1: targets met to the left"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.grid(True, axis="x", which="major", color=C_GRID, linewidth=0.6, zorder=0)
    if len(rows) > 1:
        ax.set_title(f"Candidates, best first: {s.name} ({len(rows)} material × section)\n"
                     "objectives within 0.1 % tie: lower deflection, then lower mass first (in brackets)",
                     fontsize=10.5)
    else:
        ax.set_title(f"The evaluated design: {s.name} (no search, no other candidates)", fontsize=10.5)
    _fit_labels(ax, labels, log)
    return fig


def _fit_labels(ax, labels, log: bool) -> None:
    """The x axis widened until every bar's label ends inside it: a long label on the longest bar
    (the chosen design of an infeasible spec, ranked by closeness rather than its objective, with
    "◀ chosen") ran into the legend. The axes' width is estimated from the figure's, less the
    widest tick label, the legend's widest entry and LAYOUT_PAD (laying the figure out to measure
    it took a second); a label keeps its width in points whatever the axis' limits. Text is
    measured only where a generous bound on its width (WIDEST_GLYPH) would not fit."""
    from matplotlib.backends.backend_agg import RendererAgg

    measure = RendererAgg(1, 1, 72).get_text_width_height_descent   # widths in points

    def lines(text) -> list[str]:
        return text.get_text().split("\n")

    def width(text) -> float:
        return max(measure(line, text.get_fontproperties(), ismath=False)[0] for line in lines(text))

    def widest(texts) -> float:   # the longest of ``texts``, measured
        return width(max(texts, key=lambda t: max(map(len, lines(t))))) if texts else 0.0

    legend = ax.get_legend()
    room = (ax.figure.get_figwidth() * 72 - widest(ax.get_yticklabels())
            - (widest(legend.get_texts()) if legend else 0.0) - LAYOUT_PAD)
    left, right = ax.get_xlim()
    t = np.log10 if log else (lambda v: v)
    need = t(right)

    def reach(label, x, w) -> float:   # the right limit at which the label ends at the axes' edge
        share = 1 - (w + LABEL_OFFSET + 2 * label.get_fontsize() * LABEL_PAD) / room
        return t(left) + (t(x) - t(left)) / share if share > 0.2 else -math.inf

    for label, x in labels:
        if reach(label, x, max(map(len, lines(label))) * label.get_fontsize() * WIDEST_GLYPH) > need:
            need = max(need, reach(label, x, width(label)))
    ax.set_xlim(left, 10 ** need if log else need)


# A bound on a label's mean glyph width, in ems: above DejaVu Sans's bold digits and letters.
WIDEST_GLYPH = 0.8
# Points of the figure's width that are neither the axes, the tick labels nor the legend's text
# (ticks, the legend's handles, the paddings): 39-47 on the candidate charts laid out to measure.
LAYOUT_PAD = 60.0


# Each bar's label a little right of the bar's end, on a faint white ground above the grid and the
# e = 1 line it may cross.
LABEL_PAD = 0.1   # of the font size, round the text
LABEL_BOX = {"boxstyle": f"square,pad={LABEL_PAD}", "facecolor": "white", "edgecolor": "none", "alpha": 0.85}


LABEL_OFFSET = 5   # points right of the bar's end


def _label(ax, x: float, y: float, text: str, **style):
    return ax.annotate(text, (x, y), xytext=(LABEL_OFFSET, 0), textcoords="offset points", va="center", fontsize=8,
                       zorder=6, bbox=LABEL_BOX, **style)


# An outranked candidate's bar ends at its answer before rounding: IPOPT's local optimum of
# continuous sizes, which no design of the 0.01 mm grid or of stock is sure to reach or beat
# (docs/model.md section 5), so the legend says what the bar is.
STATUS_LEGEND = {"outranked": "outranked: drawn at its\nanswer before rounding"}


def _bounded(row: Mapping) -> bool:
    """An outranked candidate with its answer before rounding."""
    return row.get("status") == "outranked" and row.get("objective") is None and row.get("bound") is not None


def _missing_text(row: Mapping, scale: float) -> str:
    """What a candidate without a design shows: outranked (with its answer before rounding, which
    no rounded or stock design is sure to reach or beat), no stock size that meets every limit, a
    family the limits leave no room (not searched), or no design at all."""
    if _bounded(row):
        return f"{fmt_number(row['bound'] * scale, 4)} before rounding: outranked"
    if row.get("no_stock"):
        return "no stock size (report.md says why)"
    if row.get("not_searched"):
        return "not searched: the limits leave it no room (report.md says why)"
    return "no design found"


def _candidate_rows(design: Mapping, s: SensorData) -> list[dict]:
    raw = design.get("candidates") or []
    if not isinstance(raw, Sequence) or isinstance(raw, str):
        raise DesignFileError(f"candidates: {brief(raw)} must be a list of objects")
    chosen_labels = {s.section, f"{s.section}+{s.feature}"}
    rows = []
    for i, c in enumerate(raw):
        if not isinstance(c, Mapping):
            raise DesignFileError(f"candidates[{i}]: {brief(c)} must be an object")
        objective = c.get("objective")
        if objective is not None and not is_number(objective):
            raise DesignFileError(f"candidates[{i}].objective: {objective!r} must be a number or null")
        rows.append({"material": str(c.get("material", "?")), "section": str(c.get("section", "?")),
                     "status": str(c.get("status", "")), "objective": objective,
                     "deflection": optional_number(c.get("deflection")),
                     "mass": optional_number(c.get("mass")),
                     "worst_violation": optional_number(c.get("worst_violation")),
                     "bound": optional_number(c.get("continuous_objective")), "no_stock": bool(c.get("stock_note")),
                     "not_searched": any(str(f).startswith("not searched:") for f in c.get("fallbacks") or []),
                     "chosen": str(c.get("material")) == s.material and str(c.get("section")) in chosen_labels})
    if not any(r["chosen"] for r in rows):
        rows.append({"material": s.material, "section": s.section, "status": s.status or "feasible",
                     "objective": s.objective, "deflection": s.deflection,
                     "mass": optional_number((design.get("predicted") or {}).get("mass")),
                     "worst_violation": None, "chosen": True})
    chosen = [r for r in rows if r["chosen"]]
    for r in chosen[1:]:  # the same material and family twice: only the first is the design
        r["chosen"] = False
    return rank_candidates(rows)


def rank_candidates(rows: Sequence[Mapping]) -> list:
    """Order candidates as MODEL.md section 5 ranks designs: the ones that meet every limit by
    objective, where objectives within 0.1 % tie and the lower deflection, then the lower mass,
    goes first, and each outranked one at its bound (before the first design above it, after the
    first design), as the search lists them; then the infeasible ones in the search's order, the
    closest first (docs/model.md §5; and the outranked ones when no design meets every limit); then
    those without a design."""
    def number(row, key):
        value = row.get(key)
        return math.inf if value is None else float(value)

    good = [r for r in rows if r.get("objective") is not None and r.get("status") not in ("infeasible", "failed")]
    bad = [r for r in rows if r.get("objective") is not None and r.get("status") in ("infeasible", "failed")]
    bounded = sorted((r for r in rows if _bounded(r)), key=lambda r: float(r["bound"]))
    none = [r for r in rows if r.get("objective") is None and not _bounded(r)]
    rest = sorted(good, key=lambda r: r["objective"])
    ranked = []
    while rest:
        lead = rest[0]["objective"]
        tied = [r for r in rest if model.ties(r["objective"], lead)]  # the model's tie rule
        pick = min(tied, key=lambda r: (number(r, "deflection"), number(r, "mass"), r["objective"]))
        while ranked and bounded and float(bounded[0]["bound"]) < pick["objective"]:
            ranked.append(bounded.pop(0))   # (never before the first: the chosen design)
        ranked.append(pick)
        rest.remove(pick)
    ranked += bounded + bad if good else bad + bounded
    return ranked + none


def _candidate_label(row: dict) -> str:
    return f"{row['material']} · {row['section']}"
