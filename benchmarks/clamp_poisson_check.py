"""Does the clamp's effect on a wide bar depend on the material? The clamp fit (``ClampFit``,
docs/model.md §7) was fitted on the study's 6061-T6 bars (Poisson's ratio 0.33). A rigid clamp
stops the anticlastic curvature, which is nu times the bending curvature, so the strain it takes
from a station near it should grow with nu. Here the clamp's series (``checks.clamp_study``:
plain bars 3 mm high, 2 to 16 times as wide, the first station moved out from the clamp face)
is run in 3-D (``checks.study.run_case``) in four materials of the catalogue spanning its
Poisson's ratios, and the near station's strain over the far one's is compared with the fit's,
as fitted and with its loss scaled by ``(nu / CLAMP_POISSON)^p``: the shipped power
``corrections.CLAMP_POISSON_POWER`` and the power of least squares over the series. Only the
stations inside the fit's domain (a quarter width and more from the clamp face) are judged.
Run by hand (about 6 minutes on 2 cores, normal mesh):

    python benchmarks/clamp_poisson_check.py [--mesh normal] [-o benchmarks/clamp_poisson_check.md]
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from designer.checks import clamp_study, study
from designer.model import corrections
from designer.spec import catalogue

MATERIALS = ("17-4PH-H900", "301-full-hard", "6061-T6", "Ti-6Al-4V")   # nu 0.272, 0.29, 0.33, 0.342
WIDTH_RATIOS = (2.0, 4.0, 8.0, 16.0)
CLEARANCES = (0.2, 0.35, 0.5, 0.75, 1.0)   # from the clamp face to the gauge's end, in widths


def series() -> list[tuple[str, study.Case]]:
    h = clamp_study.HEIGHT
    return [(m, study.Case("rectangle-none", width=w * h, height=h,
                           clamp_clearance=max(c * w * h, clamp_study.MIN_CLEARANCE)))
            for m in MATERIALS for w in WIDTH_RATIOS for c in CLEARANCES]


def run(material: str, case: study.Case, mesh: str) -> float:
    """The near station's 3-D strain over the far station's (each over the plain beam model)."""
    row = study.run_case(replace(case, material=material), mesh)
    return row.strain_near / row.strain_far


def model(fit, w: float, u: float, nu: float, power: float) -> float:
    return 1 - (1 - fit(w, u)) * (nu / corrections.CLAMP_POISSON) ** power


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("-o", "--output", type=Path, help="also write the table and the summary as markdown")
    args = parser.parse_args(argv)
    fit = corrections.clamp_fit(corrections.load())
    power = corrections.CLAMP_POISSON_POWER
    lowest = fit.domain["station_width_ratio"][0]
    lines = ["| material | nu | b / h | station / b | 3-D near / far | fit | fit, nu-scaled |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    print("\n".join(lines))
    start, points = time.perf_counter(), []
    for material, case in series():
        nu = catalogue.material(material).poisson
        w, u = case.width / case.height, case.stations()[0] / case.width
        if u < lowest:
            continue
        ratio = run(material, case, args.mesh)
        points.append((material, nu, w, u, ratio))
        line = (f"| {material} | {nu:.3f} | {w:.0f} | {u:.3f} | {ratio:.4f} | {model(fit, w, u, nu, 0.0):.4f} | "
                f"{model(fit, w, u, nu, power):.4f} |")
        lines.append(line)
        print(line, flush=True)
    seconds = time.perf_counter() - start

    def misses(p):
        return np.array([model(fit, w, u, nu, p) - r for _, nu, w, u, r in points])

    grid = np.linspace(0.0, 3.0, 301)
    best = grid[int(np.argmin([np.sqrt(np.mean(misses(p) ** 2)) for p in grid]))]
    parts = []
    for label, p in (("as fitted", 0.0), (f"nu-scaled, power {power:g} (shipped)", power),
                     (f"nu-scaled, power {best:.2f} (least squares)", best)):
        e = misses(p)
        parts.append(f"{label}: the fit reads {e.min():+.2%} to {e.max():+.2%} of the 3-D ratio "
                     f"(RMS {np.sqrt(np.mean(e ** 2)):.2%})")
    summary = ("\n" + "; ".join(parts) + f". The clamp fit's largest left-out error on 6061-T6, which "
               f"the gauge-strain limit keeps as room: {fit.loo_max:.2%}. {len(points)} bars, {args.mesh} mesh, "
               f"{seconds:.0f} s.\n")
    print(summary)
    if args.output:
        head = ("The clamp's effect on a wide bar in four materials: `python benchmarks/clamp_poisson_check.py` "
                "(a positive reading is the fit's strain above the 3-D one, on the gauge-strain limit's safe "
                "side).\n\n")
        args.output.write_text(head + "\n".join(lines) + "\n" + summary, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
