"""The load grooves' K_t in 3-D (docs/model.md §4, designer.model.grooves): a submodel of one groove
in pure bending (designer.checks.fea.groove, which verify runs on a design's groove), its root
meshed ever finer until the peak settles.

Each case is a straight segment of the bar, 2.5 section sizes long either side of one groove,
built in gmsh's OpenCASCADE kernel with the groove the model assumes: 0.5 mm wide, ``t`` deep,
its walls ending in a semicircular root of radius ``r = 0.25 mm`` (a ring on a round bar or
tube; on a rectangle one such groove across each face, the top and side grooves crossing at the
section's edges as the CAD's do). Only the eighth ``x, y, z >= 0`` is meshed: the groove's
mid-plane ``x = 0`` and the bending plane ``y = 0`` are planes of symmetry, the neutral plane
``z = 0`` one of antisymmetry (``u_x = u_y = 0``), one vertex on it holds ``u_z``. The end face
``x = L`` carries the pure bending traction ``sigma = M z / I`` (``I`` that of the meshed face,
so that the resultant is ``M``); for a prismatic bar that is the exact solution, so the groove's
own disturbance is all the segment holds. Quadratic tetrahedra (scikit-fem's ElementTetP2, the
3-D check's assembly and two-level conjugate gradients, designer.checks.fea.solve); the element
size is ``r / n`` within 0.4 r of the groove's faces (a gmsh Distance/Threshold field) and grows
from there at 0.3 per unit distance to an eighth of the section.

Read out at the groove's faces: the largest axial stress ``sigma_xx`` at a vertex, both as the
stress tensor averaged over the elements at the vertex and as the largest single element's value
there (which approaches the average as the mesh converges), over the net section's nominal
stress ``M c / I`` exactly as ``grooves.groove_stress`` defines it (the 3-D ``K_t``), against
Roark's ``K_t`` (W. C. Young and R. G. Budynas, Roark's Formulas for Stress and Strain, 7th ed.,
Table 17.1, as ``grooves.stress_concentration`` has it, without ``FACTOR_3D``). The finest three
meshes are Richardson-extrapolated (order from the three, at most 2 for the averaged stress of
quadratic elements). Two checks: the same segment without a groove (``K_t`` 1), and a
square-bottomed groove (sharp inner corners, no root radius: what the CAD cut before it cut the
full-radius groove of designer/outputs/cad/solid.py), whose corner stress grows without bound as
the mesh is refined (M. L. Williams, J. Appl. Mech. 19 (1952) 526: a 90 degree re-entrant corner's stress goes as
``rho^-0.456``), so that it has no K_t to converge to.

Run by hand:  python benchmarks/groove_kt_check.py [--meshes 4 6 9 12 18] [--further]   (about 40 minutes on two cores;
the Ø16 bar's r/18 mesh is near 2.5 million tetrahedra and 10 GB)
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

# (label, section, sizes in mm, groove depth in mm or None for the default); profile "u" is the
# model's groove (and the CAD's), "square" a square-bottomed one, None the plain segment
CASES = [
    ("round Ø8, default groove", "round", {"diameter": 8.0}, None, "u"),
    ("rectangle 10 x 6, default groove", "rectangle", {"width": 10.0, "height": 6.0}, None, "u"),
    ("round Ø16, 0.8 mm groove", "round", {"diameter": 16.0}, 0.8, "u"),
    ("tube Ø12 / Ø8, default groove", "tube", {"diameter": 12.0, "wall": 2.0}, None, "u"),
    ("round Ø8, no groove", "round", {"diameter": 8.0}, None, None),
    ("rectangle 10 x 6, no groove", "rectangle", {"width": 10.0, "height": 6.0}, None, None),
    ("tube Ø12 / Ø8, no groove", "tube", {"diameter": 12.0, "wall": 2.0}, None, None),
    ("round Ø8, square-bottomed groove", "round", {"diameter": 8.0}, None, "square"),
    ("rectangle 10 x 6, square-bottomed groove", "rectangle", {"width": 10.0, "height": 6.0}, None, "square"),
]
# Further sections for the factors' reach (run with --meshes 6 9 12 --further): a square, a flat and a
# tall bar, thin-walled tubes
FURTHER = [
    ("rectangle 8 x 8, default groove", "rectangle", {"width": 8.0, "height": 8.0}, None, "u"),
    ("rectangle 16 x 4, default groove", "rectangle", {"width": 16.0, "height": 4.0}, None, "u"),
    ("rectangle 4 x 12, default groove", "rectangle", {"width": 4.0, "height": 12.0}, None, "u"),
    ("tube Ø12 x 1, default groove", "tube", {"diameter": 12.0, "wall": 1.0}, None, "u"),
    ("tube Ø20 x 1.2, default groove", "tube", {"diameter": 20.0, "wall": 1.2}, None, "u"),
]
# Elements at the root: r / n for each n
MESHES = (4, 6, 9, 12, 18)


def default_depth(kind: str, dims: dict) -> float:
    """The CAD's default groove depth (mm): ``grooves.cut_depth`` of the smaller side."""
    from designer.model import grooves

    smaller = min(dims["width"], dims["height"]) if kind == "rectangle" else dims["diameter"]
    return grooves.cut_depth(smaller * 1e-3) * 1e3


def richardson(ns, values) -> tuple:
    """``(extrapolated value, order)`` from the last three meshes (root sizes ``r / n``): the order
    ``p`` solving ``(v2 - v1) / (v3 - v2) = (h1^p - h2^p) / (h2^p - h3^p)``; ``(None, None)`` when
    the three do not change monotonically (scatter, not a trend) or ``p`` is below 0.5 (no asymptotic
    range); ``p`` at most 3 (a faster settling is taken at 3)."""
    (n1, n2, n3), (v1, v2, v3) = ns[-3:], values[-3:]
    h1, h2, h3 = 1 / n1, 1 / n2, 1 / n3
    d1, d2 = v2 - v1, v3 - v2
    if not d1 * d2 > 0:
        return None, None

    def excess(p):
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - d1 / d2

    lo, hi = 0.5, 3.0
    if excess(hi) < 0:                      # faster than third order: settled, taken at the cap
        return v3 + d2 * h3 ** hi / (h2 ** hi - h3 ** hi), hi
    if excess(lo) > 0:
        return None, None
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if excess(lo) * excess(mid) > 0 else (lo, mid)
    p = (lo + hi) / 2
    return v3 + d2 * h3 ** p / (h2 ** p - h3 ** p), p


def check(label: str, kind: str, dims: dict, depth, profile, meshes) -> dict:
    from designer.checks.fea.groove import reference, root_peak, segment, solve_bending

    t = depth if depth is not None else default_depth(kind, dims)
    nominal, kt_roark = reference(kind, dims, t, profile is not None)
    runs = []
    for n in meshes:
        t0 = time.perf_counter()
        points, tets, nodes, L = segment(kind, dims, t, profile, n)
        mesh, dofs, u, iterations = solve_bending(points, tets, L)
        out = root_peak(mesh, dofs, u, nodes)
        out.update(n=n, tetrahedra=tets.shape[1], unknowns=3 * dofs.N, iterations=iterations,
                   seconds=time.perf_counter() - t0, kt=out["averaged"] / nominal, kt_raw=out["raw"] / nominal,
                   kt_mid=out["mid"] / nominal)
        runs.append(out)
        print(f"  {label}, r/{n:g}: K_t {out['kt']:.4f} (element {out['kt_raw']:.4f}), at "
              f"({', '.join(f'{c:.3f}' for c in out['at'])}) mm; {out['tetrahedra']:,} tetrahedra, "
              f"{out['unknowns']:,} unknowns, {iterations} iterations, {out['seconds']:.0f} s", flush=True)
    return {"label": label, "kind": kind, "t": t, "nominal": nominal, "roark": kt_roark, "profile": profile,
            "runs": runs}


def converged(ns, runs) -> tuple:
    """``(K_t, how)``: the Richardson limit of the finest three meshes, else the mean of the finest
    two (scatter about a settled value)."""
    kts = [run["kt"] for run in runs]
    limit, order = richardson(ns, kts) if len(runs) >= 3 else (None, None)
    if limit is not None:
        return limit, f"Richardson, p {order:.1f}"
    return float(np.mean(kts[-2:])), "mean of the finest two"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", type=float, nargs="+", default=list(MESHES),
                        help="root element sizes as r / n, the n (default: %(default)s)")
    parser.add_argument("--further", action="store_true", help="the further sections (FURTHER) instead")
    args = parser.parse_args()
    results = [check(*case, args.meshes) for case in (FURTHER if args.further else CASES)]
    print()
    print("| case | root mesh | 3-D K_t | largest element's | 3-D / Roark | tetrahedra | s |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for res in results:
        for run in res["runs"]:
            ratio = f"{run['kt'] / res['roark']:.3f}" if res["profile"] else "-"
            print(f"| {res['label']} | r/{run['n']:g} | {run['kt']:.3f} | {run['kt_raw']:.3f} | {ratio} | "
                  f"{run['tetrahedra']:,} | {run['seconds']:.0f} |")
    print()
    print("| case | t (mm) | nominal (MPa) | Roark K_t | 3-D K_t | 3-D / Roark |")
    print("|---|---:|---:|---:|---:|---:|")
    for res in results:
        if res["profile"] == "square":
            kt, ratio = "none (singular)", "-"
        else:
            value, how = converged(args.meshes, res["runs"])
            kt = f"{value:.3f} ({how})"
            ratio = f"{value / res['roark']:.3f}" if res["profile"] else "-"
        print(f"| {res['label']} | {res['t']:.2f} | {res['nominal']:.2f} | {res['roark']:.3f} | {kt} | {ratio} |")
    print()
    for res in results:
        if res["kind"] == "rectangle" and res["profile"] == "u":
            mids = " / ".join(f"{run['kt_mid']:.3f}" for run in res["runs"])
            print(f"{res['label']}: K_t in the middle of the top face's root (y = 0): {mids}")
        if res["profile"] == "square" and len(res["runs"]) >= 2:
            a, b = res["runs"][-2:]
            print(f"{res['label']}: K_t grows as n^{math.log(b['kt'] / a['kt']) / math.log(b['n'] / a['n']):.2f} "
                  f"between the finest two meshes")


if __name__ == "__main__":
    main()
