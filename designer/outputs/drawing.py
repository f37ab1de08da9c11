"""A dimensioned shop drawing and a rendered picture of a designed beam (matplotlib only).

``plot_drawing(beam)`` draws an A3 sheet in first-angle projection: a side view (``X``-``Z``)
above a top view (``X``-``Y``), an enlarged section through the first station, callouts for
every machined feature, notes and a title block. Long plain runs of the beam are shortened
with break lines and a slender section is drawn deeper than the length scale (the view says
so); the dimensions, along the beam all from the clamp face, give the true sizes.
``plot_model(meshes, beam)`` renders the tessellated solid in orthographic projection: shaded
triangles painted far to near, and the solid's edges with hidden parts removed against a depth
buffer. Both take ``ax=None`` and return the figure; neither touches pyplot or rcParams.
"""

from __future__ import annotations

import io
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designer.outputs.cad import MM, BeamCad, fmt_mm
from designer.outputs.files import atomic_write_bytes

# ----------------------------------------------------------------- sheet conventions

PAPER = (420.0, 297.0)        # A3 landscape, mm
BORDER = 10.0                 # mm
PT = 25.4 / 72                # mm per typographic point
DIM_PT = 7.5                  # dimension text, pt (2.6 mm, ISO 3098 small lettering)
NOTE_PT = 6.8
LABEL_PT = 8.0
CHAR_WIDTH = 0.62             # average DejaVu Sans advance for digits and capitals, in font heights
ARROW = 2.4                   # arrowhead length, mm
ARROW_HALF = 0.45             # arrowhead half width, mm
TIER = 6.5                    # spacing of stacked dimension lines, mm
EXT_GAP = 1.0                 # gap between a feature and its extension line, mm
EXT_OVER = 1.5                # extension line beyond the dimension line, mm
BREAK_PAPER = 18.0            # paper length of a shortened plain run, mm
BREAK_SHARE = 0.25            # a plain run is shortened when longer than this share of the rest ...
BREAK_MIN_SIZES = 6.0         # ... and longer than this many section sizes
BREAK_HALF_GAP = 1.6          # half the gap between the two break lines, mm
VIEW_LEFT = 24.0              # left end of the main views, mm
VIEW_WIDTH = 268.0            # paper length available to the main views, mm
MIN_VIEW_DEPTH = 9.0          # a view is drawn at least this deep (mm), exaggerating if needed ...
MIN_EXAGGERATION = 1.5        # ... by at least this factor (a thinner view is left true to scale)
MAX_VIEW_DEPTH = 60.0         # the length scale is reduced so that no view is deeper (mm)
MAX_LENGTH_SCALE = 4.0        # paper mm per model mm along the beam, at most
CALLOUT_BAND = 13.0           # height of the band of feature notes between the views, mm
SECTION_BOX = 58.0            # the enlarged section fits in this square, mm
SECTION_SCALES = (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10, 15, 20)

INK = "black"
GAUGE_INK = "#1f5fbf"
THICK, THIN = 0.9, 0.4        # line widths, pt (ISO 128 wide and narrow lines on a screen)
HIDDEN = (0, (4.0, 2.0))      # dash patterns, in line widths
CHAIN = (0, (12.0, 3.0, 2.0, 3.0))
PHANTOM = (0, (10.0, 2.5, 2.0, 2.5, 2.0, 2.5))


# ----------------------------------------------------------------- the length axis

@dataclass(frozen=True)
class _LengthAxis:
    """Paper position along the beam: piecewise linear, with long plain runs shortened."""

    knots_model: tuple     # m
    knots_paper: tuple     # mm
    gaps: tuple            # (paper start, paper end) of the blank gap in each break
    scale: float           # paper mm per model mm in the unbroken parts

    def __call__(self, x: float) -> float:
        return float(np.interp(x, self.knots_model, self.knots_paper))

    def pieces(self, x0: float, x1: float) -> list[tuple[float, float]]:
        """The paper intervals of ``[x0, x1]`` (model) that are not inside a break gap."""
        a, b = sorted((self(x0), self(x1)))
        out = [(a, b)]
        for g0, g1 in self.gaps:
            nxt = []
            for p0, p1 in out:
                if p1 <= g0 or p0 >= g1:
                    nxt.append((p0, p1))
                    continue
                if p0 < g0:
                    nxt.append((p0, g0))
                if p1 > g1:
                    nxt.append((g1, p1))
            out = nxt
        return out


def _length_axis(beam: BeamCad) -> _LengthAxis:
    """Shorten the longest plain runs while each one is a large share of what is left
    (breaking it enlarges the drawing by a third or more) and long against the section."""
    c = beam.clamp
    size = max(beam.width, beam.height, c.width)
    spans = [(-c.length, 0.0)]
    spans += [(d - beam.feature_length / 2, d + beam.feature_length / 2) for d in beam.stations]
    if beam.grooves is not None:
        spans += [(x - beam.grooves.width / 2, x + beam.grooves.width / 2) for x in beam.grooves.positions]
    spans.append((beam.length, beam.length))
    spans.sort()
    runs = sorted(((b0 - a1, a1, b0) for (a0, a1), (b0, b1) in zip(spans, spans[1:]) if b0 > a1), reverse=True)
    kept = c.length + beam.length
    broken = []
    for length, a, b in runs:
        if length > BREAK_SHARE * kept and length > BREAK_MIN_SIZES * size:
            broken.append((a, b))
            kept -= length
    broken.sort()
    scale = min((VIEW_WIDTH - BREAK_PAPER * len(broken)) / (kept / MM), MAX_LENGTH_SCALE,
                MAX_VIEW_DEPTH / (max(c.width, beam.width, beam.height) / MM))
    knots_m, knots_p, gaps = [-c.length], [VIEW_LEFT], []
    for a, b in broken:
        pa = knots_p[-1] + (a - knots_m[-1]) / MM * scale
        knots_m += [a, b]
        knots_p += [pa, pa + BREAK_PAPER]
        mid = pa + BREAK_PAPER / 2
        gaps.append((mid - BREAK_HALF_GAP, mid + BREAK_HALF_GAP))
    knots_m.append(beam.length)
    knots_p.append(knots_p[-1] + (beam.length - knots_m[-2]) / MM * scale)
    return _LengthAxis(tuple(knots_m), tuple(knots_p), tuple(gaps), scale)


# ----------------------------------------------------------------- drawing primitives

class _Pen:
    """Lines, arrows, text and dimensions on one axes in paper millimetres."""

    def __init__(self, ax):
        self.ax = ax

    def line(self, xs, ys, kind="visible", color=INK, zorder=3):
        style = {"visible": ("-", THICK), "thin": ("-", THIN), "hidden": (HIDDEN, THIN * 1.2),
                 "chain": (CHAIN, THIN), "phantom": (PHANTOM, THIN), "cut": ("-", THICK * 1.8)}[kind]
        self.ax.plot(xs, ys, linestyle=style[0], linewidth=style[1], color=color, solid_capstyle="butt",
                     dash_capstyle="butt", zorder=zorder)

    def text(self, x, y, s, size=DIM_PT, ha="center", va="bottom", rotation=0, color=INK, weight="normal",
             zorder=5, mask=False):
        """Text; ``mask`` blanks the lines behind it, as dimension figures do."""
        box = {"facecolor": "white", "edgecolor": "none", "pad": 0.4} if mask else None
        self.ax.text(x, y, s, fontsize=size, ha=ha, va=va, rotation=rotation, color=color, weight=weight,
                     zorder=zorder, rotation_mode="anchor", bbox=box)

    @staticmethod
    def text_width(s: str, size=DIM_PT) -> float:
        return len(s) * CHAR_WIDTH * size * PT

    def arrow(self, tip, direction):
        """A filled arrowhead with its point at ``tip``, pointing along ``direction``."""
        from matplotlib.patches import Polygon

        d = np.asarray(direction, float)
        d /= np.linalg.norm(d)
        n = np.array([-d[1], d[0]])
        tip = np.asarray(tip, float)
        base = tip - ARROW * d
        self.ax.add_patch(Polygon([tip, base + ARROW_HALF * n, base - ARROW_HALF * n], closed=True,
                                  facecolor=INK, edgecolor=INK, linewidth=0.2, zorder=4))

    def dim_h(self, x0, x1, y, text, feet=(None, None), side="above"):
        """A horizontal dimension at height ``y`` between ``x0`` and ``x1`` with extension lines from
        the feature points ``feet`` (paper y of each end, or None for no extension line)."""
        for x, foot in zip((x0, x1), feet):
            if foot is None:
                continue
            sgn = 1 if y > foot else -1
            self.line([x, x], [foot + sgn * EXT_GAP, y + sgn * EXT_OVER], "thin")
        span = abs(x1 - x0)
        width = self.text_width(text)
        lo, hi = min(x0, x1), max(x0, x1)
        ty = y + 0.7 if side == "above" else y - 0.7
        va = "bottom" if side == "above" else "top"
        if span >= width + 2 * ARROW + 1.5:
            self.line([lo, hi], [y, y], "thin")
            self.arrow((lo, y), (-1, 0))
            self.arrow((hi, y), (1, 0))
            self.text((lo + hi) / 2, ty, text, va=va, mask=True)
        else:  # arrows outside, text beyond the right arrow
            self.line([lo - ARROW - 2.0, hi + ARROW + 1.0], [y, y], "thin")
            self.arrow((lo, y), (1, 0))
            self.arrow((hi, y), (-1, 0))
            self.text(hi + ARROW + 1.5, ty, text, ha="left", va=va, mask=True)

    def dim_v(self, y0, y1, x, text, feet=(None, None), side="left"):
        """A vertical dimension at ``x`` between ``y0`` and ``y1`` (text reads from below)."""
        for yy, foot in zip((y0, y1), feet):
            if foot is None:
                continue
            sgn = 1 if x > foot else -1
            self.line([foot + sgn * EXT_GAP, x + sgn * EXT_OVER], [yy, yy], "thin")
        span = abs(y1 - y0)
        width = self.text_width(text)
        lo, hi = min(y0, y1), max(y0, y1)
        tx = x - 0.7 if side == "left" else x + 0.7 + DIM_PT * PT
        if span >= width + 2 * ARROW + 1.5:
            self.line([x, x], [lo, hi], "thin")
            self.arrow((x, lo), (0, -1))
            self.arrow((x, hi), (0, 1))
            self.text(tx, (lo + hi) / 2, text, rotation=90, va="bottom", ha="center", mask=True)
        else:  # arrows outside, text beside the line
            self.line([x, x], [lo - ARROW - 1.5, hi + ARROW + 1.5], "thin")
            self.arrow((x, lo), (0, 1))
            self.arrow((x, hi), (0, -1))
            ha = "right" if side == "left" else "left"
            self.text(x - 1.2 if side == "left" else x + 1.2, (lo + hi) / 2, text, ha=ha, va="center", mask=True)

    def dim_diameter(self, cx, cy, r, angle_deg, text):
        """A diameter dimension through the centre of a circle, at ``angle_deg``, text along it."""
        u = np.array([math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))])
        a, b = np.array([cx, cy]) - r * u, np.array([cx, cy]) + r * u
        self.line([a[0], b[0]], [a[1], b[1]], "thin")
        self.arrow(a, -u)
        self.arrow(b, u)
        n = np.array([-u[1], u[0]])
        at = np.array([cx, cy]) + 0.5 * r * u + 0.7 * n
        self.text(at[0], at[1], text, rotation=angle_deg, ha="center", va="bottom", mask=True)

    def leader(self, target, anchor, text, ha="left", va="center"):
        """A note at ``anchor`` with a leader line ending in an arrow at ``target``."""
        tx, ty = anchor
        self.line([tx, target[0]], [ty, target[1]], "thin")
        d = np.subtract(target, anchor)
        if np.linalg.norm(d) > ARROW:
            self.arrow(target, d)
        pad = 0.8
        self.text(tx + (pad if ha == "left" else -pad if ha == "right" else 0), ty, text, ha=ha, va=va)


# ----------------------------------------------------------------- one orthographic view

@dataclass(frozen=True)
class _ViewSetup:
    name: str
    axis: str                # the transverse axis drawn up the paper: "z" (side) or "y" (top)
    edge_faces: tuple        # faces seen edge-on (their normal is +-axis)
    facing: str              # the featured face turned to the viewer
    centre: float            # paper y of the beam's axis
    scale: float             # paper mm per model mm across the beam


def _half(beam: BeamCad, axis: str) -> float:
    return (beam.height if axis == "z" else beam.width) / 2


def _block_half(beam: BeamCad, axis: str) -> float:
    return (beam.clamp.height if axis == "z" else beam.clamp.width) / 2


def _block_is_bar(beam: BeamCad) -> bool:
    """True when the clamp block is simply the bar continued (no edge at the clamp face)."""
    return beam.section == "rectangle" and abs(beam.clamp.width - beam.width) < 1e-12


def _draw_view(pen: _Pen, beam: BeamCad, X: _LengthAxis, v: _ViewSetup) -> None:
    def Y(t):  # model transverse coordinate (m) -> paper
        return v.centre + t / MM * v.scale

    def hline(x0, x1, t, kind="visible", color=INK):
        for p0, p1 in X.pieces(x0, x1):
            pen.line([p0, p1], [Y(t), Y(t)], kind, color)

    def vline(x, t0, t1, kind="visible", color=INK):
        pen.line([X(x), X(x)], [Y(t0), Y(t1)], kind, color)

    c = beam.clamp
    half, hb = _half(beam, v.axis), _block_half(beam, v.axis)
    L = beam.length
    edge_cut = [f for f in v.edge_faces if f in beam.cut_faces]
    face_cut = v.facing in beam.cut_faces
    lp, wp, p = beam.pocket_length, beam.pocket_width, beam.pocket_depth
    flats = beam.feature == "pocket" and beam.section != "rectangle"
    slots = beam.feature == "pocket" and beam.section == "rectangle"

    # clamp block
    for s in (+1, -1):
        hline(-c.length, 0.0, s * hb)
    vline(-c.length, -hb, hb)
    if not _block_is_bar(beam):
        vline(0.0, -hb, hb)
    # silhouette of the free length, notched by grooves and by flats seen edge-on
    for s, face in ((+1, f"+{v.axis}"), (-1, f"-{v.axis}")):
        notches = []
        if beam.grooves is not None:
            notches += [(x - beam.grooves.width / 2, x + beam.grooves.width / 2, beam.grooves.depth)
                        for x in beam.grooves.positions]
        if flats and face in edge_cut:
            notches += [(d - lp / 2, d + lp / 2, p) for d in beam.stations]
        cur = 0.0
        for a, b, depth in sorted(notches):
            hline(cur, a, s * half)
            vline(a, s * half, s * (half - depth))
            hline(a, b, s * (half - depth))
            vline(b, s * (half - depth), s * half)
            cur = b
        hline(cur, L, s * half)
    vline(L, -half, half)
    # grooves seen on the facing side: their two walls
    if beam.grooves is not None:
        g = beam.grooves
        for x in g.positions:
            for e in (-g.width / 2, g.width / 2):
                vline(x + e, -(half - g.depth), half - g.depth, "thin")
    # features seen edge-on
    for face in edge_cut:
        s = 1 if face.startswith("+") else -1
        for d in beam.stations:
            if slots:  # hidden behind the slot's side walls
                hline(d - lp / 2, d + lp / 2, s * (half - p), "hidden")
                vline(d - lp / 2, s * half, s * (half - p), "hidden")
                vline(d + lp / 2, s * half, s * (half - p), "hidden")
    # features seen face-on
    if face_cut:
        for d in beam.stations:
            if slots:
                _rounded_rect(pen, X, Y, d, lp, wp, beam.corner_radius)
            else:
                hc = beam.flat_half_chord
                for t in (-hc, hc):
                    hline(d - lp / 2, d + lp / 2, t)
                vline(d - lp / 2, -hc, hc)
                vline(d + lp / 2, -hc, hc)
    # through-holes along Y
    if beam.feature == "hole":
        r = beam.hole_diameter / 2
        for d in beam.stations:
            if v.axis == "z":
                _circle(pen, X(d), Y(0), r / MM * X.scale, r / MM * v.scale)
                _centre_cross(pen, X(d), Y(0), r / MM * X.scale + 1.5, r / MM * v.scale + 1.5)
            else:
                vline(d - r, -half, half, "hidden")
                vline(d + r, -half, half, "hidden")
                vline(d, -half - 1.5 * MM / v.scale, half + 1.5 * MM / v.scale, "chain")
    # bolt holes along Z
    rb = c.bolt_clearance / 2
    for xb in c.bolt_positions:
        if v.axis == "z":
            vline(xb - rb, -hb, hb, "hidden")
            vline(xb + rb, -hb, hb, "hidden")
            vline(xb, -hb - 1.5 * MM / v.scale, hb + 1.5 * MM / v.scale, "chain")
        else:
            _circle(pen, X(xb), Y(0), rb / MM * X.scale, rb / MM * v.scale)
            _centre_cross(pen, X(xb), Y(0), rb / MM * X.scale + 1.5, rb / MM * v.scale + 1.5)
    # wire channels
    if beam.channels is not None:
        cw, cd = beam.channels.width, beam.channels.depth
        runs = _channel_runs(beam)
        for face in edge_cut:
            s = 1 if face.startswith("+") else -1
            for a, b in runs:
                hline(a, b, s * (half - cd), "hidden")
            hline(-cw / 2, 0.0, s * (half - cd), "hidden")
            vline(-cw / 2, s * half, s * (half - cd), "hidden")
        if face_cut:
            for a, b in runs:
                for t in (-cw / 2, cw / 2):
                    hline(a, b, t)
            _half_circle(pen, X(0.0), Y(0.0), cw / 2 / MM * X.scale, cw / 2 / MM * v.scale)
    # the tube's bore, from the free end to the clamp face
    if beam.section == "tube":
        ri = beam.radius - beam.wall
        for t in (-ri, ri):
            hline(0.0, L, t, "hidden")
        vline(0.0, -ri, ri, "hidden")
    # gauges on the facing face (reference only)
    if v.facing in beam.faces:
        for d in beam.stations:
            gl, gw = beam.gauge_length, beam.gauge_width
            xs = [X(d - gl / 2), X(d + gl / 2), X(d + gl / 2), X(d - gl / 2), X(d - gl / 2)]
            ys = [Y(-gw / 2), Y(-gw / 2), Y(gw / 2), Y(gw / 2), Y(-gw / 2)]
            pen.line(xs, ys, "phantom", GAUGE_INK, zorder=2)
    # centre lines: the beam's axis, each station, the clamp face datum
    over = 3.0 * MM / X.scale
    for p0, p1 in X.pieces(-c.length - over, L + over):
        pen.line([p0, p1], [Y(0), Y(0)], "chain")
    ext = 2.0 * MM / v.scale
    for d in beam.stations:
        vline(d, -half - ext, half + ext, "chain")
    vline(0.0, -hb - ext, hb + ext, "chain")
    # break lines
    for g0, g1 in X.gaps:
        for gx in (g0, g1):
            _break_line(pen, gx, Y(-half), Y(half))


def _channel_runs(beam: BeamCad) -> list[tuple[float, float]]:
    """Stretches of wire channel outside the pockets, from the clamp face to the farthest pocket."""
    lp = beam.pocket_length
    edges = [0.0]
    for d in beam.stations:
        edges += [d - lp / 2, d + lp / 2]
    return [(edges[i], edges[i + 1]) for i in range(0, len(edges) - 2, 2)]


def _circle(pen, cx, cy, rx, ry, kind="visible"):
    a = np.linspace(0, 2 * np.pi, 121)
    pen.line(cx + rx * np.cos(a), cy + ry * np.sin(a), kind)


def _half_circle(pen, cx, cy, rx, ry):
    a = np.linspace(np.pi / 2, 3 * np.pi / 2, 61)
    pen.line(cx + rx * np.cos(a), cy + ry * np.sin(a))


def _centre_cross(pen, cx, cy, hx, hy):
    pen.line([cx - hx, cx + hx], [cy, cy], "chain")
    pen.line([cx, cx], [cy - hy, cy + hy], "chain")


def _rounded_rect(pen, X, Y, d, length, width, r):
    """A slot outline of ``length`` x ``width`` with corner radius ``r`` centred at ``(d, 0)``."""
    pts = []
    cx, cy = length / 2 - r, width / 2 - r
    for (sx, sy), a0 in (((1, 1), 0.0), ((-1, 1), 90.0), ((-1, -1), 180.0), ((1, -1), 270.0)):
        a = np.radians(np.linspace(a0, a0 + 90.0, 16))
        pts += list(zip(d + sx * cx + r * np.cos(a), sy * cy + r * np.sin(a)))
    pts.append(pts[0])
    pen.line([X(x) for x, _ in pts], [Y(y) for _, y in pts])


def _break_line(pen, x, y0, y1):
    """A freehand-style short break line across the part."""
    if y1 < y0:
        y0, y1 = y1, y0
    t = np.linspace(0, 1, 40)
    ys = y0 - 1.0 + (y1 - y0 + 2.0) * t
    xs = x + 0.9 * np.sin(2 * np.pi * 1.5 * t)
    pen.line(xs, ys, "thin")


# ----------------------------------------------------------------- the section

def _section_outline(beam: BeamCad) -> list[np.ndarray]:
    """Closed outlines (model metres, (y, z)) of the section through a station; the first is the
    outer boundary, the rest are holes. A through-hole splits the section into two pieces."""
    b, h = beam.width, beam.height
    faces = beam.cut_faces
    if beam.section == "rectangle":
        if beam.feature == "hole":
            r = beam.hole_diameter / 2
            return [np.array([(-b / 2, r), (b / 2, r), (b / 2, h / 2), (-b / 2, h / 2)]),
                    np.array([(-b / 2, -h / 2), (b / 2, -h / 2), (b / 2, -r), (-b / 2, -r)])]
        p, w = beam.pocket_depth, beam.pocket_width
        pts = []
        # walk counter-clockwise: bottom (-z), right (+y), top (+z), left (-y)
        corners = [(-b / 2, -h / 2), (b / 2, -h / 2), (b / 2, h / 2), (-b / 2, h / 2)]
        sides = ["-z", "+y", "+z", "-y"]
        for i, face in enumerate(sides):
            a, e = np.array(corners[i]), np.array(corners[(i + 1) % 4])
            pts.append(tuple(a))
            if face in faces:
                u = (e - a) / np.linalg.norm(e - a)
                n = np.array([-u[1], u[0]])  # inward normal for a counter-clockwise walk
                mid = (a + e) / 2
                for q in (mid - u * w / 2, mid - u * w / 2 + n * p, mid + u * w / 2 + n * p, mid + u * w / 2):
                    pts.append(tuple(q))
        return [np.array(pts)]
    R = beam.radius
    a = np.linspace(0, 2 * np.pi, 721)[:-1]
    y, z = R * np.cos(a), R * np.sin(a)
    lim = R - beam.pocket_depth
    if "+z" in faces:
        z = np.minimum(z, lim)
    if "-z" in faces:
        z = np.maximum(z, -lim)
    if "+y" in faces:
        y = np.minimum(y, lim)
    if "-y" in faces:
        y = np.maximum(y, -lim)
    out = [np.column_stack([y, z])]
    if beam.section == "tube":
        ri = R - beam.wall
        out.append(np.column_stack([ri * np.cos(a[::-1]), ri * np.sin(a[::-1])]))
    return out


def _section_scale(beam: BeamCad) -> float:
    size = max(beam.width, beam.height) / MM
    fitting = [k for k in SECTION_SCALES if size * k <= SECTION_BOX]
    return fitting[-1] if fitting else SECTION_BOX / size


def _draw_section(pen: _Pen, beam: BeamCad, cx: float, cy: float) -> tuple[float, float]:
    """The section through the first station, centred at (cx, cy); returns (scale, bottom y)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    k = _section_scale(beam)

    def P(pts):
        return np.column_stack([cx + pts[:, 0] / MM * k, cy + pts[:, 1] / MM * k])

    outlines = _section_outline(beam)
    if beam.section == "rectangle" and beam.feature == "hole":
        pieces = [[o] for o in outlines]
    else:
        pieces = [outlines]
    for piece in pieces:
        verts, codes = [], []
        for o in piece:
            q = P(o)
            verts += list(q) + [q[0]]
            codes += [MplPath.MOVETO] + [MplPath.LINETO] * (len(q) - 1) + [MplPath.CLOSEPOLY]
        patch = PathPatch(MplPath(verts, codes), facecolor="none", edgecolor=INK, linewidth=THICK, hatch="////",
                          zorder=3)
        patch.set_hatch_linewidth(0.35)
        pen.ax.add_patch(patch)
    b, h = beam.width / MM * k, beam.height / MM * k
    _centre_cross(pen, cx, cy, b / 2 + 3, h / 2 + 3)
    bottom = cy - h / 2
    # overall size
    if beam.section == "rectangle":
        pen.dim_h(cx - b / 2, cx + b / 2, cy - h / 2 - 7, fmt_mm(beam.width), feet=(cy - h / 2, cy - h / 2),
                  side="below")
        pen.dim_v(cy - h / 2, cy + h / 2, cx + b / 2 + 8, fmt_mm(beam.height), feet=(cx + b / 2, cx + b / 2),
                  side="right")
        bottom = cy - h / 2 - 7 - DIM_PT * PT - 1
    else:
        if "+y" in beam.cut_faces:  # flats all round: the diameter remains only on the diagonals
            u = np.array([-1.0, -1.0]) / math.sqrt(2)
            target = np.array([cx, cy]) + b / 2 * u
            pen.leader(tuple(target), (cx - b / 2 - 6, cy - h / 2 - 5), "Ø" + fmt_mm(beam.width), ha="right")
            bottom = cy - h / 2 - 6
        else:
            pen.dim_h(cx - b / 2, cx + b / 2, cy - h / 2 - 7, "Ø" + fmt_mm(beam.width),
                      feet=(cy, cy), side="below")
            bottom = cy - h / 2 - 7 - DIM_PT * PT - 1
        if beam.section == "tube":
            ri = (beam.radius - beam.wall) / MM * k
            pen.dim_diameter(cx, cy, ri, 35.0, "Ø" + fmt_mm(beam.width - 2 * beam.wall))
    # the feature
    if beam.feature == "pocket":
        p = beam.pocket_depth / MM * k
        top = cy + h / 2
        if beam.section == "rectangle":
            w = beam.pocket_width / MM * k
            pen.dim_h(cx - w / 2, cx + w / 2, top + 6, fmt_mm(beam.pocket_width), feet=(top - p, top - p))
            pen.dim_v(top - p, top, cx - b / 2 - 6, fmt_mm(beam.pocket_depth), feet=(cx - w / 2, cx - b / 2),
                      side="left")
        else:
            hc = beam.flat_half_chord / MM * k
            pen.dim_h(cx - hc, cx + hc, top + 6, f"({fmt_mm(2 * beam.flat_half_chord)})", feet=(top - p, top - p))
            across = beam.width - 2 * beam.pocket_depth     # what the machinist measures
            pen.dim_v(cy - h / 2 + p, top - p, cx + b / 2 + 8, fmt_mm(across), feet=(cx + hc, cx + hc), side="right")
    elif beam.feature == "hole":
        r = beam.hole_diameter / 2 / MM * k
        pen.dim_v(cy - r, cy + r, cx - b / 2 - 6, "Ø" + fmt_mm(beam.hole_diameter), feet=(cx - b / 2, cx - b / 2),
                  side="left")
    return k, bottom


# ----------------------------------------------------------------- the sheet

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
    pen = _Pen(ax)
    pen.line([BORDER, PAPER[0] - BORDER, PAPER[0] - BORDER, BORDER, BORDER],
             [BORDER, BORDER, PAPER[1] - BORDER, PAPER[1] - BORDER, BORDER], "visible")

    X = _length_axis(beam)
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
             (1 + len(grooves)) * TIER + 12.0]  # bolts, pocket length, grooves and the view's name
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

    side = _ViewSetup("SIDE VIEW", "z", ("+z", "-z"), "-y", side_centre, side_k)
    top = _ViewSetup("TOP VIEW", "y", ("+y", "-y"), "+z", top_centre, top_k)
    _draw_view(pen, beam, X, side)
    _draw_view(pen, beam, X, top)

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
    for j, xg in enumerate(grooves):
        pen.dim_h(X(0.0), X(xg), tier1 - (j + 1) * TIER, fmt_mm(xg), feet=(YT(-th), YT(-beam.width / 2)),
                  side="below")
    top_label = top.name
    if top_k > X.scale * 1.01:
        top_label += f"  (widths drawn x{top_k / X.scale:.1f})"
    pen.text(X(-c.length), tier1 - len(grooves) * TIER - 6.0, top_label, size=LABEL_PT, ha="left", va="top",
             weight="bold")

    # section A-A through the first station, marked on the top view
    d0 = beam.stations[0]
    for s in (+1, -1):
        y0 = YT(s * th) + s * 2.0
        pen.line([X(d0), X(d0)], [y0, y0 + s * 4.0], "cut")
        pen.line([X(d0), X(d0) + 4.0], [y0 + s * 4.0, y0 + s * 4.0], "thin")
        pen.arrow((X(d0) + 4.0 + ARROW * 0.2, y0 + s * 4.0), (1, 0))
        pen.text(X(d0) + 6.5, y0 + s * 4.0, "A", size=LABEL_PT, ha="left", va="center", weight="bold")
    sec_cx, sec_cy = 352.0, (side_centre + top_centre) / 2 + 8.0
    k, sec_bottom = _draw_section(pen, beam, sec_cx, sec_cy)
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
                      f"{faces}, EACH STATION"))
    elif beam.feature == "pocket":
        faces = "ALL 4 SIDES" if beam.axes == 2 else "TOP AND BOTTOM"
        items.append(((X(d0 + beam.pocket_length / 4), YT(beam.flat_half_chord)),
                      f"FLAT {fmt_mm(beam.pocket_length)} LONG x {fmt_mm(beam.pocket_depth)} DEEP "
                      f"({fmt_mm(beam.width - 2 * beam.pocket_depth)} ACROSS FLATS), {faces}, EACH STATION"))
    elif beam.feature == "hole":
        r = beam.hole_diameter / 2
        items.append(((X(d0 + r * 0.70710678), YS(-r * 0.70710678)),
                      f"{len(beam.stations)}x Ø{fmt_mm(beam.hole_diameter)} THRU"))
    if beam.channels is not None:
        a, b = _channel_runs(beam)[0]
        items.append(((X((a + b) / 2), YT(beam.channels.width / 2)),
                      f"WIRE CHANNEL {fmt_mm(beam.channels.width)} WIDE x {fmt_mm(beam.channels.depth)} DEEP "
                      f"TO THE CLAMP FACE, EACH POCKETED FACE"))
    if beam.grooves is not None:
        g = beam.grooves
        items.append(((X(g.positions[0]), YT(beam.width / 2 - g.depth)),
                      f"{len(g.positions)}x LOAD GROOVE {fmt_mm(g.width)} WIDE x {fmt_mm(g.depth)} DEEP ALL AROUND"))
    _place_callouts(pen, items, y)


def _place_callouts(pen, items: list, y: float) -> None:
    """Two rows of notes; each leader runs from the start of its text to its target.

    Every split of the notes between the rows is tried; a split is valid when no texts in a row
    overlap and no leader from the upper row passes through a text of the lower row. The valid
    split whose texts sit nearest above their targets wins."""
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
            if row != 0:
                continue
            lo, hi = sorted((x0 - 2.0, target[0]))
            for x1, w1, row1 in zip(starts, widths, split):
                if row1 == 1 and x1 - 1.0 < hi and x1 + w1 + 1.0 > lo:
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
             "2. General tolerances ISO 2768-m. Break sharp edges 0.2 max.",
             "3. Gauge faces and pocket floors: flat, Ra 1.6 or better, free of burrs "
             "(strain gauges are bonded there).",
             ]
    if beam.feature == "pocket":
        where = "all four faces" if beam.axes == 2 else "the top and bottom faces"
        what = "slot pockets" if beam.section == "rectangle" else "flats"
        lines.append(f"4. Identical {what} at every station, on {where}, centred on the gauge stations.")
    elif beam.feature == "hole":
        lines.append("4. Through-holes on the beam's axis at every station, square to the gauge faces.")
    else:
        lines.append("4. No machining at the stations: the gauges are bonded on the plain faces (shown dashed).")
    if beam.section == "tube":
        lines.append(f"5. Bore Ø{fmt_mm(beam.width - 2 * beam.wall)} from the free end to the clamp face; "
                     "the clamp block is solid.")
    if X.gaps:
        lines.append(f"{len(lines)}. Long plain lengths are shown broken; the dimensions give the true lengths.")
    y = 60.0
    for i, text in enumerate(lines):
        pen.text(BORDER + 4, y - i * 4.2, text, size=NOTE_PT, ha="left", va="top",
                 weight="bold" if i == 0 else "normal")


def _title_block(pen, beam: BeamCad) -> None:
    x0, x1, y0, y1 = 262.0, PAPER[0] - BORDER, BORDER, 62.0
    pen.line([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], "visible")
    rows = [y1 - 14.0, y1 - 24.0, y1 - 34.0, y1 - 44.0]
    for yy in rows:
        pen.line([x0, x1], [yy, yy], "thin")
    pen.line([x0 + 74, x0 + 74], [y0, rows[0]], "thin")
    pen.text(x0 + 3, y1 - 3, "fpdesign force-and-position cantilever", size=NOTE_PT - 0.5, ha="left", va="top")
    pen.text(x0 + 3, y1 - 7.3, beam.name, size=13, ha="left", va="top", weight="bold")

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


# ----------------------------------------------------------------- the 3-D picture

BASE_COLOUR = np.array([0.72, 0.76, 0.82])   # anodised-aluminium grey-blue
EDGE_COLOUR = (0.12, 0.13, 0.16)
AMBIENT, KEY, HEAD = 0.30, 0.60, 0.20        # light shares: ambient, key light, head light
VIEW = (22.0, -62.0)                         # elevation and azimuth of the camera, degrees
DETAIL_VIEW = (26.0, -50.0)
GAUGE_COLOUR = (0.25, 0.50, 0.95)            # the gauges' backings, for orientation only
GAUGE_LIFT_MM = 0.02                         # drawn this far off their face
X_AXIS = np.array([1.0, 0.0, 0.0])
PIECES = 12                                  # triangles are split to 1/PIECES of the picture's size
EDGE_BUFFER_PIXELS = 1400                    # depth-buffer resolution along the picture's longer side
EDGE_DEPTH_TOLERANCE = 3.0                   # an edge within this many pixels of the nearest depth is seen
SPAN_SLACK = 0.05                            # pixels added to each side of a scan-line span
HIDDEN_SHARE = 0.1                           # a triangle nearest at fewer of its pixels is hidden
MIN_EDGE_RUN = 3                             # visible runs of an edge shorter than this (pixels) are noise


def _camera(elev: float, azim: float):
    """Unit vectors: towards the eye, screen right, screen up."""
    e, a = np.radians(elev), np.radians(azim)
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    right = np.cross([0.0, 0.0, 1.0], eye)
    right /= np.linalg.norm(right)
    return eye, right, np.cross(eye, right)


def _split_long(tri: np.ndarray, normal: np.ndarray, max_edge: float) -> tuple[np.ndarray, np.ndarray]:
    """Halve triangles (m, 3, 3) across their longest edge until no edge exceeds ``max_edge``,
    so that a depth sort by centroid orders them correctly against small neighbours; each half
    keeps its parent's ``normal`` (m, 3)."""
    done, done_n = [], []
    for _ in range(24):
        lengths = np.linalg.norm(tri[:, [1, 2, 0]] - tri, axis=2)
        k = lengths.argmax(axis=1)
        idx = np.arange(len(tri))
        big = lengths[idx, k] > max_edge
        done.append(tri[~big])
        done_n.append(normal[~big])
        tri, normal, k = tri[big], normal[big], k[big]
        if not len(tri):
            break
        idx = np.arange(len(tri))
        a, b, c = tri[idx, k], tri[idx, (k + 1) % 3], tri[idx, (k + 2) % 3]
        m = (a + b) / 2
        tri = np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])
        normal = np.concatenate([normal, normal])
    done.append(tri)
    done_n.append(normal)
    return np.concatenate(done), np.concatenate(done_n)


def _smooth_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """One normal per triangle: the mean of its vertices' area-weighted normals. Slivers of the
    tessellation, whose own normals are round-off, take their neighbours'; facets of a cylinder
    shade a little smoother."""
    tri = vertices[triangles]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])   # twice the area, outward
    per_vertex = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(per_vertex, triangles[:, k], face)
    per_vertex /= np.maximum(np.linalg.norm(per_vertex, axis=1), 1e-300)[:, None]
    n = per_vertex[triangles].sum(axis=1)
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]


def _resample(line: np.ndarray, step: float) -> np.ndarray:
    """Points along a polyline no farther apart than ``step``."""
    out = [line[:1]]
    for a, b in zip(line[:-1], line[1:]):
        count = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
        t = np.linspace(0.0, 1.0, count + 1)[1:, None]
        out.append(a + t * (b - a))
    return np.concatenate(out)


def _zbuffer(xy: np.ndarray, depth: np.ndarray, lo: np.ndarray, pixel: float, shape: tuple,
             hidden: bool = False):
    """Nearest depth per pixel of projected triangles ``xy`` (m, 3, 2) with vertex depths (m, 3),
    by scan lines, all triangles at once. With ``hidden``, also which triangles cover pixels
    but are nearest at none of them."""
    zbuf = np.full(shape, -np.inf)
    p = (xy - lo) / pixel                                   # pixel units; pixel centres at i + 0.5
    x, y = p[..., 0], p[..., 1]
    # the depth plane of each triangle: z = a x + b y + c
    A = np.stack([x, y, np.ones_like(x)], axis=2)
    ok = np.abs(np.linalg.det(A)) > 1e-9
    index = np.flatnonzero(ok)
    depth_all = depth
    x, y, A, depth = x[ok], y[ok], A[ok], depth[ok]
    a, b, c = np.linalg.solve(A, depth[..., None])[..., 0].T
    # spans are widened by a hair so that triangles sharing an edge leave no pixel between them
    r0 = np.clip(np.ceil(y.min(axis=1) - 0.5 - SPAN_SLACK), 0, shape[0] - 1).astype(int)
    r1 = np.clip(np.floor(y.max(axis=1) - 0.5 + SPAN_SLACK), -1, shape[0] - 1).astype(int)
    count = np.maximum(r1 - r0 + 1, 0)
    tri = np.repeat(np.arange(len(x)), count)
    row = r0[tri] + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    yc = row + 0.5
    left = np.full(len(row), np.inf)
    right = np.full(len(row), -np.inf)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        y0, y1, x0, x1 = y[tri, i], y[tri, j], x[tri, i], x[tri, j]
        lo_y, hi_y = np.minimum(y0, y1) - SPAN_SLACK, np.maximum(y0, y1) + SPAN_SLACK
        crosses = (yc >= lo_y) & (yc <= hi_y) & (y0 != y1)
        t = np.clip(np.where(crosses, (yc - y0) / np.where(y0 != y1, y1 - y0, 1.0), 0.0), 0.0, 1.0)
        xc = x0 + t * (x1 - x0)
        left = np.where(crosses, np.minimum(left, xc), left)
        right = np.where(crosses, np.maximum(right, xc), right)
    c0 = np.clip(np.ceil(left - 0.5 - SPAN_SLACK), 0, shape[1] - 1)
    c1 = np.clip(np.floor(right - 0.5 + SPAN_SLACK), -1, shape[1] - 1)
    width = np.where(np.isfinite(left), np.maximum(c1 - c0 + 1, 0), 0).astype(int)
    span = np.repeat(np.arange(len(row)), width)
    col = c0[span].astype(int) + np.arange(width.sum()) - np.repeat(np.cumsum(width) - width, width)
    r, t = row[span], tri[span]
    z = a[t] * (col + 0.5) + b[t] * (r + 0.5) + c[t]
    np.maximum.at(zbuf, (r, col), z)
    # a pixel centre exactly on an edge shared by two triangles can fall between them by
    # round-off: fill such pin holes (empty, with covered neighbours on two opposite sides)
    pad = np.pad(zbuf, 1, constant_values=-np.inf)
    left, right, down, up = pad[1:-1, :-2], pad[1:-1, 2:], pad[:-2, 1:-1], pad[2:, 1:-1]
    hole = ~np.isfinite(zbuf) & ((np.isfinite(left) & np.isfinite(right)) | (np.isfinite(down) & np.isfinite(up)))
    zbuf[hole] = np.maximum.reduce([left, right, down, up])[hole]
    if not hidden:
        return zbuf
    won = z >= zbuf[r, col] - 1e-9 * (np.abs(z) + 1.0)
    covered = np.bincount(index[t], minlength=len(xy))
    owned = np.bincount(index[t[won]], minlength=len(xy))
    # nearest at almost none of its pixels: seen only through pin holes between other triangles
    behind = (covered > 0) & (owned < HIDDEN_SHARE * covered)
    # a sliver that covers no pixel centre is judged at its centroid
    centre = (xy - lo).mean(axis=1) / pixel
    ci = np.clip(np.floor(centre).astype(int), 0, np.array(shape)[::-1] - 1)
    behind |= (covered == 0) & (depth_all.mean(axis=1) + EDGE_DEPTH_TOLERANCE * pixel < zbuf[ci[:, 1], ci[:, 0]])
    return zbuf, behind


def _gauge_quads(beam: BeamCad) -> tuple[np.ndarray, np.ndarray]:
    """The gauges' backings as quads (k, 4, 3) in mm on their faces, and their outward normals."""
    normals = {"+z": (0, 0, 1), "-z": (0, 0, -1), "+y": (0, 1, 0), "-y": (0, -1, 0)}
    across = {"+z": (0, 1, 0), "-z": (0, 1, 0), "+y": (0, 0, 1), "-y": (0, 0, 1)}
    quads, out = [], []
    gl, gw = beam.gauge_length / MM / 2, beam.gauge_width / MM / 2
    for face in beam.faces:
        n, a = np.array(normals[face], float), np.array(across[face], float)
        half = (beam.height if face.endswith("z") else beam.width) / 2
        level = (half - (beam.pocket_depth if beam.feature == "pocket" else 0.0)) / MM + GAUGE_LIFT_MM
        for d in beam.stations:
            c = np.array([d / MM, 0.0, 0.0]) + level * n
            quads.append([c - gl * X_AXIS - gw * a, c + gl * X_AXIS - gw * a, c + gl * X_AXIS + gw * a,
                          c - gl * X_AXIS + gw * a])
            out.append(n)
    return np.array(quads, float).reshape(-1, 4, 3), np.array(out, float).reshape(-1, 3)


def _render(ax, mesh: dict, view: tuple, pieces: int, gauges=None) -> None:
    """Shaded triangles facing the camera, painted far to near, and the solid's visible edges
    (hidden ones removed against a depth buffer), in orthographic projection on a 2-D axes.
    ``gauges``: optional quads and normals drawn in the gauge colour."""
    from matplotlib.collections import LineCollection, PolyCollection

    eye, right, up = _camera(*view)
    to2d = np.column_stack([right, up])
    v = mesh["vertices"]
    tri = v[mesh["triangles"]]
    xy_all = v @ to2d
    lo, hi = xy_all.min(axis=0), xy_all.max(axis=0)
    span = float((hi - lo).max())

    n = _smooth_normals(v, mesh["triangles"])
    front = n @ eye > 0                         # faces turned away are hidden anyway
    # short triangles, so that sorting them by the depth of their centroids paints them right
    tri, n = _split_long(tri[front], n[front], span / pieces)
    # a depth buffer finds the triangles hidden behind others (dropped: painted out of order
    # they would show through) and which parts of the edges are seen
    pixel = span / EDGE_BUFFER_PIXELS
    shape = (int(math.ceil((hi[1] - lo[1]) / pixel)) + 2, int(math.ceil((hi[0] - lo[0]) / pixel)) + 2)
    zbuf, behind = _zbuffer(tri @ to2d, tri @ eye, lo, pixel, shape, hidden=True)
    tri, n = tri[~behind], n[~behind]
    segments = []
    for line in mesh["edges"]:
        if len(line) < 2:
            continue
        pts = _resample(line, pixel)
        mid = (pts[:-1] + pts[1:]) / 2
        ij = np.floor((mid @ to2d - lo) / pixel).astype(int)
        ij[:, 0] = np.clip(ij[:, 0], 0, shape[1] - 1)
        ij[:, 1] = np.clip(ij[:, 1], 0, shape[0] - 1)
        seen = mid @ eye + EDGE_DEPTH_TOLERANCE * pixel >= zbuf[ij[:, 1], ij[:, 0]]
        p2 = pts @ to2d
        # one polyline per run of visible segments
        flags = np.concatenate([[False], seen, [False]]).astype(int)
        starts = np.flatnonzero(np.diff(flags) == 1)
        stops = np.flatnonzero(np.diff(flags) == -1)
        segments += [p2[a:b + 1] for a, b in zip(starts, stops) if b - a >= MIN_EDGE_RUN]
    key = eye + 0.7 * up - 0.5 * right
    key /= np.linalg.norm(key)
    shade = AMBIENT + KEY * np.clip(n @ key, 0, 1) + HEAD * np.clip(n @ eye, 0, 1)
    colours = np.clip(BASE_COLOUR[None, :] * shade[:, None], 0, 1)
    order = np.argsort((tri @ eye).mean(axis=1), kind="stable")
    ax.add_collection(PolyCollection((tri @ to2d)[order], facecolors=colours[order],
                                     edgecolors=colours[order], linewidths=0.6))
    # gauges lie on their faces: painted where the depth buffer sees them, as an image
    if gauges is not None and len(gauges[0]):
        quads, quad_normals = gauges
        facing = quad_normals @ eye > 0
        quads, quad_normals = quads[facing], quad_normals[facing]
        if len(quads):
            halves = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
            gz = _zbuffer(halves @ to2d, halves @ eye, lo, pixel, shape)
            seen = np.isfinite(gz) & (gz + EDGE_DEPTH_TOLERANCE * pixel >= zbuf)
            light = AMBIENT + KEY * np.clip(quad_normals @ key, 0, 1).mean() + HEAD * (quad_normals @ eye).mean()
            image = np.zeros(shape + (4,))
            image[..., :3] = np.clip(np.array(GAUGE_COLOUR) * light, 0, 1)
            image[..., 3] = seen
            ax.imshow(image, origin="lower", interpolation="bilinear", zorder=2.5,
                      extent=(lo[0], lo[0] + shape[1] * pixel, lo[1], lo[1] + shape[0] * pixel))
    ax.add_collection(LineCollection(segments, colors=[EDGE_COLOUR], linewidths=0.6, capstyle="round", zorder=3))
    pad = 0.04 * span
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()


def _projected_aspect(mesh: dict, view: tuple) -> float:
    """Height over width of the picture of ``mesh`` seen from ``view``."""
    eye, right, up = _camera(*view)
    xy = mesh["vertices"] @ np.column_stack([right, up])
    span = np.ptp(xy, axis=0)
    return float(span[1] / span[0])


def plot_model(meshes: dict, beam: BeamCad, ax=None):
    """A shaded picture of the solid; with a close-up of the clamp block and gauge stations when
    ``meshes`` has one. ``meshes``: ``{"whole": mesh[, "detail": mesh]}`` from ``cad.model_meshes``."""
    from matplotlib.figure import Figure

    detail = meshes.get("detail")
    ax_detail = None
    if ax is None:
        width = 11.0
        h_whole = min(max(width * _projected_aspect(meshes["whole"], VIEW), 1.6), 6.0)
        h_detail = min(max(width * 0.8 * _projected_aspect(detail, DETAIL_VIEW), 2.0), 5.0) if detail else 0.0
        title, gap = 0.45, 0.35 if detail else 0.0
        height = title + h_whole + gap + h_detail
        fig = Figure(figsize=(width, height))
        ax = fig.add_axes((0.02, (h_detail + gap) / height, 0.96, h_whole / height))
        if detail is not None:
            ax_detail = fig.add_axes((0.1, 0.0, 0.8, h_detail / height))
    fig = ax.figure
    gauges = _gauge_quads(beam)
    _render(ax, meshes["whole"], VIEW, pieces=PIECES, gauges=gauges)
    title = (f"{beam.name}: {beam.material} {beam.section_label()}, free length {fmt_mm(beam.length)} mm, "
             f"stations {', '.join(fmt_mm(d) for d in beam.stations)} mm from the clamp face")
    fig.suptitle(title, fontsize=10, y=0.995, va="top")
    if ax_detail is not None:
        _render(ax_detail, detail, DETAIL_VIEW, pieces=PIECES, gauges=gauges)
        cut = float(detail["vertices"][:, 0].max())
        ax_detail.set_title(f"clamp block and gauge stations (cut at {cut:.4g} mm; gauges shown blue)", fontsize=9)
    return fig


# ----------------------------------------------------------------- files

def figure_bytes(fig, fmt: str, dpi: int = 150) -> bytes:
    """``fig`` as ``fmt`` (svg or png). SVG text is drawn as outlines, so that it looks the same
    in every viewer, and carries no date, so that the same design gives the same file."""
    import matplotlib

    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.fonttype": "path", "svg.hashsalt": "fpdesign"}):
        fig.savefig(buf, format=fmt, dpi=dpi, metadata={"Date": None} if fmt == "svg" else None,
                    facecolor="white")
    return buf.getvalue()


def save_figure(fig, path: str | os.PathLike, fmt: str, dpi: int = 150) -> Path:
    """Write ``fig`` as ``fmt`` (svg or png) so that no half-written file is left behind."""
    return atomic_write_bytes(path, figure_bytes(fig, fmt, dpi))
