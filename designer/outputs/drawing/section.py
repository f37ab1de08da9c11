"""The enlarged section through a station, hatched and dimensioned."""

from __future__ import annotations

import math

import numpy as np

from designer.outputs.drawing.pen import DIM_PT, INK, PT, THICK, Pen
from designer.outputs.drawing.views import centre_cross
from designer.outputs.part import MM, BeamCad, fmt_mm

SECTION_BOX = 58.0            # the enlarged section fits in this square, mm
SECTION_SCALES = (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10, 15, 20)


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
                q0, q3 = mid - u * w / 2, mid + u * w / 2
                q1, q2 = q0 + n * p, q3 + n * p
                r = beam.floor_radius   # the floor meets each side wall in the end mill's corner radius
                phi = np.linspace(0.0, np.pi / 2, 13)[:, None]
                pts.append(tuple(q0))
                pts += [tuple(q) for q in q1 - n * r + u * r + r * (-u * np.cos(phi) + n * np.sin(phi))]
                pts += [tuple(q) for q in q2 - u * r - n * r + r * (n * np.cos(phi) + u * np.sin(phi))]
                pts.append(tuple(q3))
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


def draw_section(pen: Pen, beam: BeamCad, cx: float, cy: float) -> tuple[float, float]:
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
    centre_cross(pen, cx, cy, b / 2 + 3, h / 2 + 3)
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
            # the floor radius, on the fillet's middle at the slot's +Y wall
            rf = beam.floor_radius / MM * k * (1 - math.sqrt(0.5))
            pen.leader((cx + w / 2 - rf, top - p + rf), (cx + w / 2 + 5.0, top + 2.5),
                       f"R{fmt_mm(beam.floor_radius)} TYP")
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
