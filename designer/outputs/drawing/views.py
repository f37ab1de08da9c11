"""The two orthographic views of the sheet: the length axis along the beam, with long plain
runs shortened by break lines, and one view (side or top) of every edge of the part."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from designer.outputs.drawing.pen import GAUGE_INK, INK, Pen
from designer.outputs.part import MM, BeamCad

BREAK_PAPER = 18.0            # paper length of a shortened plain run, mm
BREAK_SHARE = 0.25            # a plain run is shortened when longer than this share of the rest ...
BREAK_MIN_SIZES = 6.0         # ... and longer than this many section sizes
BREAK_HALF_GAP = 1.6          # half the gap between the two break lines, mm
VIEW_LEFT = 24.0              # left end of the main views, mm
VIEW_WIDTH = 268.0            # paper length available to the main views, mm
MAX_VIEW_DEPTH = 60.0         # the length scale is reduced so that no view is deeper (mm)
MAX_LENGTH_SCALE = 4.0        # paper mm per model mm along the beam, at most


# ----------------------------------------------------------------- the length axis

@dataclass(frozen=True)
class LengthAxis:
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


def length_axis(beam: BeamCad) -> LengthAxis:
    """Shorten the longest plain runs while each one is a large share of what is left
    (breaking it enlarges the drawing by a third or more) and long against the section."""
    c = beam.clamp
    size = max(beam.width, beam.height, c.width)
    spans = [(-c.length, 0.0)]
    spans += list(beam.geometry.reduced_spans)
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
    return LengthAxis(tuple(knots_m), tuple(knots_p), tuple(gaps), scale)


# ----------------------------------------------------------------- one orthographic view

@dataclass(frozen=True)
class ViewSetup:
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


def draw_view(pen: Pen, beam: BeamCad, X: LengthAxis, v: ViewSetup) -> None:
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
    if not beam.block_is_bar:
        vline(0.0, -hb, hb)
    # silhouette of the free length, notched by grooves and by flats seen edge-on (a flat's
    # floor runs into its end walls in the end mill's corner radius)
    for s, face in ((+1, f"+{v.axis}"), (-1, f"-{v.axis}")):
        notches = []
        if beam.grooves is not None:
            notches += [(x - beam.grooves.width / 2, x + beam.grooves.width / 2, beam.grooves.depth, 0.0)
                        for x in beam.grooves.positions]
        if flats and face in edge_cut:
            notches += [(d - lp / 2, d + lp / 2, p, beam.floor_radius) for d in beam.stations]
        cur = 0.0
        for a, b, depth, r in sorted(notches):
            hline(cur, a, s * half)
            xs, ts = floor_profile(a, b, half, half - depth, r, s)
            pen.line([X(x) for x in xs], [Y(t) for t in ts])
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
                xs, ts = floor_profile(d - lp / 2, d + lp / 2, half, half - p, beam.floor_radius, s)
                pen.line([X(x) for x in xs], [Y(t) for t in ts], "hidden")
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
                centre_cross(pen, X(d), Y(0), r / MM * X.scale + 1.5, r / MM * v.scale + 1.5)
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
            centre_cross(pen, X(xb), Y(0), rb / MM * X.scale + 1.5, rb / MM * v.scale + 1.5)
    # wire channels
    if beam.channels is not None:
        cw, cd = beam.channels.width, beam.channels.depth
        runs = channel_runs(beam)
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


def floor_profile(a: float, b: float, surface: float, floor: float, r: float, sign: int = 1, steps: int = 12):
    """A pocket's outline seen edge-on (model m): down the wall at ``a`` from ``surface`` to
    ``floor``, along the floor, up the wall at ``b``; the floor meets each wall in radius ``r``.
    Heights are distances from the axis, turned to the face's side by ``sign``."""
    xs, ts = [a], [surface]
    if r > 0:
        q = np.linspace(0.0, np.pi / 2, steps)
        xs += list(a + r - r * np.cos(q)) + list(b - r + r * np.sin(q))
        ts += list(floor + r - r * np.sin(q)) + list(floor + r - r * np.cos(q))
    else:
        xs += [a, b]
        ts += [floor, floor]
    xs.append(b)
    ts.append(surface)
    return xs, [sign * t for t in ts]


def channel_runs(beam: BeamCad) -> list[tuple[float, float]]:
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


def centre_cross(pen, cx, cy, hx, hy):
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
