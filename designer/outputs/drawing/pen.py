"""Drawing on a sheet in paper millimetres: the sheet's conventions (lettering, line types,
arrowheads, dimension spacing) and ``Pen``, which draws lines, text and dimensions with them."""

from __future__ import annotations

import math

import numpy as np

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

INK = "black"
GAUGE_INK = "#1f5fbf"
THICK, THIN = 0.9, 0.4        # line widths, pt (ISO 128 wide and narrow lines on a screen)
HIDDEN = (0, (4.0, 2.0))      # dash patterns, in line widths
CHAIN = (0, (12.0, 3.0, 2.0, 3.0))
PHANTOM = (0, (10.0, 2.5, 2.0, 2.5, 2.0, 2.5))


class Pen:
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
