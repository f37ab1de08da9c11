"""Do the features' fits depend on the material? The pocket, flat and hole fits (docs/model.md
§7) were fitted on the study's 6061-T6 bars (Poisson's ratio 0.33); the catalogue's steels
reach down to 0.272. A feature's 3-D field (a floor held by the walls around it, the flow of
stress round a hole) depends on nu, so a fit taken at one nu may read another material's gauge
off. Here a spread of the study's own
cases (``checks.study.cases``, a few of each feature family inside the fits' domain, where the
optimiser may take a design) is checked in 3-D
(``checks.fea.verify_design``) in four materials of the catalogue spanning its Poisson's ratios,
and each reading is set beside the same bar's in 6061-T6: the 3-D over the shipped model's gauge
strain at each station, free-end deflection and peak stress at the features. Run by hand (5 bars
of each family in four materials, 80 3-D checks: about half an hour, normal mesh):

    python benchmarks/feature_poisson_check.py [--per-family 5] [--families ...] [--materials ...] [-o FILE.md]

``--families round-none tube-none`` takes plain round bars and tubes instead, whose own near-clamp
fits were taken on 6061-T6 too. benchmarks/feature_poisson_check.md holds two runs of 8 bars of each
feature family in 17-4PH-H900 and Ti-6Al-4V, one of 5 in four materials, and two of 8 plain round
bars and tubes (before and after their near-clamp loss was scaled to nu); docs/model.md §7 and
``model.poisson`` read them.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from designer.checks import study
from designer.errors import FpdError, SpecError
from designer.spec import catalogue

MATERIALS = ("6061-T6", "17-4PH-H900", "301-full-hard", "Ti-6Al-4V")   # nu 0.33 (the fits'), 0.272, 0.29, 0.342
FAMILIES = ("rectangle-pocket", "round-pocket", "tube-pocket", "rectangle-hole")
# plain round bars and tubes: their own near-clamp fits (``near_clamp``), taken on 6061-T6 too
PLAIN_FAMILIES = ("round-none", "tube-none")


def evaluated(case: study.Case):
    """The case's design evaluated (``evaluate_fixed``)."""
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    return evaluate_fixed(parse_spec_text(case.spec_text(), source=case.family))


def in_domain(case: study.Case) -> bool:
    """Whether the case lies inside the fits' domain, where the optimiser may take a design (and is
    a design the CAD can cut)."""
    try:
        violations = evaluated(case).evaluation.violations
    except FpdError:
        return False
    return not any(v.name.startswith("domain_") for v in violations)


def sample(per_family: int, families=FAMILIES) -> list[study.Case]:
    """``per_family`` cases of each of ``families`` inside the fits' domain, evenly spread over the
    study's list of them."""
    out = []
    for family in families:
        cases = [c for c in study.cases((family,)) if in_domain(c)]
        picks = np.linspace(0, len(cases) - 1, per_family).round().astype(int)
        out += [cases[i] for i in dict.fromkeys(picks)]
    return out


def run(material: str, case: study.Case, mesh: str) -> tuple:
    """``(gauge ratios, deflection ratio, feature peak ratio)``: 3-D over the shipped model."""
    from designer.checks.fea import verify_design

    v = verify_design(evaluated(replace(case, material=material)).record, mesh=mesh)
    return (tuple(g.ratio for g in v.gauges), v.deflection_fea / v.deflection_model,
            v.stress_feature_fea / v.stress_model)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per-family", type=int, default=5, help="cases of each feature family [5]")
    parser.add_argument("--families", nargs="+", default=FAMILIES, choices=FAMILIES + PLAIN_FAMILIES,
                        metavar="FAMILY",
                        help=f"the feature families [{' '.join(FAMILIES)}]")
    parser.add_argument("--materials", nargs="+", default=MATERIALS[1:], metavar="MATERIAL",
                        help=f"the catalogue's materials to set beside {MATERIALS[0]} [{' '.join(MATERIALS[1:])}]")
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("-o", "--output", type=Path, help="also write the table and the summary as markdown")
    args = parser.parse_args(argv)
    lines = ["| case | material | nu | gauge strain 3-D/model | vs 6061-T6 | deflection | vs 6061-T6 | "
             "feature peak | vs 6061-T6 |", "|---|---|---:|---|---|---:|---:|---:|---:|"]
    print("\n".join(lines))
    materials = (MATERIALS[0], *(m for m in args.materials if m != MATERIALS[0]))
    for m in materials:
        try:
            catalogue.material(m)    # an unknown name is refused before any 3-D run
        except SpecError as e:
            parser.error(f"--materials: {e}")
    start, shifts, cases = time.perf_counter(), {}, sample(args.per_family, args.families)
    for k, case in enumerate(cases):
        base = None
        for material in materials:
            nu = catalogue.material(material).poisson
            gauges, deflection, peak = run(material, case, args.mesh)
            if base is None:
                base = gauges, deflection, peak
            shift = ([g / b - 1 for g, b in zip(gauges, base[0])], deflection / base[1] - 1, peak / base[2] - 1)
            shifts.setdefault((case.family, material), []).append(shift)
            line = (f"| {k + 1} {case.family} | {material} | {nu:.3f} | {', '.join(f'{g:.4f}' for g in gauges)} | "
                    f"{', '.join(f'{s:+.2%}' for s in shift[0])} | {deflection:.4f} | {shift[1]:+.2%} | "
                    f"{peak:.3f} | {shift[2]:+.1%} |")
            lines.append(line)
            print(line, flush=True)
    seconds = time.perf_counter() - start
    summary = ["", "| family | material | nu | gauge strain vs 6061-T6 | deflection | feature peak |",
               "|---|---|---:|---|---|---|"]
    for (family, material), rows in shifts.items():
        if material == MATERIALS[0]:
            continue
        g = np.array([s for r in rows for s in r[0]])
        d, p = np.array([r[1] for r in rows]), np.array([r[2] for r in rows])
        summary.append(f"| {family} | {material} | {catalogue.material(material).poisson:.3f} | "
                       f"{g.min():+.2%} .. {g.max():+.2%} (mean {g.mean():+.2%}) | {d.min():+.2%} .. {d.max():+.2%} | "
                       f"{p.min():+.1%} .. {p.max():+.1%} |")
    summary.append(f"\n{len(cases)} cases x {len(materials)} materials, "
                   f"{args.mesh} mesh, {seconds:.0f} s.")
    print("\n".join(summary))
    if args.output:
        head = (f"The features' fits in {len(materials)} materials: `python benchmarks/feature_poisson_check.py` (each "
                "reading is 3-D over the shipped model; \"vs 6061-T6\" is the same bar's reading over its "
                "reading in 6061-T6, the fits' material).\n\n")
        args.output.write_text(head + "\n".join(lines + summary) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
