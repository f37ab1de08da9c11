"""The plain bar's free-end deflection beyond Euler-Bernoulli theory: the 3-D series and its fit
(docs/model.md §7, ``model.corrections.StiffnessFit``).

Two effects move a plain bar's deflection off Euler-Bernoulli theory, and the study's feature
beams (about ten sections long, up to 11 times as wide as high) do not separate them:

- a rigid clamp stops a wide bar's anticlastic curvature, so near it the bar bends in plane strain
  and is stiffer, by up to about ``nu^2`` of its curvature, over about one width (a 16:1 plate
  five heights long deflects 0.92 of the beam model);
- a stubby bar shears: Timoshenko's ``F x / (kappa G A)``, of which the clamp face, held flat,
  stops a part (a round bar two diameters long deflects 1.08 of the beam model, a thin tube 1.36).

The series runs ``fpdesign verify``'s 3-D check on plain 6061-T6 bars, rectangles of width/height
0.5 to 16, round bars and tubes of wall/diameter 0.05 to 0.35, loaded 2 to 60 section sizes from
the clamp at their free end, and ``fit`` fits the StiffnessFit to the ratio of the 3-D deflection
to Euler-Bernoulli's. Run by hand:

    python -m designer.checks.stiffness_study -o materials/stiffness_study.csv [--mesh normal]
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

TABLE = "stiffness_study.csv"   # beside the study table in materials/
MATERIAL = "6061-T6"
POISSON = 0.33            # 6061-T6's, materials/materials.yaml
GAUGE_HALF_LENGTH = 3.45e-3   # BF350-3AA's backing, half of it
# (width/height, slenderness, height in mm): the clamp's plate effect over the width and the
# length, and stubby bars for the shear
RECTANGLES = tuple((w, s, 4.0) for w in (1, 2, 4, 8, 16) for s in (5, 8, 14)) + (
    (16, 30, 4.0), (16, 60, 4.0), (8, 30, 4.0), (4, 30, 4.0), (1, 25, 4.0), (3, 10, 4.0), (6, 10, 4.0),
    (11, 10, 4.0), (0.5, 2, 10.0), (0.5, 3, 10.0), (0.5, 5, 10.0), (1, 2, 10.0), (2, 2.5, 10.0))
ROUND_DIAMETER = 10.0     # mm
ROUND_SLENDERNESS = (2, 3, 5, 8, 14)
TUBE_WALLS = (0.05, 0.1, 0.2, 0.35)
TUBE_SLENDERNESS = (2, 3.5, 6, 12)
START = (0.1, 2.6, 0.27, 0.55, 0.4)    # plate, w0, reach, shear, shear_bore


@dataclass(frozen=True)
class Bar:
    """One plain bar of the series, loaded at its free end ``slenderness`` sizes from the clamp."""

    section: str
    size: float             # h or D, m
    slenderness: float
    width_ratio: float = 1.0
    wall_ratio: float = 0.0

    @property
    def length(self) -> float:
        return self.slenderness * self.size

    def stations(self) -> tuple[float, float]:
        """A gauge near the clamp and one half way (they do not enter the deflection)."""
        near = max(GAUGE_HALF_LENGTH + 0.5e-3, 0.3 * self.size)
        return near, max(self.length / 2, near + 2 * GAUGE_HALF_LENGTH + 0.1e-3)

    def spec_text(self) -> str:
        mm = lambda v: f"{v * 1e3:.6g} mm"  # noqa: E731 - a local formatter
        section = {"rectangle": f"{{kind: rectangle, width: {mm(self.width_ratio * self.size)}, "
                                f"height: {mm(self.size)}}}",
                   "round": f"{{kind: round, diameter: {mm(self.size)}}}",
                   "tube": f"{{kind: tube, diameter: {mm(self.size)}, wall: {mm(self.wall_ratio * self.size)}}}"}
        near, far = self.stations()
        x = self.length
        return (f"name: stiffness-{self.section}\n"
                f"load: {{force: [1 N, 10 N], position: [{mm(x - 1e-3)}, {mm(x)}]}}\n"
                "electronics: {excitation: 5 V, gain: 128, noise_rti: 50 nV}\n"
                "gauge: BF350-3AA\nbridge: half\n"
                f"limits: {{load_clearance: 0 mm, clamp_clearance: {mm(near - GAUGE_HALF_LENGTH)}}}\n"
                f"design:\n  material: {MATERIAL}\n  section: {section[self.section]}\n"
                f"  stations: [{mm(near)}, {mm(far)}]\n  feature: {{kind: none}}\n")


def series() -> list[Bar]:
    mm = 1e-3
    out = [Bar("rectangle", h * mm, s, width_ratio=w) for w, s, h in RECTANGLES]
    out += [Bar("round", ROUND_DIAMETER * mm, s) for s in ROUND_SLENDERNESS]
    out += [Bar("tube", ROUND_DIAMETER * mm, s, wall_ratio=t) for t in TUBE_WALLS for s in TUBE_SLENDERNESS]
    return out


FIELDS = ("section", "width_ratio", "wall_ratio", "slenderness", "poisson", "deflection_ratio", "mesh_change",
          "seconds")


def run(bar: Bar, mesh: str = "normal") -> dict:
    """The 3-D check of one bar: its free-end deflection over Euler-Bernoulli's."""
    from designer import model
    from designer.checks.fea import verify_design
    from designer.model import corrections
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(bar.spec_text(), source=f"stiffness-{bar.section}")
    result = evaluate_fixed(spec)
    t0 = time.perf_counter()
    v = verify_design(result.record, mesh=mesh)
    design = result.evaluation.design
    raw = model.analyse(design.geometry, design.material_params(spec), spec, table=corrections.Corrections({}))
    return {"section": bar.section, "width_ratio": bar.width_ratio, "wall_ratio": bar.wall_ratio,
            "slenderness": bar.slenderness, "poisson": float(design.material.poisson),
            "deflection_ratio": v.deflection_fea / float(raw.deflection),
            "mesh_change": max(gc.mesh_change for gc in v.gauges), "seconds": time.perf_counter() - t0}


def write_csv(rows: list[dict], path: Path) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(FIELDS)
        for r in rows:
            w.writerow([f"{r[k]:.6g}" if isinstance(r[k], float) else r[k] for k in FIELDS])


def read_csv(path: Path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as fh:
        return [{k: (v if k == "section" else float(v)) for k, v in row.items()} for row in csv.DictReader(fh)]


def predicted_ratio(fit, row: dict) -> float:
    """The fit's deflection over Euler-Bernoulli's for a row's bar (unit size, force and E)."""
    from designer.model.sections import Geometry, section_properties

    s = row["slenderness"]
    g = Geometry(section=row["section"], feature="none", stations=(), length=s, width=row["width_ratio"],
                 height=1.0, diameter=1.0, wall=row["wall_ratio"])
    sp = section_properties(g)
    euler = s ** 3 / (3 * sp.I)
    return 1 + float(fit.extra_deflection(g, sp, 1.0, row["poisson"], 1.0, s)) / euler


def fit(rows: list[dict]):
    """The StiffnessFit of the series by least squares, with its RMS residual and the largest
    residual at a point left out of the fit; its domain is the series' (width/height up to its
    widest, free length over size from its stubbiest)."""
    import numpy as np
    from scipy.optimize import least_squares

    from designer.model.corrections import StiffnessFit

    rects = [r["width_ratio"] for r in rows if r["section"] == "rectangle"]
    domain = {"width_ratio": (-math.inf, max(rects)), "slenderness": (min(r["slenderness"] for r in rows), math.inf)}

    def solve(data, start):
        def residual(c):
            f = StiffnessFit(*c, domain)
            return [predicted_ratio(f, r) - r["deflection_ratio"] for r in data]
        return least_squares(residual, start, bounds=([0, 0.3, 0.01, 0, -1], [0.3, 20, 5, 2, 2])).x

    coefficients = solve(rows, START)
    best = StiffnessFit(*coefficients, domain)
    resid = np.array([predicted_ratio(best, r) - r["deflection_ratio"] for r in rows])
    loo = []
    for j in range(len(rows)):
        c = solve(rows[:j] + rows[j + 1:], coefficients)
        loo.append(predicted_ratio(StiffnessFit(*c, domain), rows[j]) - rows[j]["deflection_ratio"])
    return StiffnessFit(*(float(c) for c in coefficients), domain, float(np.sqrt(np.mean(resid ** 2))),
                        float(np.max(np.abs(loo))))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description="Run the plain bars' 3-D deflection series, or fit it.")
    p.add_argument("-o", "--output", type=Path, help="CSV to write")
    p.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    p.add_argument("--fit", type=Path, metavar="CSV", help="fit this table and print the fit")
    args = p.parse_args(argv)
    if args.fit is not None:
        f = fit(read_csv(args.fit))
        print(f"{f}\nrms {f.rms:.4f}, leave-one-out max {f.loo_max:.4f}")
        return 0
    if args.output is None:
        p.error("-o/--output is required to run the series")
    from designer.errors import FpdError

    rows = []
    for bar in series():
        try:
            row = run(bar, args.mesh)
        except FpdError as exc:
            print(f"{bar}: left out: {exc}", flush=True)
            continue
        rows.append(row)
        print(f"{bar.section} w {bar.width_ratio:g} t {bar.wall_ratio:g} s {bar.slenderness:g}: "
              f"deflection {row['deflection_ratio']:.4f} ({row['seconds']:.1f} s)", flush=True)
        write_csv(rows, args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
