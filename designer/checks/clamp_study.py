"""The clamp's effect on a station near it: the 3-D study series and its fit (docs/model.md §7).

A rigid clamp stops the anticlastic bending of a wide bar: near it the bar bends in plane strain
and the gauge strain falls below the beam model's, by up to about ``nu^2`` on a wide plate, over a
length of about the bar's width. The series runs ``fpdesign verify``'s 3-D check (``checks.study.clamp_cases``) on plain bars of
width/height 2 to 16 with the first station moved out from the clamp (``checks.study.Case``
``rectangle-none``; its far station is the reference), and ``fit`` fits
``model.corrections.ClampFit`` to the ratio of the two stations' 3-D/model strains.
"""

from __future__ import annotations

import math

HEIGHT = 3e-3
WIDTH_RATIOS = (2.0, 4.0, 8.0, 16.0)
CLEARANCES = (0.03, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5)   # from the clamp face, in widths
MIN_CLEARANCE = 0.5e-3
# The fit's domain: the station at least this many widths from the clamp face. Closer, the
# clamp face's own corner raises the strain again (a 16:1 plate: 0.93 at 0.27 widths, 1.00 at 0.10).
MIN_STATION_WIDTH_RATIO = 0.25
MAX_WIDTH_RATIO = 16.0
START = (0.07, 2.7, 3.0, 0.32)   # a, w0, k, u0


def series() -> list[dict]:
    """The series' bars (``checks.study.Case`` fields): the near station's gauge from
    ``CLEARANCES`` widths out."""
    return [{"width": w * HEIGHT, "height": HEIGHT, "clamp_clearance": max(c * w * HEIGHT, MIN_CLEARANCE)}
            for w in WIDTH_RATIOS for c in CLEARANCES]


def near_station(row: dict) -> float:
    """A study row's near station (its gauge grid's centre) from the clamp face, in section sizes:
    half the feature beyond the clamp-side end the row records."""
    return row["clamp_ratio"] + row["length_ratio"] / 2


def points(rows: list[dict]) -> list[tuple]:
    """``(width_ratio, station_width_ratio, near/far strain ratio)`` of the study's plain-bar rows
    (``checks.study.read_csv``): the station is the gauge's centre, half the feature length beyond
    the clamp-side end the study records."""
    out = []
    for r in rows:
        if r["family"] != "rectangle-none":
            continue
        w = r["width_ratio"]
        u = near_station(r) / w
        out.append((w, u, r["strain_near"] / r["strain_far"]))
    return out


def fit(rows: list[dict]):
    """The ClampFit of the series by least squares over its domain, with its RMS residual and the
    largest residual at a point left out of the fit."""
    import numpy as np
    from scipy.optimize import least_squares

    from designer.model.corrections import ClampFit

    data = np.array([p for p in points(rows) if p[1] >= MIN_STATION_WIDTH_RATIO and p[0] <= MAX_WIDTH_RATIO])
    # no lower bound on b/h: a ratio of sizes is positive, and an idle bound at 0 only hampers IPOPT
    domain = {"station_width_ratio": (MIN_STATION_WIDTH_RATIO, math.inf), "width_ratio": (-math.inf, MAX_WIDTH_RATIO)}

    def solve(d, start):
        def residual(c):
            return ClampFit(*c, domain)(d[:, 0], d[:, 1]) - d[:, 2]
        return least_squares(residual, start, bounds=([0, 0.1, 0.1, 0], [1, 100, 20, 2])).x

    coefficients = solve(data, START)
    resid = ClampFit(*coefficients, domain)(data[:, 0], data[:, 1]) - data[:, 2]
    loo = []
    for j in range(len(data)):
        rest = np.delete(data, j, axis=0)
        c = solve(rest, coefficients)
        loo.append(float(ClampFit(*c, domain)(data[j:j + 1, 0], data[j:j + 1, 1])[0] - data[j, 2]))
    return ClampFit(*(float(c) for c in coefficients), domain, float(np.sqrt(np.mean(resid ** 2))),
                    float(np.max(np.abs(loo))))
