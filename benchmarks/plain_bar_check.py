"""Benchmark: what a pocket (or a hole) costs. Every optimiser example and every spec of the bench
suite (one or more seeds) that asks for a feature is searched as it is and again with
``search.feature: none`` (the gauges bonded on the bar's own faces), and the two answers are set
side by side: the objective of each (error ratio, mass or deflection), and which of them meets
every limit.

The search names the plain bar to a spec no design with its feature meets (docs/model.md §5,
``remedies.plain``); this measures how the two compare where both have a design, which the
search does not report (the spec's feature is the user's choice: a pocket recesses and protects
its gauge).

    python benchmarks/plain_bar_check.py [--seeds 0 14] [--count 50] [-o benchmarks/plain_bar_check.md]
"""

from __future__ import annotations

import argparse
import platform
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from designer.bench.suite import generate_suite  # noqa: E402
from designer.errors import FpdError  # noqa: E402
from designer.outputs.files import atomic_write_text  # noqa: E402
from designer.search import optimize  # noqa: E402
from designer.spec.reader import load_spec  # noqa: E402


def _searched(spec):
    """The search's answer, or None when it refuses the spec."""
    try:
        return optimize(spec, closest=False)
    except FpdError:
        return None


def specs(seeds, count: int):
    """(name, spec) of the optimiser examples, then of the bench suite's specs of each seed."""
    for path in sorted((ROOT / "examples").glob("*.yaml")):
        spec = load_spec(path)
        if spec.design is None:
            yield path.stem, spec
    for seed in seeds:
        for item in generate_suite(count, seed):
            yield f"s{seed}:{item.name}", item.spec


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 14])
    parser.add_argument("--count", type=int, default=50)
    parser.add_argument("-o", "--out", type=Path, default=None)
    args = parser.parse_args(argv)
    lines = ["| spec | objective | with its feature | objective | plain bar | objective | plain / feature |",
             "|---|---|---|---:|---|---:|---:|"]
    ratios: dict[str, list[float]] = {}
    only_plain = only_feature = neither = 0
    t0 = time.perf_counter()
    for name, spec in specs(args.seeds, args.count):
        if spec.search.feature == "none":
            continue
        with_feature = _searched(spec)
        plain = _searched(replace(spec, search=replace(spec.search, feature="none")))
        a = with_feature is not None and with_feature.success
        b = plain is not None and plain.success
        if not a and not b:
            neither += 1
            continue
        only_plain += b and not a
        only_feature += a and not b
        cells = [f"{r.best.design.label()} | {r.best.objective:.4g}" if ok else "no design | -"
                 for r, ok in ((with_feature, a), (plain, b))]
        ratio = "-"
        if a and b:
            value = plain.best.objective / with_feature.best.objective
            ratios.setdefault(spec.objective, []).append(value)
            ratio = f"{value:.3f}"
        lines.append(f"| {name} | {spec.objective} | {cells[0]} | {cells[1]} | {ratio} |")
        print(lines[-1], flush=True)
    summary = [f"The optimiser examples and seeds {', '.join(map(str, args.seeds))}, {args.count} specs each, those "
               "asking for a feature; "
               f"{time.perf_counter() - t0:.0f} s on {platform.machine()}.", ""]
    for objective, values in sorted(ratios.items()):
        better = sum(v < 1 - 1e-3 for v in values)
        summary.append(f"- objective {objective}: both have a design on {len(values)} specs; the plain bar's "
                       f"objective is lower on {better}, median {statistics.median(values):.3f} of the feature's "
                       f"({min(values):.3f}-{max(values):.3f})")
    summary.append(f"- only the plain bar has a design: {only_plain} specs; only the feature: {only_feature}; "
                   f"neither: {neither}")
    print("\n".join(summary))
    if args.out is not None:
        atomic_write_text(args.out, "# What a pocket costs: each spec with its feature and as a plain bar\n\n"
                          + "\n".join(summary) + "\n\n" + "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
