"""The bench's chart: solve time against objective gap, one point per method over the runs."""

from __future__ import annotations

import math

from designer import model
from designer.bench.run import BenchResult, gap
from designer.bench.summary import SPREAD, method_summary
from designer.search.problem import METHODS


def chart_data(result: BenchResult) -> dict:
    """What ``chart`` draws: per method its medians and spreads; per run its time and gap."""
    summary = method_summary(result)
    points = [{"method": r.method, "seconds": r.seconds, "gap": gap(r, result.truth(r))}
              for r in result.runs if result.truth(r).feasible]
    return {"methods": summary, "points": points, "specs": len(result.suite),
            "feasible_specs": sum(t.feasible for t in result.truths.values()), "tie": model.TIE_TOLERANCE}


def chart(data: dict, ax=None):
    """Solve time (log) against objective gap (symlog %), one point per method (median time with
    its spread, 90th-percentile gap with a bar down to the median gap) over faint per-spec points;
    the speed-accuracy front dashed. Returns the figure."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.ticker import NullFormatter

    if ax is None:
        fig = Figure(figsize=(9.5, 6.0), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    methods = data["methods"]
    finite = [p["gap"] * 100 for p in data["points"] if p["gap"] is not None and math.isfinite(p["gap"])]
    top = 10 ** math.ceil(math.log10(max(finite + [10.0]))) * 3   # the "no design" row, % above every gap
    colours = {m: f"C{i}" for i, m in enumerate(METHODS)}

    def y(g):
        return top if g is None or math.isinf(g) else g * 100

    for p in data["points"]:
        missing = p["gap"] is not None and math.isinf(p["gap"])
        ax.scatter(p["seconds"], y(p["gap"]), s=22 if missing else 12, color=colours[p["method"]],
                   alpha=0.6 if missing else 0.28, linewidths=1.2 if missing else 0,
                   marker="x" if missing else "o", zorder=1)
    labels, bars = [], []
    for r in methods:
        t, g = r["median_seconds"], r["p90_gap"]
        if t is None or g is None:
            continue
        xerr = [[t - r["seconds_low"]], [r["seconds_high"] - t]]
        yerr = [[y(g) - y(r["median_gap"])], [0.0]]  # down to the median gap
        c = colours[r["method"]]
        default = r["method"] == "ipopt"  # a diamond on top: no other point hides it
        ax.errorbar(t, y(g), xerr=xerr, yerr=yerr, fmt="D" if default else "o", ms=8 if default else 9, color=c,
                    mec="black", mew=1.4 if default else 0.8, elinewidth=1.4, capsize=3, zorder=5 if default else 3)
        labels.append((r["method"] + (" (default)" if default else ""), t, y(g), c, default))
        bars += [((r["seconds_low"], y(g)), (r["seconds_high"], y(g))), ((t, y(r["median_gap"])), (t, y(g)))]
    front = sorted((r["median_seconds"], y(r["p90_gap"])) for r in methods if r["on_front"])
    if front:
        xs, ys = zip(*front)
        ax.plot(xs, ys, ls="--", color="0.3", lw=1.2, zorder=2, drawstyle="steps-post")
    linthresh = data["tie"] * 100
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide when times span under a decade
    ax.set_yscale("symlog", linthresh=linthresh, linscale=0.6)
    ax.set_ylim(-linthresh * 0.3, top * 2.5)
    ax.axhline(top / 1.8, color="0.75", lw=0.8)
    ticks = [0] + [10.0 ** k for k in range(int(round(math.log10(linthresh))), int(math.log10(top)))]
    ax.set_yticks(ticks + [top])
    ax.set_yticklabels([_tick(v) for v in ticks] + ["no design"])
    ax.set_xlabel("wall time of one optimize call, s (log scale)")
    ax.set_ylabel(f"objective gap to the best known design, %\n(symlog; 0 = within the {data['tie']:.1%} tie band)")
    ax.set_title(f"Speed against accuracy: {len(methods)} methods on {data['feasible_specs']} feasible specs "
                 f"(of {data['specs']})", fontsize=11)
    ax.grid(True, which="major", alpha=0.3)
    handles = [Line2D([], [], marker="D" if r["method"] == "ipopt" else "o", ls="", color=colours[r["method"]],
                      mec="black", ms=7 if r["method"] == "ipopt" else 8, label=r["method"])
               for r in methods]
    handles += [Line2D([], [], marker="o", ls="", color="0.5", alpha=0.3, ms=5, label="one spec"),
                Line2D([], [], marker="x", ls="", color="0.5", ms=5, label="one spec, no design"),
                Line2D([], [], color="black", lw=1.2, label=f"median time (p{SPREAD[0]}-p{SPREAD[1]} bar),\n"
                                                             "p90 gap (bar down to the median gap)"),
                Line2D([], [], ls="--", color="0.3", label="speed-accuracy front")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8.5, frameon=False)
    _label(ax, labels, bars)
    return fig


# Method labels: font size (points), marker radius (points) they keep clear of, and the offsets
# (points from the marker's centre to the label's lower left or lower right corner) tried in turn.
LABEL_SIZE = 9.0
MARKER_RADIUS = 6.0
LABEL_OFFSETS = tuple((dx, dy) for k in range(4) for dy in (7 + 12 * k, -7 - LABEL_SIZE - 12 * k) for dx in (7, -7))


def _label(ax, labels, bars) -> None:
    """Each method's name beside its point (the default method's first), at the first of
    LABEL_OFFSETS where it stays inside the axes and covers no method's marker, no label placed
    before it and no error bar; failing that, no marker and no label. ``bars`` are the error
    bars' ends, data units. Positions are taken after the figure's layout, which the labels are
    kept out of."""
    fig = ax.figure
    if fig.get_layout_engine() is not None:
        fig.get_layout_engine().execute(fig)
    scale = fig.dpi / 72.0
    frame = ax.bbox.extents   # the labels stay inside the axes
    centres = [ax.transData.transform((t, g)) for _, t, g, _, _ in labels]
    lines = []
    for a, b in bars:
        (x0, y0), (x1, y1) = ax.transData.transform(a), ax.transData.transform(b)
        lines.append((min(x0, x1) - 1, min(y0, y1) - 1, max(x0, x1) + 1, max(y0, y1) + 1))
    taken = []
    for text, t, g, colour, default in sorted(labels, key=lambda item: not item[4]):
        x0, y0 = ax.transData.transform((t, g))
        width, height = 0.6 * LABEL_SIZE * len(text) * scale, LABEL_SIZE * scale

        def box(offset):
            dx, dy = offset
            left = x0 + dx * scale - (width if dx < 0 else 0.0)
            return left, y0 + dy * scale, left + width, y0 + dy * scale + height

        def clear(offset, obstacles):
            b = box(offset)
            return (frame[0] <= b[0] and b[2] <= frame[2] and frame[1] <= b[1] and b[3] <= frame[3]
                    and not any(_overlaps(b, o) for o in taken + obstacles)
                    and not any(_covers(b, c, MARKER_RADIUS * scale) for c in centres))

        dx, dy = next((o for obstacles in (lines, []) for o in LABEL_OFFSETS if clear(o, obstacles)),
                      LABEL_OFFSETS[0])
        taken.append(box((dx, dy)))
        ax.annotate(text, (t, g), xytext=(dx, dy), textcoords="offset points", fontsize=LABEL_SIZE,
                    ha="right" if dx < 0 else "left", va="bottom", fontweight="bold" if default else "normal",
                    color=colour, zorder=4, in_layout=False)


def _overlaps(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _covers(box, centre, radius: float) -> bool:
    """Whether ``box`` (x0, y0, x1, y1) comes within ``radius`` of ``centre`` (display units)."""
    nearest_x = min(max(centre[0], box[0]), box[2])
    nearest_y = min(max(centre[1], box[1]), box[3])
    return math.hypot(centre[0] - nearest_x, centre[1] - nearest_y) < radius


def _tick(v: float) -> str:
    return "0" if v == 0 else f"{v:g}"
