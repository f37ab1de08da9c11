"""Benchmark: where the beam model stops being true, by section family and strain feature.

Runs the 3-D check (``designer.checks.fea.verify_design``) on one design per section family
(rectangle, round, tube) and feature kind (pocket or flat, hole, none), among them the
paper's Prototypes A, B and C (Noh et al. 2025, Table 1), and prints a Markdown table of the
FEA / beam-model ratios of the gauge strains, the free-end deflection and the peak stress,
with the mesh used, its convergence and the time each run took.

    python benchmarks/fea_table.py [--mesh normal] [--out benchmarks/fea_table.md] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from designer.checks import fea  # noqa: E402
from designer.result.evaluation import evaluate, fixed_design  # noqa: E402
from designer.outputs.files import atomic_write_text  # noqa: E402
from designer.result.record import build_record  # noqa: E402
from designer.spec.reader import parse_spec  # noqa: E402

ELECTRONICS = {"excitation": "5 V", "gain": 1000, "noise": "1.3 mV"}
# Loads of the paper's Table 2 for the prototypes; the other designs carry 20 N at 300 mm.
CASES = {
    "A: rectangle, none (paper)": {
        "load": {"force": ["250 gf", "2000 gf"], "position": ["150 mm", "650 mm"]}, "bridge": "full",
        "design": {"material": "6061-T6", "section": {"kind": "rectangle", "width": "50 mm", "height": "3.18 mm"},
                   "stations": ["20 mm", "120 mm"], "feature": {"kind": "none"}, "length": "800 mm"}},
    "B: rectangle, hole Ø9.5 (paper)": {
        "load": {"force": ["200 gf", "2000 gf"], "position": ["150 mm", "450 mm"]},
        "design": {"material": "2024-T3", "section": {"kind": "rectangle", "width": "12.7 mm", "height": "12.7 mm"},
                   "stations": ["20 mm", "60 mm", "100 mm"], "feature": {"kind": "hole", "diameter": "9.5 mm"},
                   "length": "450 mm"}},
    "C: tube, none, biaxial (paper)": {
        "load": {"force": ["250 gf", "2000 gf"], "position": ["100 mm", "200 mm"]}, "axes": 2,
        "limits": {"load_clearance": "0 mm", "tip_margin": "0 mm"},
        "design": {"material": "6061-T6", "section": {"kind": "tube", "diameter": "12.7 mm", "wall": "1.65 mm"},
                   "stations": ["20 mm", "70 mm"], "feature": {"kind": "none"}, "length": "200 mm"}},
    "rectangle, hole Ø6": {
        "design": {"material": "2024-T3", "section": {"kind": "rectangle", "width": "12.7 mm", "height": "12.7 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "hole", "diameter": "6 mm"}}},
    "rectangle, slot pockets": {
        "design": {"material": "2024-T3", "section": {"kind": "rectangle", "width": "12 mm", "height": "8 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "pocket", "depth": "1.5 mm"}}},
    "rectangle, none": {
        "design": {"material": "2024-T3", "section": {"kind": "rectangle", "width": "12 mm", "height": "8 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "none"}}},
    "round, flats": {
        "design": {"material": "2024-T3", "section": {"kind": "round", "diameter": "10 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "pocket", "depth": "1 mm"}}},
    "round, none": {
        "design": {"material": "2024-T3", "section": {"kind": "round", "diameter": "10 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "none"}}},
    "tube, flats": {
        "design": {"material": "2024-T3", "section": {"kind": "tube", "diameter": "16 mm", "wall": "3 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "pocket", "depth": "1 mm"}}},
    "tube, none": {
        "design": {"material": "2024-T3", "section": {"kind": "tube", "diameter": "16 mm", "wall": "3 mm"},
                   "stations": ["20 mm", "60 mm"], "feature": {"kind": "none"}}},
}


def record_for(name: str) -> dict:
    raw = {"name": name, "load": {"force": ["2 N", "20 N"], "position": ["100 mm", "300 mm"]},
           "electronics": ELECTRONICS, "bridge": "half", "limits": {"fatigue": False}}
    raw.update(json.loads(json.dumps(CASES[name])))
    spec = parse_spec(raw)
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    return json.loads(json.dumps(build_record("feasible" if ev.feasible else "infeasible", spec, ev)))


def run(names, mesh: str) -> list[dict]:
    rows = []
    for name in names:
        record = record_for(name)
        start = time.perf_counter()
        r = fea.verify_design(record, mesh=mesh)
        seconds = time.perf_counter() - start
        main_run = r.runs[0]
        rows.append({"name": name, "ratios": r.ratios, "stations": [g.station for g in r.gauges],
                     "deflection": r.deflection_fea / r.deflection_model,
                     "stress": r.stress_peak.value / r.stress_model_at_peak, "where": r.stress_peak.where,
                     "change": max(g.mesh_change for g in r.gauges), "stress_change": r.stress_change,
                     "elements": main_run.elements, "dofs": main_run.dofs, "size": main_run.global_size,
                     "detail": main_run.detail_size, "seconds": seconds})
        print(f"{name}: {', '.join(f'{q:.3f}' for q in r.ratios)} in {seconds:.1f} s", file=sys.stderr)
    return rows


def table(rows: list[dict], mesh: str) -> str:
    lines = [f"3-D FEA / beam model under F_max at x_max (`fpdesign verify --mesh {mesh}`; quarter model, "
             "quadratic tetrahedra; strain = mean over the gauge grid, 3.0 x 2.2 mm).", "",
             "| design | gauge strain FEA/model (by station) | deflection FEA/model | peak stress FEA/model (where) "
             "| mesh: elements, unknowns, size/detail (mm) | strain change on a 1.5x coarser mesh | time (s) |",
             "|---|---|---:|---|---|---:|---:|"]
    for r in rows:
        gauges = ", ".join(f"{q:.3f} ({d * 1e3:.0f} mm)" for q, d in zip(r["ratios"], r["stations"]))
        lines.append(f"| {r['name']} | {gauges} | {r['deflection']:.3f} | {r['stress']:.2f} ({r['where']}) | "
                     f"{r['elements']}, {r['dofs']}, {r['size'] * 1e3:.2f}/{r['detail'] * 1e3:.2f} | "
                     f"{r['change']:.2%} | {r['seconds']:.1f} |")
    lines += ["", f"Machine: {platform.machine()}, {platform.python_version()}; times include building the "
              "CAD solid, meshing and solving both meshes.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="normal", choices=tuple(fea.MESH_LEVELS))
    parser.add_argument("--out", default=None,
                        help="Markdown file to write [benchmarks/fea_table.md for the whole table; none with --only, "
                             "which would leave it with only those rows]")
    parser.add_argument("--only", nargs="*", default=None, help="run only these cases (names as in the table)")
    args = parser.parse_args(argv)
    names = args.only or list(CASES)
    text = table(run(names, args.mesh), args.mesh)
    print(text)
    out = args.out or (None if args.only else str(ROOT / "benchmarks" / "fea_table.md"))
    if out:
        atomic_write_text(out, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
