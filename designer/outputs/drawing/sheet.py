"""The dimensioned shop drawing: an A3 sheet in first-angle projection with a side view above
a top view, the enlarged section, callouts for every machined feature, notes and a title block.
Dimensions along the beam are all from the clamp face and give the true sizes."""

from __future__ import annotations

import math

import numpy as np

from designer.outputs.drawing.pen import ARROW, DIM_PT, EXT_GAP, LABEL_PT, NOTE_PT, PT, TIER, Pen
from designer.outputs.drawing.section import draw_section
from designer.outputs.drawing.views import VIEW_LEFT, VIEW_WIDTH, ViewSetup, channel_runs, draw_view, length_axis
from designer.outputs.part import MM, BeamCad, fmt_mm

PAPER = (420.0, 297.0)        # A3 landscape, mm
BORDER = 10.0                 # mm
MIN_VIEW_DEPTH = 9.0          # a view is drawn at least this deep (mm), exaggerating if needed ...
MIN_EXAGGERATION = 1.5        # ... by at least this factor (a thinner view is left true to scale)
CALLOUT_BAND = 13.0           # height of the band of feature notes between the views, mm
# Load grooves each dimensioned from the clamp face on a line of their own, up to this many; more
# are given as ordinates: one extension line each down to a common line, the position written
# along it (and the figures in as many rows as they need not to touch)
STACKED_GROOVES = 6


def _ordinate_rows(grooves, X) -> list[int]:
    """Each groove's row of ordinate figures: the next row where its figure would touch the one
    before it in the row the groove before it took."""
    rows, height, count = [], DIM_PT * PT + 0.6, _row_count(grooves, X)   # a figure along its line: its height across
    for j, xg in enumerate(grooves):
        rows.append(0 if j == 0 or X(xg) - X(grooves[j - 1]) >= height else (rows[-1] + 1) % count)
    return rows


def _row_count(grooves, X) -> int:
    gaps = [X(b) - X(a) for a, b in zip(grooves, grooves[1:])]
    return max(1, math.ceil((DIM_PT * PT + 0.6) / min(gaps))) if gaps else 1


def _figure_length(grooves) -> float:
    return max(Pen.text_width(fmt_mm(x)) for x in grooves) + 1.5


def _grooves_depth(grooves, X) -> float:
    """How far below the first dimension line the grooves' dimensions reach, mm."""
    if len(grooves) <= STACKED_GROOVES:
        return len(grooves) * TIER
    return TIER + _row_count(grooves, X) * _figure_length(grooves)


def _dimension_grooves(pen, grooves, X, tier1: float, feet) -> None:
    """The grooves' positions from the clamp face below the top view: each on a dimension line of
    its own, or, past STACKED_GROOVES, as ordinates from the clamp face (0)."""
    if len(grooves) <= STACKED_GROOVES:
        for j, xg in enumerate(grooves):
            pen.dim_h(X(0.0), X(xg), tier1 - (j + 1) * TIER, fmt_mm(xg), feet=feet, side="below")
        return
    base = tier1 - TIER
    pen.line([X(0.0), X(0.0)], [feet[0] - EXT_GAP, base], "thin")
    pen.text(X(0.0), base - 1.0, "0", rotation=90, ha="right", va="center")
    length = _figure_length(grooves)
    for xg, row in zip(grooves, _ordinate_rows(grooves, X)):
        end = base - row * length
        pen.line([X(xg), X(xg)], [feet[1] - EXT_GAP, end], "thin")
        pen.text(X(xg), end - 1.0, fmt_mm(xg), rotation=90, ha="right", va="center", mask=True)


def plot_drawing(beam: BeamCad, ax=None):
    """The dimensioned shop drawing of ``beam`` on an A3 sheet; returns the figure."""
    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(PAPER[0] / 25.4, PAPER[1] / 25.4))
        ax = fig.add_axes((0, 0, 1, 1))
    fig = ax.figure
    ax.set_xlim(0, PAPER[0])
    ax.set_ylim(0, PAPER[1])
    ax.set_aspect("equal")
    ax.axis("off")
    pen = Pen(ax)
    pen.line([BORDER, PAPER[0] - BORDER, PAPER[0] - BORDER, BORDER, BORDER],
             [BORDER, BORDER, PAPER[1] - BORDER, PAPER[1] - BORDER, BORDER], "visible")

    X = length_axis(beam)
    n = len(beam.stations)
    c = beam.clamp
    grooves = beam.grooves.positions if beam.grooves is not None else ()
    # across the beam the views keep the length scale, unless a slender section needs more
    side_k = _depth_scale(X.scale, c.height)
    top_k = _depth_scale(X.scale, max(c.width, beam.width))
    sh, th = c.height / 2, max(c.width, beam.width) / 2
    side_depth, top_depth = 2 * sh / MM * side_k, 2 * th / MM * top_k

    # vertical layout: fixed bands from the top border down, the spare height spread between them
    bands = [(n + 2) * TIER + 3.0,            # station, free length and overall length dimensions
             side_depth,
             TIER + 12.0,                     # clamp length dimension and the view's name
             CALLOUT_BAND,
             10.0,                            # section marks A-A
             top_depth,
             TIER + _grooves_depth(grooves, X) + 12.0]  # bolts, pocket length, grooves and the view's name
    top_limit, bottom_limit = PAPER[1] - BORDER - 3.0, 66.0
    spare = max(0.0, top_limit - bottom_limit - sum(bands))
    gap = min(spare / 4, 14.0)
    y = top_limit - gap
    side_top = y - bands[0]
    side_centre = side_top - side_depth / 2
    side_bottom = side_top - side_depth
    callout_y = side_bottom - bands[2] - gap / 2 - CALLOUT_BAND / 2
    top_top = callout_y - CALLOUT_BAND / 2 - gap / 2 - bands[4]
    top_centre = top_top - top_depth / 2
    top_bottom = top_top - top_depth

    side = ViewSetup("SIDE VIEW", "z", ("+z", "-z"), "-y", side_centre, side_k)
    top = ViewSetup("TOP VIEW", "y", ("+y", "-y"), "+z", top_centre, top_k)
    draw_view(pen, beam, X, side)
    draw_view(pen, beam, X, top)

    def YS(t):
        return side_centre + t / MM * side_k

    def YT(t):
        return top_centre + t / MM * top_k

    # side view: stations, free length and overall length, all from the clamp face
    for i, d in enumerate(beam.stations):
        pen.dim_h(X(0.0), X(d), side_top + (i + 1) * TIER, fmt_mm(d), feet=(YS(sh), YS(beam.height / 2)))
    pen.dim_h(X(0.0), X(beam.length), side_top + (n + 1) * TIER, fmt_mm(beam.length),
              feet=(YS(sh), YS(beam.height / 2)))
    pen.dim_h(X(-c.length), X(beam.length), side_top + (n + 2) * TIER, fmt_mm(beam.overall_length),
              feet=(YS(sh), YS(beam.height / 2)))
    pen.text(X(0.0) - 1.0, side_top + 1.2, "CLAMP FACE", size=NOTE_PT - 1, ha="right", va="bottom")
    # side view: clamp length below, height at the free end
    pen.dim_h(X(-c.length), X(0.0), side_bottom - TIER, fmt_mm(c.length), feet=(YS(-sh), YS(-sh)), side="below")
    label = fmt_mm(beam.height) if beam.section == "rectangle" else "Ø" + fmt_mm(beam.height)
    pen.dim_v(YS(-beam.height / 2), YS(beam.height / 2), X(beam.length) + 7, label,
              feet=(X(beam.length), X(beam.length)), side="right")
    if beam.feature == "pocket" and beam.section != "rectangle":
        # a flat's floor radius, from below through the opening of the first lower flat
        a, rf = beam.stations[0] - beam.pocket_length / 2, beam.floor_radius
        inset = rf * (1 - math.sqrt(0.5))
        pen.leader((X(a + inset), YS(-(beam.height / 2 - beam.pocket_depth + inset))), (X(a) + 3.0, side_bottom - 6.0),
                   f"R{fmt_mm(rf)} TYP")
    side_label = side.name
    if side_k > X.scale * 1.01:
        side_label += f"  (heights drawn x{side_k / X.scale:.1f})"
    pen.text(X(-c.length), side_bottom - TIER - 6.0, side_label, size=LABEL_PT, ha="left", va="top",
             weight="bold")

    # top view: width at the free end, block width if wider, bolts, pocket length, grooves
    label = fmt_mm(beam.width) if beam.section == "rectangle" else "Ø" + fmt_mm(beam.width)
    pen.dim_v(YT(-beam.width / 2), YT(beam.width / 2), X(beam.length) + 7, label,
              feet=(X(beam.length), X(beam.length)), side="right")
    if c.width > beam.width + 1e-12:
        pen.dim_v(YT(-c.width / 2), YT(c.width / 2), X(-c.length) - 6, fmt_mm(c.width),
                  feet=(X(-c.length), X(-c.length)), side="left")
    tier1 = top_bottom - TIER
    xb = sorted(c.bolt_positions, reverse=True)  # nearest the clamp face first
    pen.dim_h(X(xb[0]), X(0.0), tier1, fmt_mm(-xb[0]), feet=(YT(0), YT(-th)), side="below")
    pen.dim_h(X(xb[1]), X(xb[0]), tier1, fmt_mm(xb[0] - xb[1]), feet=(YT(0), None), side="below")
    if beam.feature == "pocket":
        dn = beam.stations[-1]
        edge = -beam.flat_half_chord if beam.section != "rectangle" else -beam.pocket_width / 2
        pen.dim_h(X(dn - beam.pocket_length / 2), X(dn + beam.pocket_length / 2), tier1,
                  fmt_mm(beam.pocket_length), feet=(YT(edge), YT(edge)), side="below")
    _dimension_grooves(pen, grooves, X, tier1, (YT(-th), YT(-beam.width / 2)))
    top_label = top.name
    if top_k > X.scale * 1.01:
        top_label += f"  (widths drawn x{top_k / X.scale:.1f})"
    pen.text(X(-c.length), tier1 - _grooves_depth(grooves, X) - 6.0, top_label, size=LABEL_PT, ha="left",
             va="top", weight="bold")

    # section A-A through the first station, marked on the top view
    d0 = beam.stations[0]
    for s in (+1, -1):
        y0 = YT(s * th) + s * 2.0
        pen.line([X(d0), X(d0)], [y0, y0 + s * 4.0], "cut")
        pen.line([X(d0), X(d0) + 4.0], [y0 + s * 4.0, y0 + s * 4.0], "thin")
        pen.arrow((X(d0) + 4.0 + ARROW * 0.2, y0 + s * 4.0), (1, 0))
        pen.text(X(d0) + 6.5, y0 + s * 4.0, "A", size=LABEL_PT, ha="left", va="center", weight="bold")
    sec_cx, sec_cy = 352.0, (side_centre + top_centre) / 2 + 8.0
    k, sec_bottom = draw_section(pen, beam, sec_cx, sec_cy)
    pen.text(sec_cx, sec_bottom - 2.0, f"SECTION A-A  {_scale_text(k)}", size=LABEL_PT, va="top", weight="bold")
    pen.text(sec_cx, sec_bottom - 6.5, "the same at every station", size=NOTE_PT, va="top")

    _callouts(pen, beam, X, YS, YT, callout_y)
    _notes(pen, beam, X)
    _title_block(pen, beam)
    return fig


def _depth_scale(length_scale: float, size: float) -> float:
    """The scale across the beam in a view: the length scale, unless the view would be thinner
    than MIN_VIEW_DEPTH; small exaggerations (under MIN_EXAGGERATION) are not worth the distortion."""
    needed = MIN_VIEW_DEPTH / (size / MM)
    return needed if needed > MIN_EXAGGERATION * length_scale else length_scale


def _scale_text(k: float) -> str:
    if k >= 1:
        return f"{k:g}:1"
    return f"1:{1 / k:.3g}"


def _callouts(pen, beam: BeamCad, X, YS, YT, y) -> None:
    """Notes with leaders, in the band between the two views."""
    c = beam.clamp
    items = []  # (target, text)
    bolt = f"M{fmt_mm(c.bolt_diameter)}"
    items.append(((X(c.bolt_positions[1]), YT(c.bolt_clearance / 2)),
                  f"2x Ø{fmt_mm(c.bolt_clearance)} THRU ({bolt} CLEARANCE)"))
    d0 = beam.stations[0]
    if beam.feature == "pocket" and beam.section == "rectangle":
        r = beam.corner_radius
        x = d0 + beam.pocket_length / 2 - r * (1 - 0.70710678)
        yy = beam.pocket_width / 2 - r * (1 - 0.70710678)
        faces = "ALL 4 FACES" if beam.axes == 2 else "TOP AND BOTTOM"
        items.append(((X(x), YT(yy)), f"SLOT {fmt_mm(beam.pocket_length)} x {fmt_mm(beam.pocket_width)} x "
                      f"{fmt_mm(beam.pocket_depth)} DEEP, R{fmt_mm(r)} CORNERS (Ø{fmt_mm(beam.end_mill)} END MILL), "
                      f"FLOOR EDGES R{fmt_mm(beam.floor_radius)} (BULL-NOSE), {faces}, EACH STATION"))
    elif beam.feature == "pocket":
        faces = "ALL 4 SIDES" if beam.axes == 2 else "TOP AND BOTTOM"
        rf = beam.floor_radius
        items.append(((X(d0 + beam.pocket_length / 4), YT(beam.flat_half_chord)),
                      f"FLAT {fmt_mm(beam.pocket_length)} LONG x {fmt_mm(beam.pocket_depth)} DEEP "
                      f"({fmt_mm(beam.width - 2 * beam.pocket_depth)} ACROSS FLATS), ENDS R{fmt_mm(rf)} "
                      f"(BULL-NOSE{', ' + beam.tool.upper() + ' ACROSS' if beam.tool else ''}), {faces}, "
                      "EACH STATION"))

    elif beam.feature == "hole":
        r = beam.hole_diameter / 2
        items.append(((X(d0 + r * 0.70710678), YS(-r * 0.70710678)),
                      f"{len(beam.stations)}x Ø{fmt_mm(beam.hole_diameter)} THRU"))
    if beam.channels is not None:
        a, b = channel_runs(beam)[0]
        items.append(((X((a + b) / 2), YT(beam.channels.width / 2)),
                      f"WIRE CHANNEL {fmt_mm(beam.channels.width)} WIDE x {fmt_mm(beam.channels.depth)} DEEP "
                      f"TO THE CLAMP FACE, EACH POCKETED FACE"))
    if beam.grooves is not None:
        g = beam.grooves
        items.append(((X(g.positions[0]), YT(beam.width / 2 - g.depth)),
                      f"{len(g.positions)}x LOAD GROOVE {fmt_mm(g.width)} WIDE x {fmt_mm(g.depth)} DEEP, "
                      f"R{fmt_mm(g.width / 2)} FULL-RADIUS ROOT, ALL AROUND"))
    _place_callouts(pen, items, y)


def _place_callouts(pen, items: list, y: float) -> None:
    """Two rows of notes; each leader runs from the start of its text to its target.

    Every split of the notes between the rows is tried; a split is valid when no texts in a row
    overlap and no leader passes through a text of the other row (a leader from the upper row
    to a target below the band, or from the lower row to one above it, in the side view). The
    valid split whose texts sit nearest above their targets wins."""
    import itertools

    items = sorted(items, key=lambda it: it[0][0])
    rows = (y + 3.0, y - 3.2)
    right = VIEW_LEFT + VIEW_WIDTH + 12.0
    widths = [pen.text_width(text, NOTE_PT) for _, text in items]
    best = None
    for split in itertools.product((0, 1), repeat=len(items)):
        starts, ok = [], True
        ends = [-math.inf, -math.inf]
        for (target, _), w, row in zip(items, widths, split):
            x0 = max(target[0] - 1.5, ends[row] + 4.0)
            x0 = min(x0, right - w)
            if x0 < ends[row] + 4.0 or x0 < BORDER + 4.0:
                ok = False
                break
            ends[row] = x0 + w
            starts.append(x0)
        if not ok:
            continue
        for (target, _), x0, row in zip(items, starts, split):
            crossed = 1 if row == 0 and target[1] < rows[1] else 0 if row == 1 and target[1] > rows[0] else None
            if crossed is None:
                continue
            lo, hi = sorted((x0 - 2.0, target[0]))
            for x1, w1, row1 in zip(starts, widths, split):
                if row1 == crossed and x1 - 1.0 < hi and x1 + w1 + 1.0 > lo:
                    ok = False
        if not ok:
            continue
        cost = sum(abs(x0 - (t[0] - 1.5)) for (t, _), x0 in zip(items, starts)) + 0.1 * sum(split)
        if best is None or cost < best[0]:
            best = (cost, split, starts)
    if best is None:  # crowded: one note per row, alternating, leaders may cross
        split = [i % 2 for i in range(len(items))]
        starts, ends = [], [-math.inf, -math.inf]
        for (target, _), w, row in zip(items, widths, split):
            starts.append(max(target[0] - 1.5, ends[row] + 4.0))
            ends[row] = starts[-1] + w
    else:
        _, split, starts = best
    for (target, text), x0, row in zip(items, starts, split):
        yy = rows[row]
        pen.text(x0, yy, text, size=NOTE_PT, ha="left", va="center")
        knee = (x0 - 2.0, yy)
        pen.line([x0 - 0.6, knee[0]], [yy, yy], "thin")
        pen.line([knee[0], target[0]], [yy, target[1]], "thin")
        pen.arrow(target, np.subtract(target, knee))


def _notes(pen, beam: BeamCad, X) -> None:
    lines = ["NOTES",
             "1. Dimensions in mm. Positions along the beam are from the clamp face (X = 0).",
             "2. General tolerances ISO 2768-m. Break sharp edges 0.2 max." if not beam.tolerances else
             f"2. Tolerances {beam.tolerances}: every limit holds at their extremes. Break sharp edges 0.2 max."
             if beam.tolerances_hold else
             f"2. Tolerances {beam.tolerances}: some limits break at their extremes (report.md). Break sharp "
             "edges 0.2 max.",
             "3. Gauge faces and pocket floors: flat, Ra 1.6 or better, free of burrs "
             "(strain gauges are bonded there).",
             ]
    if beam.feature == "pocket":
        where = "all four faces" if beam.axes == 2 else "the top and bottom faces"
        what = "slot pockets" if beam.section == "rectangle" else "flats"
        lines.append(f"4. Identical {what} at every station, on {where}, centred on the gauge stations.")
        walls = "its walls all round" if beam.section == "rectangle" else "its two end walls"
        mill = f"the {beam.tool}" if beam.tool else "the end mill"
        lines.append(f"{len(lines)}. Each floor meets {walls} in R{fmt_mm(beam.floor_radius)}, the corner radius "
                     f"of {mill}: no sharp inside corner (it would raise the stress there).")
    elif beam.feature == "hole":
        lines.append("4. Through-holes on the beam's axis at every station, square to the gauge faces.")
    else:
        lines.append("4. No machining at the stations: the gauges are bonded on the plain faces (shown dashed).")
    if beam.section == "tube":
        lines.append(f"{len(lines)}. Bore Ø{fmt_mm(beam.width - 2 * beam.wall)} from the free end to the clamp face; "
                     "the clamp block is solid.")
    if beam.stock:
        lines.append(f"{len(lines)}. Stock: {beam.stock}; its section is used as supplied.")
    if X.gaps:
        lines.append(f"{len(lines)}. Long plain lengths are shown broken; the dimensions give the true lengths.")
    y = 60.0
    for i, text in enumerate(lines):
        pen.text(BORDER + 4, y - i * 4.2, text, size=NOTE_PT, ha="left", va="top",
                 weight="bold" if i == 0 else "normal")


# The design's name in the title block: TITLE_PT, smaller for a long name down to MIN_TITLE_PT,
# then cut with an ellipsis; BOLD_WIDTH: bold DejaVu Sans is about this much wider than the pen's
# estimate for regular text.
TITLE_PT, MIN_TITLE_PT, BOLD_WIDTH = 13.0, 8.0, 1.12


def _title_fit(pen, name: str, room: float) -> tuple[str, float]:
    """``(text, size)`` of ``name`` that fits ``room`` mm in the title block."""
    width = pen.text_width(name, TITLE_PT) * BOLD_WIDTH
    size = max(MIN_TITLE_PT, TITLE_PT * min(1.0, room / width)) if width else TITLE_PT
    while len(name) > 1 and pen.text_width(name, size) * BOLD_WIDTH > room:
        name = name[:-2].rstrip() + "…"
    return name, size


def _title_block(pen, beam: BeamCad) -> None:
    x0, x1, y0, y1 = 262.0, PAPER[0] - BORDER, BORDER, 62.0
    pen.line([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], "visible")
    rows = [y1 - 14.0, y1 - 24.0, y1 - 34.0, y1 - 44.0]
    for yy in rows:
        pen.line([x0, x1], [yy, yy], "thin")
    pen.line([x0 + 74, x0 + 74], [y0, rows[0]], "thin")
    pen.text(x0 + 3, y1 - 3, "fpdesign force-and-position cantilever", size=NOTE_PT - 0.5, ha="left", va="top")
    name, size = _title_fit(pen, beam.name, x1 - x0 - 6)
    pen.text(x0 + 3, y1 - 7.3, name, size=size, ha="left", va="top", weight="bold")

    def cell(col, row, label, value):
        x = x0 + (3 if col == 0 else 77)
        top = rows[row]
        pen.text(x, top - 1.5, label, size=NOTE_PT - 1.2, ha="left", va="top", color="#444444")
        pen.text(x, top - 4.6, value, size=NOTE_PT + 0.5, ha="left", va="top")

    stations = ", ".join(fmt_mm(d) for d in beam.stations)
    cell(0, 0, "MATERIAL", beam.material)
    cell(1, 0, "SECTION", beam.section_label())
    cell(0, 1, "FREE LENGTH / OVERALL", f"{fmt_mm(beam.length)} / {fmt_mm(beam.overall_length)} mm")
    cell(1, 1, "GAUGE STATIONS FROM CLAMP FACE", f"{stations} mm")
    feature = {"pocket": "slot pockets" if beam.section == "rectangle" else "flats", "hole": "through-holes",
               "none": "none (plain faces)"}[beam.feature]
    cell(0, 2, "FEATURE", feature)
    cell(1, 2, "GAUGE", f"{beam.gauge_name} {fmt_mm(beam.gauge_length)} x {fmt_mm(beam.gauge_width)} mm, "
                        f"{'2 axes' if beam.axes == 2 else '1 axis'}")
    cell(0, 3, "UNITS / SHEET", "mm / A3, first-angle projection")
    status = beam.status
    warn = status == "infeasible"
    cell(1, 3, "DESIGN STATUS", "INFEASIBLE: does not meet every limit" if warn else status)
