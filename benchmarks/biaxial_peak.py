"""A biaxial sensor's feature peak against the load's direction, in 3-D (docs/model.md §9).

A biaxial design has pockets or flats on all four faces; the beam model's K_t are fitted on
single-axis designs, whose nominal stress is at the single-axis fibre (a flat's floor R - p, a
square's face h/2). This study measures, for round bars, a tube and squares with features of
several depths and widths, the features' peak under a load along an axis and at every direction
between (the mesh of ``verify``, refined at the floor radii of the top and the side features,
solved for F along -Z and along -Y and superposed every 2.5 degrees: ``readout.worst_direction``),
and sets it beside the model: ``K_t`` times the notch's nominal (an axis load) and
``DIRECTION_FACTOR`` times that (the worst direction). The factor is the largest ratio of the
worst direction's peak to the axis's measured here.

The designs are the three biaxial designs of tests/data (biaxial_*.json: 7075-T6, 20 N at 110 mm)
with their sizes changed. Run by hand:

    python benchmarks/biaxial_peak.py [--mesh normal] [--only R1 Q1 ...] [-o benchmarks/biaxial_peak.md]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"


def _chord(diameter: float, depth: float) -> float:
    """A flat's width at the surface, less 0.1 mm: as wide as the bar lets it be (mm)."""
    r = diameter / 2
    return round(2 * math.sqrt(r * r - (r - depth) ** 2) - 0.1, 2)


# name: (base design, changed sizes in mm)
DESIGNS = {
    "R1": ("biaxial_round_flats", {}),
    "R2": ("biaxial_round_flats", {"diameter": 16, "depth": 0.5, "width": _chord(16, 0.5)}),
    "R3": ("biaxial_round_flats", {"depth": 1.28, "width": _chord(9.18, 1.28)}),
    "R4": ("biaxial_round_flats", {"diameter": 12, "depth": 0.72, "width": _chord(12, 0.72)}),
    "T1": ("biaxial_tube_flats", {}),
    "Q1": ("biaxial_square_slots", {}),
    "Q2": ("biaxial_square_slots", {"width": 4.5}),
    "Q3": ("biaxial_square_slots", {"depth": 1.0}),
    "Q4": ("biaxial_square_slots", {"width": 4.5, "depth": 1.3}),
}


def design(name: str) -> dict:
    """The design.json record of a study design."""
    base, sizes = DESIGNS[name]
    record = json.loads((DATA / f"{base}.json").read_text(encoding="utf-8"))
    d = record["design"]
    for key, mm in sizes.items():
        (d["section"] if key in ("diameter", "wall") else d["feature"])[key] = mm / 1e3
    return record


def measure(record: dict, mesh: str) -> dict:
    """The 3-D features' peak along an axis and at the worst direction, and the model's."""
    from designer.checks.fea.compare import _problem, _run, _step
    from designer.checks.fea.geometry_mesh import MESH_LEVELS
    from designer.checks.fea.readout import worst_direction
    from designer.checks.fea.solve import solve

    _, model_design, ev, beam, pb = _problem(record, mesh)
    a, refinement = ev.analysis, MESH_LEVELS[mesh]
    start = time.perf_counter()
    with _step(record, beam) as step_path:
        figures, along_z = _run(step_path, pb, mesh, refinement)
    along_y = solve(along_z.mesh.p, along_z.mesh.t, replace(pb, lateral=True))
    worst, angle = worst_direction(along_z, along_y, pb, refinement)
    g = model_design.geometry
    return {"section": g.section, "size": g.size * 1e3, "depth": g.depth * 1e3, "width": g.pocket_width * 1e3,
            "nominal": float(a.stress_feature), "notch": float(a.stress_notch), "kt": float(a.stress_concentration),
            "axis_model": float(a.stress_peak_axis), "worst_model": float(a.stress_peak),
            "axis": figures.feature_peak, "worst": worst, "angle": angle,
            "elements": figures.run.elements, "seconds": time.perf_counter() - start}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("--only", nargs="+", choices=list(DESIGNS), default=list(DESIGNS))
    parser.add_argument("-o", "--output", type=Path, help="also write the table as markdown")
    args = parser.parse_args()
    head = ("| design | section, sizes (mm) | nominal / notch's (MPa) | K_t | 3-D axis (MPa) | model axis | "
            "3-D / model | 3-D worst (MPa), direction | worst / axis | model worst | 3-D / model | elements | s |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    print(head)
    ratios = []
    for name in args.only:
        r = measure(design(name), args.mesh)
        ratios.append((name, r["worst"] / r["axis"], r["worst"] / r["worst_model"]))
        slot = f"slot {r['width']:.2f} wide, " if r["section"] == "rectangle" else ""
        sizes = f"{r['section']} {r['size']:.2f}, {slot}{r['depth']:.2f} deep"
        row = (f"| {name} | {sizes} | {r['nominal'] / 1e6:.2f} / {r['notch'] / 1e6:.2f} | {r['kt']:.3f} | "
               f"{r['axis'] / 1e6:.2f} | {r['axis_model'] / 1e6:.2f} | {r['axis'] / r['axis_model']:.3f} | "
               f"{r['worst'] / 1e6:.2f}, {r['angle']:g}° | {r['worst'] / r['axis']:.3f} | "
               f"{r['worst_model'] / 1e6:.2f} | {r['worst'] / r['worst_model']:.3f} | {r['elements']:,} | "
               f"{r['seconds']:.0f} |")
        print(row, flush=True)
        lines.append(row)
    summary = ("largest worst/axis: " + ", ".join(f"{n} {w:.3f}" for n, w, _ in ratios)
               + f"; 3-D worst / model worst from {min(m for *_, m in ratios):.3f} to {max(m for *_, m in ratios):.3f}")
    print(summary)
    if args.output:
        args.output.write_text(f"Biaxial features' peak against the load direction (`python benchmarks/biaxial_peak.py "
                               f"--mesh {args.mesh}`).\n\n" + "\n".join(lines) + f"\n\n{summary}\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
