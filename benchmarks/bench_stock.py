"""Benchmark: the stock search (``search: {stock: metric | imperial}``) on every optimiser example,
against brute force over the whole stock catalogue.

For each example and system it times ``optimize`` (the whole search: every material x section
family on stock, median of ``--repeat`` runs after a warm-up) and compares its objective with the
reference: every row of every table of every material's family solved on its own with its
section held, rounded and checked (``search.stock.brute_force``), the best that meets every
limit. The gap is the search's objective over the reference's, minus one; within the 0.1 % tie
band (docs/model.md §5) it counts as a match.

    python benchmarks/bench_stock.py [--repeat 3] [--only NAME ...] [--out benchmarks/bench_stock.md]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from designer.model import TIE_TOLERANCE  # noqa: E402
from designer.outputs.files import atomic_write_text  # noqa: E402
from designer.search import optimize  # noqa: E402
from designer.search.problem import FamilyProblem, families  # noqa: E402
from designer.search.problem import start_from
from designer.search.run import solve_candidate  # noqa: E402
from designer.search.stock import brute_force  # noqa: E402
from designer.spec import catalogue, strict_yaml  # noqa: E402
from designer.spec.reader import parse_spec  # noqa: E402

EXAMPLES = ("gripper-finger", "weigh-bar", "probe", "prototype-b-optimized")
SYSTEMS = ("metric", "imperial")


def spec_on_stock(name: str, system: str):
    raw = strict_yaml.load((ROOT / "examples" / f"{name}.yaml").read_text())
    raw.setdefault("search", {})
    raw["search"] = dict(raw["search"] or {}, stock=system)
    return parse_spec(raw, default_name=name, folder=ROOT / "examples")


def reference(spec) -> tuple[float | None, str, int]:
    """The best objective over every row (brute force), the design's label and the rows solved."""
    best, label, solved = None, "", 0
    for family in families(spec):
        problem = FamilyProblem(spec, family)
        for name in spec.search.materials:
            material = catalogue.material(name)
            continuous = solve_candidate(problem, material, "ipopt").evaluation
            x0 = start_from(problem, continuous) if continuous is not None else problem.starts()[0]
            for item, ev in brute_force(problem, material, x0):
                solved += 1
                if ev is not None and ev.feasible and (best is None or ev.objective < best):
                    best, label = ev.objective, f"{name} {item.label}"
    return best, label, solved


def bench(names, repeat: int) -> list[dict]:
    rows = []
    for name in names:
        for system in SYSTEMS:
            spec = spec_on_stock(name, system)
            optimize(spec)                                   # warm-up: imports, casadi's functions
            times, found = [], None
            for _ in range(repeat):
                start = time.perf_counter()
                found = optimize(spec)
                times.append(time.perf_counter() - start)
            start = time.perf_counter()
            ref, ref_label, solved = reference(spec)
            ref_time = time.perf_counter() - start
            best = found.best if found.best is not None and found.best.feasible else None
            row = {"name": name, "system": system, "seconds": statistics.median(times), "runs": times,
                   "objective": best.objective if best else None,
                   "design": f"{best.design.material.name} {best.design.stock.label}" if best else "none",
                   "reference": ref, "reference_design": ref_label, "rows": solved, "reference_seconds": ref_time}
            row["gap"] = (row["objective"] / ref - 1) if best and ref else None
            rows.append(row)
            gap = "-" if row["gap"] is None else f"{row['gap']:+.3%}"
            print(f"{name} {system}: {row['seconds']:.2f} s, {row['design']}, gap {gap} "
                  f"(reference: {solved} rows in {ref_time:.0f} s)", file=sys.stderr)
    return rows


def table(rows: list[dict], repeat: int) -> str:
    lines = ["The stock search against brute force over the whole catalogue (`python benchmarks/bench_stock.py`): "
             f"time of `optimize` with `search.stock` (median of {repeat} runs in one process, after a warm-up), "
             "its design, and its objective over the best of every row solved on its own (within the "
             f"{TIE_TOLERANCE:.1%} tie band: a match).", "",
             "| example | stock | time (s) | design | objective | brute force: best | rows | gap | match |",
             "|---|---|---:|---|---:|---|---:|---:|:-:|"]
    for r in rows:
        objective = "-" if r["objective"] is None else f"{r['objective']:.6g}"
        best = "none" if r["reference"] is None else f"{r['reference']:.6g} ({r['reference_design']})"
        gap = "-" if r["gap"] is None else f"{r['gap']:+.3%}"
        match = (r["gap"] is not None and r["gap"] <= TIE_TOLERANCE) or (r["objective"] is None and r["reference"] is None)
        lines.append(f"| {r['name']} | {r['system']} | {r['seconds']:.2f} | {r['design']} | {objective} | {best} | "
                     f"{r['rows']} | {gap} | {'yes' if match else 'NO'} |")
    lines += ["", f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}. "
              "The machine may be shared: compare runs made in one session.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per example and system [3]")
    parser.add_argument("--only", nargs="*", default=None, help=f"examples to run (of {', '.join(EXAMPLES)})")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "bench_stock.md"))
    args = parser.parse_args(argv)
    names = args.only or EXAMPLES
    unknown = [n for n in names if n not in EXAMPLES]
    if unknown:
        parser.error(f"--only: {unknown[0]!r} is not an optimiser example; must be one of {', '.join(EXAMPLES)}")
    text = table(bench(names, args.repeat), args.repeat)
    atomic_write_text(Path(args.out), text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
