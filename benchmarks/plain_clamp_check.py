"""Does the beam model hold for a plain rectangular bar's station near the clamp? Plain bars
(``rectangle-none``) from 0.15 to 8 times as wide as high, the first station moved out from the
clamp face, each checked in 3-D (``fpdesign verify``'s check, ``checks.study.model_ratios``): the
near station's 3-D/model gauge-strain ratio, the model with the shipped corrections (the clamp
fit's plate effect of a wide bar among them). The far station is four sizes further out.

The clamp fit was studied on bars 2-16 times as wide as high and 3 mm high, whose near stations
all sit more than a height from the clamp face; here the bars are 6-24 mm high, with the gauge's
3 mm grid, so that the station comes within a fraction of the height. Each row says whether the
design is inside the domain (docs/model.md §7): the first station at least
``domain.PLAIN_STATION_MIN`` times ``min(max(b, h), 3 h)`` and a quarter width
(``station_width_ratio``) from the clamp face. Printed: the table, the largest miss inside the
domain and the largest outside. Run by hand (about 6 minutes on 2 cores, normal mesh):

    python benchmarks/plain_clamp_check.py [--mesh normal] [-o benchmarks/plain_clamp_check.md]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from designer.checks import study
from designer.model import corrections, domain

MM = 1e-3
# (height, width ratios b/h, first stations' distances from the clamp face in heights)
TALL = (24 * MM, (0.15, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0), (0.2, 0.25, 0.3, 0.4, 0.5, 0.6, 0.75, 1.0, 1.5))
# around the bound, in its own measure d / min(max(b, h), 3 h), on bars half as high (the grid
# a quarter of the height) and wider ones
AROUND = ((12 * MM, (0.3, 1.0, 1.5, 2.0, 3.0, 4.0), (0.4, 0.5, 0.65, 0.75, 1.0)),
          (6 * MM, (8.0,), (0.4, 0.5, 0.65, 0.75, 1.0)))


def cases() -> list[study.Case]:
    """The series' bars, the near station's gauge centre at each distance."""
    out = []

    def add(h, w, d):
        clearance = d - study.GAUGE_LENGTH / 2       # to the gauge's end
        if clearance >= 0.5 * MM:
            out.append(study.Case("rectangle-none", width=w * h, height=h, clamp_clearance=clearance))

    h, widths, ratios = TALL
    for w in widths:
        for u in ratios:
            add(h, w, u * h)
    for h, widths, ratios in AROUND:
        for w in widths:
            scale = float(domain.plain_clamp_scale(w * h, h))
            for u in ratios:
                add(h, w, u * scale)
    return out


def inside(case: study.Case) -> bool:
    """Whether the case's first station is inside the domain (the plain-station bound and the clamp
    fit's quarter width)."""
    d = case.stations()[0]
    scale = float(domain.plain_clamp_scale(case.width, case.height))
    lowest = corrections.clamp_fit(corrections.load()).domain["station_width_ratio"][0]
    return d >= domain.PLAIN_STATION_MIN * scale - 1e-12 and d >= lowest * case.width - 1e-12


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("-o", "--output", type=Path, help="also write the table and the summary as markdown")
    args = parser.parse_args(argv)
    lines = ["| h (mm) | b / h | station (mm) | d / h | d / min(max(b, h), 3 h) | 3-D/model: near, far | "
             "in the domain |", "|---:|---:|---:|---:|---:|---|---|"]
    print("\n".join(lines))
    start = time.perf_counter()
    worst = {True: (0.0, ""), False: (0.0, "")}
    for case in cases():
        near, far = study.model_ratios(case, args.mesh)
        d, b, h = case.stations()[0], case.width, case.height
        scale = float(domain.plain_clamp_scale(b, h))
        ok = inside(case)
        line = (f"| {h / MM:.0f} | {b / h:.2f} | {d / MM:.2f} | {d / h:.3f} | {d / scale:.3f} | "
                f"{near:.4f}, {far:.4f} | {'yes' if ok else 'no'} |")
        lines.append(line)
        print(line, flush=True)
        if abs(near - 1) > worst[ok][0]:
            worst[ok] = (abs(near - 1), f"{near:.4f} ({h / MM:.0f} mm high, b/h {b / h:.2f}, d/h {d / h:.3f})")
    seconds = time.perf_counter() - start
    summary = (f"\nLargest miss of the near station inside the domain: {worst[True][0]:.2%}, {worst[True][1]}; "
               f"outside it: {worst[False][0]:.2%}, {worst[False][1]}. The clamp fit's largest left-out "
               f"error, which the gauge-strain limit keeps as room: "
               f"{corrections.clamp_fit(corrections.load()).loo_max:.2%}. {args.mesh} mesh, {seconds:.0f} s.\n")
    print(summary)
    if args.output:
        head = ("A plain rectangular bar's first station near the clamp: `python benchmarks/plain_clamp_check.py` "
                "(the near station's 3-D/model gauge-strain ratio with the shipped corrections; the far "
                "station is four sizes further out).\n\n")
        args.output.write_text(head + "\n".join(lines) + "\n" + summary, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
