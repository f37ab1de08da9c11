"""Round flats held out of the corrections' fits: do the round flats' fits predict flats they were
not fitted on? Each case is a pocket of the round flats' study boxes (``checks.study``) under a
gauge grid ``grid_lp`` times shorter than the pocket (4-8 grids, beyond the study's 2.4-4), on the
same beam, pocket and backing: a wide grid gap beside a short flat near the clamp, where no study
point is. Points are Halton points beyond the first LONG_GRID_SKIP, whose depths, lengths and radii
the study's own round flat groups took. Each is run through the study's 3-D check
(``study.run_case``) and written as a study table; then the shipped strain fit's error on each row.

    python benchmarks/round_flat_holdout.py [-o benchmarks/round_flat_holdout.csv] [--mesh normal]

About 12 minutes on 2 cores (37 flats, normal mesh). The table is read by
tests/validation/test_corrections_study.py and quoted in docs/model.md §7.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from designer.checks import fits, study

HERE = Path(__file__).resolve().parent
LONG_GRID_SKIP = 120
GRID_LP = (4.0, 8.0)
GROUPS = (
    ("round-pocket", {**study.POCKET_BOXES["round-pocket"], "depth_ratio": (0.05, 0.35), "grid_lp": GRID_LP}, 14),
    ("round-pocket", {**study.NEAR_CLAMP_ROUND_FLATS, "length_ratio": (0.4, 2.0), "grid_lp": GRID_LP}, 12),
    ("round-pocket", {**study.NEAR_CLAMP_SHORT_ROUND_FLATS, "length_ratio": (0.4, 0.6), "grid_lp": GRID_LP}, 18),
)


def cases() -> list:
    """The held-out flats, in the table's order."""
    return study.group_cases([(fam, box, count, LONG_GRID_SKIP) for fam, box, count in GROUPS])


def errors(path: Path) -> list[tuple[dict, float]]:
    """Each row of the table at ``path`` with the shipped strain fit's error on its far station
    (fit minus 3-D, as a share of the plain model's strain)."""
    from designer.model import corrections

    fit = corrections.load().fit("round-pocket", "strain")
    return [(r, fits.judged_error("strain", r, float(fit(r)))) for r in fits.with_nearness(study.read_csv(path))]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=HERE / "round_flat_holdout.csv")
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    args = parser.parse_args(argv)
    rows = []
    for case in cases():
        rows.append(study.run_case(case, args.mesh))
        study.write_csv(rows, args.output)
        print(f"{len(rows):2d} {rows[-1].parameters}: far {rows[-1].strain_far:.4f}", flush=True)
    print("\n| l/D | grid/D | grids | depth/D | clamp/D | 3-D far / plain | fit - 3-D |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    found = errors(args.output)
    for r, e in found:
        print(f"| {r['length_ratio']:.2f} | {r['grid_ratio']:.3f} | {r['length_ratio'] / r['grid_ratio']:.1f} | "
              f"{r['depth_ratio']:.3f} | {r['clamp_ratio']:.2f} | {r['strain_far']:.4f} | {e * 100:+.2f} % |")
    print(f"\nlargest |fit - 3-D|: {max(abs(e) for _, e in found) * 100:.2f} % over {len(found)} flats")
    return 0


if __name__ == "__main__":
    sys.exit(main())
