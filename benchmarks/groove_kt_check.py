"""Roark's K_t of the load grooves (docs/model.md §4, designer.model.grooves) against the 3-D
check's own solver, on the grooves the CAD cuts.

For each case a plain bar (no pockets) with the default load grooves (at x_min, the middle and
x_max of the load range) is built by the CAD from a fixed design, as ``export`` builds it, and
solved by verify's solver (quadratic tetrahedra, the clamp held, the load beyond the cut as its
resultant), with the mesh refined at the groove nearest the clamp to a fraction of its 0.25 mm
root radius, which verify's own mesh is not. Printed per case: the axial stress at the groove's
root (the vertices' averaged stress tensor, the largest ``sigma_xx`` within the groove's width),
its ratio to the net section's nominal stress ``M c / I`` (the 3-D ``K_t``), Roark's ``K_t`` and
their ratio, on two meshes (the second 1.5 x finer at the groove).

Run by hand:  python benchmarks/groove_kt_check.py
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

# (label, section, its sizes, groove depth): the default 0.3 mm groove (t/r 1.2) and the
# deepest a spec may give (5 % of the smaller side)
CASES = [
    ("round Ø8, default groove", {"kind": "round", "diameter": "8 mm"}, None),
    ("rectangle 10 x 6, default", {"kind": "rectangle", "width": "10 mm", "height": "6 mm"}, None),
    ("round Ø16, 0.8 mm groove", {"kind": "round", "diameter": "16 mm"}, "0.8 mm"),
]
# the groove's mesh: elements of this share of its root radius at the root, on the first mesh
ROOT_ELEMENTS = 0.25
FINER = 1.5


def record_of(section: dict, depth) -> dict:
    """design.json of a plain bar with load grooves, as ``evaluate`` writes it."""
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec

    cad = {"load_grooves": True}
    if depth is not None:
        cad["groove_depth"] = depth
    spec = parse_spec({"name": "groove", "load": {"force": ["1 N", "20 N"], "position": ["40 mm", "110 mm"]},
                       "electronics": {"excitation": "5 V", "gain": 128, "noise_rti": "50 nV"},
                       "gauge": "BF350-3AA", "limits": {"fatigue": False},
                       "design": {"material": "7075-T6", "section": section, "stations": ["8 mm", "25 mm"],
                                  "feature": {"kind": "none"}, "length": "115 mm"},
                       "cad": cad, "tolerances": {"class": "none"}})
    return evaluate_fixed(spec).record, spec


def root_stress(sol, pb, x_g: float, reach: float) -> float:
    """The largest sigma_xx within ``reach`` of the groove's plane at ``x_g``, at the mesh
    vertices, the stress tensor averaged over the elements at each (as
    ``readout.vertex_von_mises`` averages it)."""
    from skfem import Basis

    from designer.checks.fea.solve import lame

    corners = np.array([[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    vb = Basis(sol.mesh, sol.basis.elem, quadrature=(corners, np.ones(4) / 24))
    grad = np.einsum("cie,iaeq->caeq", sol.u[:, vb.element_dofs],
                     np.array([vb.basis[i][0].grad for i in range(vb.Nbfun)]))
    strain = (grad + grad.transpose(1, 0, 2, 3)) / 2
    lam, mu = lame(pb.E, pb.poisson)
    sxx = 2 * mu * strain[0, 0] + lam * np.einsum("cceq->eq", strain)     # (element, corner)
    n = sol.mesh.p.shape[1]
    total, count = np.zeros(n), np.zeros(n)
    for q in range(4):
        np.add.at(total, sol.mesh.t[q], sxx[:, q])
        np.add.at(count, sol.mesh.t[q], 1.0)
    near = np.abs(sol.mesh.p[0] - x_g) <= reach
    return float(np.max((total / count)[near]))


def check(label: str, section: dict, depth) -> tuple:
    from designer.checks.fea.compare import _problem, _step
    from designer.checks.fea.geometry_mesh import mesh_quarter
    from designer.checks.fea.solve import solve
    from designer.model import grooves

    record, spec = record_of(section, depth)
    _, _, ev, beam, pb = _problem(record, "normal")
    t = beam.grooves.depth
    x_g = min(beam.grooves.positions)
    r = grooves.ROOT_RADIUS
    # the solid to two section sizes past the groove; the groove's faces refined (``_feature_faces``
    # takes the faces inside a span as a feature's)
    pb = replace(pb, cut=min(pb.position, x_g + 2 * max(beam.width, beam.height)), feature="none",
                 spans=((x_g - r - 1e-6, x_g + r + 1e-6),), detail_size=ROOT_ELEMENTS * r,
                 detail_reach=2 * r, floor_radius=0.0)
    g = ev.design.geometry
    nominal, _ = grooves.groove_stress(g, spec)
    kt_roark = grooves.stress_concentration(g.section, t, g.size)   # the chart's, without FACTOR_3D
    moment = spec.load.force_max * (spec.load.position_max - x_g)
    out = []
    with _step(record, beam) as step_path:
        for refinement in (1.0, FINER):
            t0 = time.perf_counter()
            points, tets, _ = mesh_quarter(step_path, pb, refinement)
            sol = solve(points, tets, pb)
            peak = root_stress(sol, pb, x_g, r)
            out.append((peak, peak / float(nominal), tets.shape[1], time.perf_counter() - t0))
    return label, t, moment, float(nominal), float(kt_roark), out


def main() -> None:
    print(f"{'case':28s} {'t (mm)':>7s} {'nominal (MPa)':>14s} {'Roark K_t':>10s} "
          f"{'3-D K_t':>16s} {'3-D / Roark':>16s} {'elements':>18s}")
    for label, section, depth in CASES:
        name, t, _, nominal, kt, runs = check(label, section, depth)
        kts = " / ".join(f"{k:.3f}" for _, k, _, _ in runs)
        ratios = " / ".join(f"{k / kt:.3f}" for _, k, _, _ in runs)
        elements = " / ".join(f"{n:,}" for _, _, n, _ in runs)
        print(f"{name:28s} {t * 1e3:7.2f} {nominal / 1e6:14.2f} {kt:10.3f} {kts:>16s} {ratios:>16s} "
              f"{elements:>18s}", flush=True)
    print(f"(3-D K_t: the largest axial stress within the groove's width over the net section's M c / I; "
          f"meshes at {ROOT_ELEMENTS:g} and {ROOT_ELEMENTS / FINER:.3g} of the root radius)")


if __name__ == "__main__":
    main()
