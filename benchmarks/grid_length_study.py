"""Does a pocket read as the model says when it is many gauge grids long? Each case is a pocket of
the study's boxes, checked in 3-D twice: under the study's 3 mm grid (the pocket 2.4-4 grid
lengths long, inside the study) and, on the same beam, pocket and backing, under a grid short
enough to make the pocket ``lp`` grid lengths long (4-10).

The pocket corrections of docs/model.md §7 were fitted to a study whose pockets are 2.4-4 grid
lengths long (``checks.study``'s ``lp_grid``, the catalogue's gauges with their pocket margins).
Their parameters (depth, length, and the grid's gaps to the pocket's ends) do not say how long the
grid is beside the pocket, so a flat 0.4 D long under a grid 0.036 D long (a Ø87 mm bar under a
3.18 mm grid: 11 grid lengths) has every parameter inside the fits' ranges and still lies outside
the study. Shortening the grid on the same beam changes nothing but what the gauge averages, so
the change between the two checks is the grid's length alone. Each line prints both stations'
3-D/model gauge-strain ratios (the model with the shipped corrections) under both grids; the
summary, per family and band of ``lp``, the largest distance from 1 and the largest change; last,
the bench suite's 035-kilonewton design of before the limit under its own grid and a longer one.
Points are Halton points of the study's boxes beyond those the study used, kept where the design
is inside every other domain limit. Run by hand (about 20 minutes on 2 cores on the coarse mesh,
whose gauge-strain ratios agree with the normal mesh's within 0.1 % on the suite's largest bar):

    python benchmarks/grid_length_study.py [--points 6] [--mesh coarse]

With ``--tubes``, tube flats alone (away from the clamp and near it, from one diameter long), 4-8
grid lengths long under the short grid, at Halton points beyond the first run's: the evidence for
a tube's flat being allowed 8 grids (``domain.LP_GRID_TOP``; 11 minutes for 20 flats, ``--points 10``).
With ``--round``, round flats alone (away from the clamp and near it, and as many again 0.4-1 D long),
4-6 grid lengths long under the short grid, and the corner design at 5 and 6: the evidence for a
round bar's flat being allowed 6 grids (22 minutes for 24 flats, ``--points 6``).

Its figures: benchmarks/grid_length_study.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

from designer.checks import study

# (label, family, box): the study's boxes of each pocket family whose fits a design uses (tube
# flats from one diameter long, round flats from 0.4 D, slots from 0.9 h: docs/model.md §7).
GROUPS = (
    ("round flat", "round-pocket", study.POCKET_BOXES["round-pocket"]),
    ("round flat near the clamp", "round-pocket", study.NEAR_CLAMP_ROUND_FLATS),
    ("slot", "rectangle-pocket", study.POCKET_BOXES["rectangle-pocket"]),
    ("slot, short for its bar", "rectangle-pocket", study.SHORT_SLOTS),
    ("tube flat", "tube-pocket", {**study.POCKET_BOXES["tube-pocket"], "length_ratio": (1.0, 1.8)}),
)
# Round flats short for their bar (0.4-1 D, the shortest the round flats' strain fit takes): there a
# short grid sits in the floor's uneven middle, where the corner design read 2.8 % off at 11 grids.
SHORT_ROUND = {"length_ratio": (0.4, 1.0)}
ROUND_GROUPS = (
    GROUPS[0], GROUPS[1],
    ("round flat, short for its bar", "round-pocket", {**study.POCKET_BOXES["round-pocket"], **SHORT_ROUND}),
    ("round flat, short, near the clamp", "round-pocket", {**study.NEAR_CLAMP_ROUND_FLATS, **SHORT_ROUND}),
)
TUBE_GROUPS = (
    GROUPS[-1],
    ("tube flat near the clamp", "tube-pocket", {**study.NEAR_CLAMP_TUBE_FLATS, "length_ratio": (1.0, 1.8)}),
)
SKIP = 300          # Halton points the study's own groups may have used
TUBE_SKIP = 600     # ... and the first run's
LP_RANGE = (4.0, 10.0)
TUBE_LP_RANGE = (4.0, 8.0)
ROUND_SKIP = 900    # beyond the tubes' run too
ROUND_LP_RANGE = (4.0, 6.0)
BANDS = ((4.0, 5.0), (5.0, 6.0), (6.0, 8.0), (8.0, 10.0))
# The corner design's flats 5 and 6 grid lengths long.
ROUND_CORNER_GRIDS = (34.91e-3 / 5, 34.91e-3 / 6)


def _cases(box: dict, family: str, count: int, skip: int = SKIP, lp_range: tuple = LP_RANGE):
    """Up to ``count`` (case, lp) of ``box`` inside every domain limit at the study's grid; ``lp``
    the pocket's length in grids under the short grid, from one more Halton coordinate."""
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    out = []
    for point in study.halton(skip + 20 * count, len(box) + 1)[skip:]:
        case = study.pocket_case(family, study.box_point(box, point), box)
        if case is None:
            continue
        ev = evaluate_fixed(parse_spec_text(case.spec_text())).evaluation
        if any(v.name.startswith("domain_") for v in ev.violations):
            continue
        out.append((case, lp_range[0] + point[-1] * (lp_range[1] - lp_range[0])))
        if len(out) == count:
            break
    return out


# The bench suite's 035-kilonewton as it was designed before the limit (benchmarks/bench_verify.py's
# large-round-bar: a Ø87.26 mm bar, shallow flats 34.91 mm long 0.10 D from the clamp, at the corner
# of the round flats' fits), under its own 3.18 mm grid (11 grid lengths) and under one 8.72 mm long
# on the same backing (4.0).
CORNER_GRIDS = (3.18e-3, 8.72e-3)


def corner(mesh: str, grids=CORNER_GRIDS) -> None:
    """The corner design's three stations' 3-D/model ratios under ``grids`` (m)."""
    from designer.checks.fea import verify_design
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    from bench_verify import LARGE_SPEC     # (beside this script)

    print("\n| corner design | grid (mm) | pocket / grid | 3-D/model by station |")
    print("|---|---:|---:|---|")
    for grid in grids:
        text = LARGE_SPEC.replace("gauge: CEA-06-125UW-120",
                                  f"gauge: {{name: CEA-06-125UW-120, grid_length: {grid * 1e3:g} mm}}")
        record = evaluate_fixed(parse_spec_text(text)).record
        got = verify_design(record, mesh=mesh).ratios
        print(f"| Ø87.26 mm, flats 34.91 mm | {grid * 1e3:g} | {34.91e-3 / grid:.2f} | "
              f"{', '.join(f'{r:.3f}' for r in got)} |", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=6, help="cases per group [6]")
    parser.add_argument("--mesh", default="coarse", choices=("coarse", "normal", "fine"))
    parser.add_argument("--corner-only", action="store_true", help="only the corner design (CORNER_GRIDS)")
    parser.add_argument("--tubes", action="store_true", help="tube flats alone, 4-8 grid lengths (TUBE_GROUPS)")
    parser.add_argument("--round", action="store_true",
                        help="round flats alone, the short ones too, 4-6 grid lengths (ROUND_GROUPS) and the "
                             "corner design at 5 and 6")
    args = parser.parse_args(argv)
    if args.corner_only:
        corner(args.mesh)
        return 0
    groups, skip, lp_range = (TUBE_GROUPS, TUBE_SKIP, TUBE_LP_RANGE) if args.tubes else (GROUPS, SKIP, LP_RANGE)
    if args.round:
        groups, skip, lp_range = ROUND_GROUPS, ROUND_SKIP, ROUND_LP_RANGE
    print("| group | section (mm) | pocket (mm) | depth/size | length/size | 3 mm grid: lp, near, far | "
          "short grid: lp, near, far | change near, far |")
    print("|---|---:|---:|---:|---:|---|---|---|")
    start, seen = time.perf_counter(), []
    for label, family, box in groups:
        for case, lp in _cases(box, family, args.points, skip, lp_range):
            native = study.model_ratios(case, args.mesh)
            short = dataclasses.replace(case, grid_length=case.pocket_length / lp)
            swapped = study.model_ratios(short, args.mesh)
            change = [s / n - 1 for s, n in zip(swapped, native)]
            depth = case.depth / (case.wall if family == "tube-pocket" else case.size)
            print(f"| {label} | {case.size * 1e3:.2f} | {case.pocket_length * 1e3:.2f} | {depth:.3f} | "
                  f"{case.pocket_length / case.size:.2f} | {case.pocket_length / case.grid_length:.2f}, "
                  f"{native[0]:.4f}, {native[1]:.4f} | {lp:.2f}, {swapped[0]:.4f}, {swapped[1]:.4f} | "
                  f"{change[0] * 100:+.2f} %, {change[1] * 100:+.2f} % |", flush=True)
            seen.append((label, case.pocket_length / case.grid_length, native, lp, swapped, change))
    print("\n| group | pockets (grid lengths) | cases | largest \\|3-D/model - 1\\| "
          "| largest \\|change\\| from the 3 mm grid |")
    print("|---|---|---:|---:|---:|")
    for label, *_ in groups:
        mine = [s for s in seen if s[0] == label]
        if not mine:
            continue
        inside = [r for s in mine for r in s[2]]
        print(f"| {label} | 2.4-4 (3 mm grid) | {len(mine)} | {max(abs(r - 1) for r in inside) * 100:.2f} % | - |")
        for lo, hi in BANDS:
            band = [s for s in mine if lo <= s[3] < hi]
            if band:
                worst = max(abs(r - 1) for s in band for r in s[4])
                moved = max(abs(c) for s in band for c in s[5])
                print(f"| {label} | {lo:g}-{hi:g} | {len(band)} | {worst * 100:.2f} % | {moved * 100:.2f} % |")
    if not args.tubes:
        corner(args.mesh, ROUND_CORNER_GRIDS if args.round else CORNER_GRIDS)
    print(f"study took {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
