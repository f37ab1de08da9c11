"""A biaxial sensor's gauge strain against the beam model's, in 3-D, beside its single-axis twin's.

The gauge-strain corrections of the beam model (``corrections.strain_factors``, docs/model.md §7)
are fitted on single-axis designs (``axes: 1``: a pocket or flat on +-Z only) and applied to
biaxial ones (``axes: 2``: a feature on all four faces, docs/model.md §9) unchanged. This study
measures how far that carries: for each design it meshes and solves the solid as ``verify`` does
on one mesh level (``compare._problem`` and ``compare._run``: no convergence mesh, no verdict),
for F along -Z, and reads each station's 3-D gauge strain (the Z bridge's grid on the top
feature's floor, ``readout.gauge_strains``) against the model's (``analysis.gauge_strain``, the
corrections included). Each design is run twice: as it is (biaxial) and as its single-axis twin
(the same record with ``axes: 1`` in the spec and the design block, so the side features are
gone); the biaxial/twin ratio of 3-D/model is what the biaxial features do that the fits do not
know.

The designs are the nine of ``benchmarks/biaxial_peak.py`` (R1-R4 round bars with flats, T1 a
tube with flats, Q1-Q4 squares with slots; 7075-T6, 20 N at 110 mm) and three larger round bars
with deep flats and three stations (X1-X3), near a Ø18.3 mm Ti-6Al-4V bar whose ``verify`` had
read 0.982-0.986 of the model. ``--lateral R1 Q1`` also solves those biaxial designs for F along
-Y on the same mesh and reads the Y bridge's grid on the side feature's floor (the solution read
with Y and Z swapped), which by the sections' 4-fold symmetry should give the Z bridge's ratio.

Every run is kept in a JSON cache (``--cache``), so an interrupted study resumes and
``--table`` rewrites the markdown from the cache alone. The cache shipped (biaxial_strain.json)
was measured on the model before the side features' factor that this study set
(``model.biaxial.biaxial_strain_factor``, docs/model.md §9): runs made now measure what is left
after it. Run by hand (one FEA job at a time):

    python benchmarks/biaxial_strain.py [--mesh normal] [--only R1 Q1 ...] [--no-twins]
        [--lateral R1 Q1] [--cache biaxial_strain.json] [-o benchmarks/biaxial_strain.md]
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from biaxial_peak import DESIGNS as PEAK_DESIGNS
from biaxial_peak import _chord
from biaxial_peak import design as peak_design

# The larger round bars with deep flats (10-12 % of the diameter), three stations, the features
# 10 mm long and 4 mm apart; the load's nearest position moved to 50 mm to clear the third
# (X1-X3). The feature's length over the size is the other parameter the side features' effect
# might follow: X1 again with its flats 0.41 diameters long (L1, the shortest the 6.9 mm gauge
# backing leaves room for is 7.3 mm) and about one diameter long (L2, its stations and the load's
# nearest position spread out to fit), and Q3 with its slots 1.65 heights long (L3).
THREE = {"stations": [0.0100, 0.0240, 0.0380], "length": 10.0, "position": [0.05, 0.11]}
EXTRA = {
    "X1": ("R1", {"diameter": 18.3, "depth": 2.05, "width": _chord(18.3, 2.05), **THREE}),
    "X2": ("R1", {"diameter": 16.0, "depth": 1.76, "width": _chord(16.0, 1.76), **THREE}),
    "X3": ("R1", {"diameter": 20.0, "depth": 2.40, "width": _chord(20.0, 2.40), **THREE}),
    "L1": ("R1", {"diameter": 18.3, "depth": 2.05, "width": _chord(18.3, 2.05), **THREE, "length": 7.5}),
    "L2": ("R1", {"diameter": 18.3, "depth": 2.05, "width": _chord(18.3, 2.05), "length": 18.0,
                  "stations": [0.0140, 0.0360, 0.0580], "position": [0.075, 0.11]}),
    "L3": ("Q3", {"length": 14.0, "stations": [0.0120, 0.0320], "position": [0.045, 0.11]}),
}
NAMES = list(PEAK_DESIGNS) + list(EXTRA)
FAMILY = {"R": "round flats", "X": "round flats", "T": "tube flats", "Q": "square slots"}
FAMILY.update({n: FAMILY[b[0]] for n, (b, _) in EXTRA.items()})


def design(name: str, axes: int = 2) -> dict:
    """The design.json record of a study design, biaxial (``axes`` 2) or its single-axis twin (1)."""
    if name in PEAK_DESIGNS:
        record = peak_design(name)
    else:
        base, sizes = EXTRA[name]
        record = peak_design(base)
        d = record["design"]
        for key, mm in sizes.items():
            if key in ("diameter", "wall"):
                d["section"][key] = mm / 1e3
            elif key in ("depth", "width", "length"):
                d["feature"][key] = mm / 1e3
        if "stations" in sizes:
            d["stations"] = list(sizes["stations"])
            record["spec"]["stations"] = len(sizes["stations"])
        if "position" in sizes:
            record["spec"]["load"]["position"] = list(sizes["position"])
    record = copy.deepcopy(record)
    record["spec"]["axes"] = axes
    record["design"]["axes"] = axes
    return record


def _swapped(sol):
    """``sol`` read with Y and Z swapped: the side (+Y) face becomes the top one (the mesh's
    dofs depend on its tetrahedra alone, so the displacements keep their order)."""
    from skfem import MeshTet

    from designer.checks.fea.solve import solution

    return solution(MeshTet(sol.mesh.p[[0, 2, 1]], sol.mesh.t), sol.u[[0, 2, 1]], sol.iterations)


def measure(record: dict, mesh: str, lateral: bool = False) -> dict:
    """The model's and the 3-D gauge strain at each station (F along -Z), and with ``lateral``
    the Y bridge's 3-D strain under F along -Y on the same mesh."""
    from designer.checks.fea.compare import _problem, _run, _step
    from designer.checks.fea.geometry_mesh import MESH_LEVELS
    from designer.checks.fea.readout import gauge_strains
    from designer.checks.fea.solve import solve
    from designer.model import corrections

    _, model_design, ev, beam, pb = _problem(record, mesh)
    a, g = ev.analysis, model_design.geometry
    start = time.perf_counter()
    with _step(record, beam) as step_path:
        figures, sol = _run(step_path, pb, mesh, MESH_LEVELS[mesh])
    out = {"section": g.section, "size": g.size * 1e3, "depth": g.depth * 1e3, "width": g.pocket_width * 1e3,
           "wall": (g.wall or 0.0) * 1e3, "length": g.feature_length * 1e3, "axes": g.axes,
           "stations": [s * 1e3 for s in g.stations],
           "model": [float(e) for e in a.gauge_strain], "fea": [float(e) for e in figures.gauges],
           "factors": [float(c) for c in corrections.strain_factors(g, corrections.load())],
           "elements": figures.run.elements, "seconds": figures.run.seconds}
    if lateral:
        t0 = time.perf_counter()
        side = solve(sol.mesh.p, sol.mesh.t, replace(pb, lateral=True))
        out["fea_y"] = [float(e) for e in gauge_strains(_swapped(side), pb)]
        out["seconds_y"] = time.perf_counter() - t0
    out["seconds_total"] = time.perf_counter() - start
    return out


def _key(name: str, axes: int, mesh: str) -> str:
    return f"{name}/{axes}/{mesh}"


def _sizes(r: dict) -> str:
    if r["section"] == "rectangle":
        return f"square {r['size']:.2f}, slots {r['width']:.2f} wide, {r['depth']:.2f} deep, {r['length']:.2f} long"
    wall = f" x {r['wall']:.2f} wall" if r["section"] == "tube" else ""
    return (f"{r['section']} Ø{r['size']:.2f}{wall}, flats {r['depth']:.2f} deep, {r['length']:.2f} long "
            f"({r['width']:.2f} wide)")


def _family(name: str) -> str:
    return FAMILY[name] if name in FAMILY else FAMILY[name[0]]


def _depth_ratio(r: dict) -> float:
    """The feature's depth over the section's size (diameter or height)."""
    return r["depth"] / r["size"]


def _fit(points):
    """Least squares ``y = 1 - a x`` and ``y = b - a x`` over ``(x, y)``: (a, largest residual), (b, a, largest)."""
    import numpy as np

    x, y = np.array([p[0] for p in points]), np.array([p[1] for p in points])
    a1 = float(np.sum(x * (1 - y)) / np.sum(x * x))
    r1 = float(np.max(np.abs(y - (1 - a1 * x))))
    A = np.vstack([np.ones_like(x), -x]).T
    (b2, a2), *_ = np.linalg.lstsq(A, y, rcond=None)
    r2 = float(np.max(np.abs(y - (b2 - a2 * x))))
    corr = float(np.corrcoef(x, y)[0, 1]) if len(x) > 2 else float("nan")
    return (a1, r1), (float(b2), float(a2), r2), corr


def table(cache: dict, mesh: str, names: list) -> str:
    """The markdown table and the summary from the cached runs."""
    import numpy as np

    head = ("| design | section, sizes (mm) | station (mm) | model ε (µ) | 3-D ε biaxial (µ) | 3-D/model biaxial "
            "| 3-D/model twin | biaxial / twin | C_ε (model's factor) | elements biaxial / twin "
            "| seconds biaxial / twin |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    per_family, per_design, laterals = {}, [], []
    for name in names:
        b = cache.get(_key(name, 2, mesh))
        if b is None:
            continue
        t = cache.get(_key(name, 1, mesh))
        ratios_b = [f / m for f, m in zip(b["fea"], b["model"])]
        ratios_t = [f / m for f, m in zip(t["fea"], t["model"])] if t else [None] * len(ratios_b)
        for i, s in enumerate(b["stations"]):
            rb, rt = ratios_b[i], ratios_t[i]
            bt = rb / rt if rt else None
            if bt is not None:
                per_family.setdefault(_family(name), []).append((name, i + 1, bt))
            first = i == 0
            lines.append(
                f"| {name if first else ''} | {_sizes(b) if first else ''} | {s:.2f} | {b['model'][i] * 1e6:.1f} | "
                f"{b['fea'][i] * 1e6:.1f} | {rb:.4f} | {'' if rt is None else f'{rt:.4f}'} | "
                f"{'' if bt is None else f'**{bt:.4f}**'} | {b['factors'][i] if b['factors'] else 1:.4f} | "
                + (f"{b['elements']:,} / {t['elements']:,} | {b['seconds_total']:.0f} / {t['seconds_total']:.0f} |"
                   if first and t else (f"{b['elements']:,} / - | {b['seconds_total']:.0f} / - |" if first else "| |")))
        if t:
            bts = [rb / rt for rb, rt in zip(ratios_b, ratios_t)]
            per_design.append((name, b, t, float(np.mean(bts))))
        if "fea_y" in b:
            laterals.append((name, ratios_b, [f / m for f, m in zip(b["fea_y"], b["model"])], b["seconds_y"]))
    out = [(f"Biaxial gauge strain against the model and the single-axis twin "
            f"(`python benchmarks/biaxial_strain.py --mesh {mesh}`)."), "", *lines, ""]
    out.append("**Biaxial / twin per family** (every station):")
    out.append("")
    for fam, rows in per_family.items():
        v = np.array([r[2] for r in rows])
        out.append(f"- {fam}: mean {v.mean():.4f}, from {v.min():.4f} to {v.max():.4f} "
                   f"(spread {v.max() - v.min():.4f}, {len(v)} stations of {len({r[0] for r in rows})} designs)")
    out.append("")
    if per_design:
        out.append("**Against the feature's sizes** (each design's mean over its stations; `s` the model's own step "
                   "from the side features, biaxial model strain / twin model strain - 1 = `I_s` twin / `I_s` biaxial "
                   "- 1; `ρ` the share of it the 3-D strain shows, (biaxial 3-D / twin 3-D - 1) / s):")
        out.append("")
        out.append("| design | family | depth / size | width / size | length / size | s (model) | 3-D step | ρ | "
                   "biaxial / twin |")
        out.append("|---|---|---|---|---|---|---|---|---|")
        rows = []
        for name, b, t, v in per_design:
            step = float(np.mean([mb / mt - 1 for mb, mt in zip(b["model"], t["model"])]))
            step3 = float(np.mean([fb / ft - 1 for fb, ft in zip(b["fea"], t["fea"])]))
            rows.append((name, _family(name), _depth_ratio(b), b["width"] / b["size"], b["length"] / b["size"],
                         step, v))
            out.append(f"| {name} | {_family(name)} | {_depth_ratio(b):.4f} | {b['width'] / b['size']:.4f} | "
                       f"{b['length'] / b['size']:.3f} | {step:.4f} | {step3:.4f} | {step3 / step:.2f} | {v:.4f} |")
        out.append("")
        for fam in dict.fromkeys(FAMILY.values()):
            pts = [r for r in rows if r[1] == fam]
            if len(pts) < 3:
                continue
            y = np.array([r[6] for r in pts])
            with np.errstate(invalid="ignore", divide="ignore"):
                corr = {label: float(np.corrcoef([r[k] for r in pts], y)[0, 1])
                        for label, k in (("depth/size", 2), ("width/size", 3), ("length/size", 4), ("s", 5))}
            (a1, r1), (b2, a2, r2), _ = _fit([(r[2], r[6]) for r in pts])
            (a3, r3), _, _ = _fit([(r[5], r[6]) for r in pts])
            out.append(f"- {fam} ({len(pts)} designs): correlation of biaxial/twin with "
                       + ", ".join(f"{k} {v:+.2f}" for k, v in corr.items())
                       + f"; `1 - a p/size`: a = {a1:.4f}, largest residual {r1:.4f}; `b - a p/size`: b = {b2:.4f}, "
                       f"a = {a2:.4f}, largest residual {r2:.4f}; `1 - a s`: a = {a3:.4f}, largest residual {r3:.4f}")
        out.append("")
    out.extend(_length_laws(cache, mesh, names))
    out.extend(_convergence(cache, mesh, names))
    if laterals:
        out.append("**Y bridge under F along -Y** (same mesh; 3-D/model, Z bridge under -Z beside it):")
        out.append("")
        for name, rz, ry, sec in laterals:
            out.append(f"- {name}: Z " + ", ".join(f"{v:.4f}" for v in rz) + "; Y "
                       + ", ".join(f"{v:.4f}" for v in ry) + f" ({sec:.0f} s)")
        out.append("")
    return "\n".join(out)


def _stations(cache: dict, mesh: str, names: list) -> list:
    """Every station of a design with its twin: (name, station, family, p/size, l/size, s, biaxial/twin)."""
    rows = []
    for name in names:
        b, t = cache.get(_key(name, 2, mesh)), cache.get(_key(name, 1, mesh))
        if b is None or t is None:
            continue
        for i, (fb, mb, ft, mt) in enumerate(zip(b["fea"], b["model"], t["fea"], t["model"])):
            rows.append((name, i + 1, _family(name), _depth_ratio(b), b["length"] / b["size"], mb / mt - 1,
                         (fb / mb) / (ft / mt)))
    return rows


# The laws fitted per family to every station: biaxial/twin = 1 - a x exp(-k l/size), x the depth
# over the size or the model's own step s from the side features (tube's flats with the round's).
LAWS = {"p/size": 3, "s": 5}


def _length_laws(cache: dict, mesh: str, names: list) -> list:
    """The laws of LAWS fitted by least squares per family (round and tube flats together, square
    slots), with their largest residual."""
    import numpy as np
    from scipy.optimize import least_squares

    rows = _stations(cache, mesh, names)
    out = ["**Laws with the feature's length** (least squares over every station; round and tube flats together):", ""]
    for fam, members in (("round and tube flats", ("round flats", "tube flats")), ("square slots", ("square slots",))):
        pts = [r for r in rows if r[2] in members]
        if len(pts) < 4:
            continue
        lam, y = np.array([r[4] for r in pts]), np.array([r[6] for r in pts])
        for label, k in LAWS.items():
            x = np.array([r[k] for r in pts])
            fit = least_squares(lambda q, x=x, lam=lam, y=y: 1 - q[0] * x * np.exp(-q[1] * lam) - y, [1.0, 3.0])
            res = 1 - fit.x[0] * x * np.exp(-fit.x[1] * lam) - y
            j = int(np.argmax(np.abs(res)))
            out.append(f"- {fam} ({len(pts)} stations): `1 - a·{label}·exp(-k·l/size)`, a = {fit.x[0]:.3f}, "
                       f"k = {fit.x[1]:.3f}; rms residual {np.sqrt(np.mean(res ** 2)):.4f}, largest {abs(res[j]):.4f} "
                       f"({pts[j][0]} station {pts[j][1]})")
    out.append("")
    return out


def _convergence(cache: dict, mesh: str, names: list) -> list:
    """The designs run on the fine mesh too: their ratios beside the ``mesh`` ones."""
    out = []
    for name in names:
        f = {ax: cache.get(_key(name, ax, "fine")) for ax in (2, 1)}
        n = {ax: cache.get(_key(name, ax, mesh)) for ax in (2, 1)}
        if mesh == "fine" or not all(f.values()) or not all(n.values()):
            continue
        if not out:
            out = [f"**Mesh convergence** (fine against {mesh}; 3-D/model biaxial, twin, and biaxial/twin, "
                   "per station):", ""]
        def ratios(r):
            return [fe / mo for fe, mo in zip(r["fea"], r["model"])]
        parts = []
        for label, runs in (("fine", f), (mesh, n)):
            rb, rt = ratios(runs[2]), ratios(runs[1])
            parts.append(f"{label} " + "; ".join(f"{b:.4f}, {t:.4f}, {b / t:.4f}" for b, t in zip(rb, rt))
                         + f" ({runs[2]['elements']:,} / {runs[1]['elements']:,} elements, "
                         f"{runs[2]['seconds_total']:.0f} / {runs[1]['seconds_total']:.0f} s)")
        out.append(f"- {name}: " + " — ".join(parts))
    return out + [""] if out else []


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("--only", nargs="+", choices=NAMES, default=NAMES)
    parser.add_argument("--no-twins", action="store_true", help="the biaxial designs only")
    parser.add_argument("--twins-only", action="store_true", help="the single-axis twins only")
    parser.add_argument("--lateral", nargs="*", choices=NAMES, default=[],
                        help="biaxial designs also solved for F along -Y (Y bridge read)")
    parser.add_argument("--cache", type=Path, default=HERE / "biaxial_strain.json")
    parser.add_argument("--table", action="store_true", help="only write the table from the cache")
    parser.add_argument("-o", "--output", type=Path, help="also write the table as markdown")
    args = parser.parse_args()
    cache = json.loads(args.cache.read_text(encoding="utf-8")) if args.cache.exists() else {}
    if not args.table:
        variants = ([] if args.twins_only else [2]) + ([] if args.no_twins else [1])
        for name in args.only:
            for axes in variants:
                key = _key(name, axes, args.mesh)
                lateral = axes == 2 and name in args.lateral
                if key in cache and (not lateral or "fea_y" in cache[key]):
                    continue
                r = measure(design(name, axes), args.mesh, lateral)
                cache[key] = r
                args.cache.write_text(json.dumps(cache, indent=1), encoding="utf-8")
                ratios = ", ".join(f"{f / m:.4f}" for f, m in zip(r["fea"], r["model"]))
                extra = ("; Y " + ", ".join(f"{f / m:.4f}" for f, m in zip(r["fea_y"], r["model"]))
                         if "fea_y" in r else "")
                print(f"{key}: 3-D/model {ratios}{extra} ({r['elements']:,} elements, {r['seconds_total']:.0f} s)",
                      flush=True)
    text = table(cache, args.mesh, [n for n in NAMES if n in args.only] if not args.table else NAMES)
    print(text)
    if args.output:
        args.output.write_text(text + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
