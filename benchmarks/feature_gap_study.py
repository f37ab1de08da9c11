"""How near may two features stand before they read each other? The 3-D check of two stations
whose features are ``gap`` section sizes apart, over the same two stations far apart.

The corrections of docs/model.md §7 were fitted to beams whose two features stand
``checks.study.FAR_GAP`` (4) section sizes apart, each alone; a design may put them as close as
``limits.gauge_gap`` (2 mm by default), which on a large bar is a few hundredths of its size.
For one case of each feature family (the study's 6061-T6, BF350-3AA gauge and floor radius) this
solves the pair at each gap on the coarse mesh (whose gauge-strain ratios agree with the normal
mesh's within 0.1 % on the suite's largest bar) and prints each station's 3-D/model strain ratio
over the isolated pair's: the share by which the neighbour changes what a gauge reads. Run by
hand (about 10 minutes on 2 cores):

    python benchmarks/feature_gap_study.py [--gaps 0.05 0.1 0.2 0.3 0.5 1] [--mesh coarse]

Its figures: benchmarks/feature_gap_study.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

from designer.checks import study

# One representative case per family: mid-box depths and lengths of the study's pocket boxes
# (a 3 mm grid's pocket), a hole of half the height.
CASES = {
    "round flat": study.Case("round-pocket", diameter=20e-3, depth=3e-3, clamp_clearance=20e-3),
    "tube flat": study.Case("tube-pocket", diameter=20e-3, wall=3e-3, depth=1.5e-3, clamp_clearance=20e-3,
                            pocket_length=20e-3),
    "rectangle slot": study.Case("rectangle-pocket", width=10e-3, height=10e-3, depth=2e-3, clamp_clearance=10e-3),
    "rectangle hole": study.Case("rectangle-hole", width=12.7e-3, height=12.7e-3, hole=6e-3, clamp_clearance=12.7e-3),
}
ISOLATED = study.FAR_GAP
# Slots in bars wider than high (``--wide``): the study's 5.5 mm slot in bars WIDE_HEIGHT high and
# WIDE_WIDTHS wide, WIDE_DEPTHS of the height deep; gaps in heights (``Case.gap`` is in the larger
# of the height and the width).
WIDE_HEIGHT = 5e-3
WIDE_WIDTHS = (8e-3, 12e-3, 18e-3, 26e-3, 40e-3)
WIDE_DEPTHS = (0.15, 0.3)
WIDE_GAPS = (0.5, 1.0, 1.5, 2.0, 3.0)


def ratios(case: study.Case, gap: float, mesh: str) -> tuple[float, ...]:
    """The 3-D/model gauge-strain ratios of ``case``'s two stations with ``gap`` between features."""
    return study.model_ratios(dataclasses.replace(case, gap=gap), mesh)


def wide(mesh: str) -> None:
    """The table of slots in wide bars: each station's ratio over the isolated pair's, by gap."""
    print("| b × h (mm) | depth / h | gap (heights) | station 1 | station 2 |")
    print("|---|---:|---:|---:|---:|")
    for b in WIDE_WIDTHS:
        for depth in WIDE_DEPTHS:
            case = study.Case("rectangle-pocket", width=b, height=WIDE_HEIGHT, depth=depth * WIDE_HEIGHT,
                              clamp_clearance=max(b, WIDE_HEIGHT))
            alone = ratios(case, ISOLATED, mesh)
            for gap in WIDE_GAPS:
                near = ratios(case, gap * WIDE_HEIGHT / max(b, WIDE_HEIGHT), mesh)
                print(f"| {b * 1e3:g} × {WIDE_HEIGHT * 1e3:g} | {depth:g} | {gap:g} | {near[0] / alone[0]:.4f} | "
                      f"{near[1] / alone[1]:.4f} |", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gaps", type=float, nargs="+", default=[0.05, 0.1, 0.2, 0.3, 0.5, 1.0],
                        help="gaps between the features, in section sizes")
    parser.add_argument("--mesh", default="coarse", choices=("coarse", "normal", "fine"))
    parser.add_argument("--only", nargs="*", default=None, help=f"cases (of {', '.join(CASES)})")
    parser.add_argument("--wide", action="store_true", help="only the slots in bars wider than high, gaps in heights")
    args = parser.parse_args(argv)
    if args.wide:
        start = time.perf_counter()
        wide(args.mesh)
        print(f"study took {time.perf_counter() - start:.0f} s", file=sys.stderr)
        return 0
    names = args.only or list(CASES)
    print("| case | gap (sizes) | station 1: 3-D/model over the isolated pair's | station 2 |")
    print("|---|---:|---:|---:|")
    start = time.perf_counter()
    for name in names:
        alone = ratios(CASES[name], ISOLATED, args.mesh)
        print(f"| {name} | {ISOLATED:g} (alone: {alone[0]:.4f}, {alone[1]:.4f}) | 1 | 1 |", flush=True)
        for gap in sorted(args.gaps):
            near = ratios(CASES[name], gap, args.mesh)
            print(f"| {name} | {gap:g} | {near[0] / alone[0]:.4f} | {near[1] / alone[1]:.4f} |", flush=True)
    print(f"study took {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
