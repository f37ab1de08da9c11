"""Benchmark: is the advice of an infeasible spec's diagnosis true? On every spec of the bench
suite (``fpdesign bench``'s generated specs, one or more seeds) that no design meets, each figure
the diagnosis names is followed and the search run again:

- ``every limit it breaks grows with the largest force: at load.force[1] = F N``: the closest
  design meets every limit under the spec with that largest force (beam theory's scaling: each of
  those limits is proportional to the force), and the search finds a design there;
- ``they would be met with electronics noise of at most V mV at the output`` when the closest
  design breaks nothing but the targets (and the noise is the spec's own, not a catalogue
  front-end's): that design meets every limit with that noise, and so does the search;
- ``from load.position[0] = X mm, a <material> ... meets every limit``: the search over that
  material finds a design with the load region from there;
- ``with limits.max_deflection = Y mm a <material> ... meets every limit`` (or
  ``limits.min_frequency = f Hz``): the search over that material finds a design under that limit;
- ``with search.feature: none (...) a <material> ... meets every limit``: the search over that
  material, without a feature, finds a design.

    python benchmarks/diagnosis_check.py [--seeds 0 1 2] [--count 50] [--out benchmarks/diagnosis_check.md]
"""

from __future__ import annotations

import argparse
import platform
import re
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from designer import model  # noqa: E402
from designer.bench.suite import generate_suite  # noqa: E402
from designer.errors import FpdError  # noqa: E402
from designer.outputs.files import atomic_write_text  # noqa: E402
from designer.result.evaluation import evaluate  # noqa: E402
from designer.search import optimize  # noqa: E402

FORCE = re.compile(r"every limit it breaks grows with the largest force: at load\.force\[1\] = ([0-9.e+-]+) N")
NOISE = re.compile(r"electronics noise of at most ([0-9.e+-]+) mV at the output")
REGION = re.compile(r"from load\.position\[0\] = ([0-9.e+-]+) mm, a (\S+) ")
LOOSER = re.compile(r"with limits\.max_deflection = ([0-9.e+-]+) mm a (\S+) ")
HIGHER = re.compile(r"with limits\.min_frequency = ([0-9.e+-]+) Hz a (\S+) ")
PLAIN = re.compile(r"with search\.feature: none \([^)]*\) a (\S+) ")


def check(spec) -> list[dict]:
    """The diagnosis of ``spec`` followed: one row per figure it names (none when it is feasible)."""
    found = optimize(spec)
    if found.success:
        return []
    text, best, rows = " ".join(found.messages), found.best, []
    if m := FORCE.search(text):
        force = float(m.group(1))
        at = replace(spec, load=replace(spec.load, force_max=force))
        rows.append({"advice": f"load.force[1] = {force:.4g} N", "design": evaluate(best.design, at).feasible,
                     "search": optimize(at).success})
    broken = {v.name for v in best.violations}
    if (m := NOISE.search(text)) and broken <= set(model.TARGET_LIMITS) and spec.electronics.adc is None:
        noise = float(m.group(1)) * 1e-3
        quiet = replace(spec, electronics=replace(spec.electronics, noise=noise, noise_rti=None, noise_strain=None))
        rows.append({"advice": f"noise {noise * 1e3:.3g} mV", "design": evaluate(best.design, quiet).feasible,
                     "search": optimize(quiet).success})
    if m := REGION.search(text):
        start = float(m.group(1)) * 1e-3
        rows.append(_searched(spec, m.group(2), f"load.position[0] = {start * 1e3:.4g} mm",
                              load=replace(spec.load, position_min=start)))
    if m := LOOSER.search(text):
        level = float(m.group(1)) * 1e-3
        rows.append(_searched(spec, m.group(2), f"limits.max_deflection = {level * 1e3:.3g} mm",
                              limits=replace(spec.limits, max_deflection=level)))
    if m := HIGHER.search(text):
        level = float(m.group(1))
        rows.append(_searched(spec, m.group(2), f"limits.min_frequency = {level:.4g} Hz",
                              limits=replace(spec.limits, min_frequency=level)))
    if m := PLAIN.search(text):
        rows.append(_searched(spec, m.group(1), "search.feature: none",
                              search=replace(spec.search, feature="none", materials=(m.group(1),))))
    return rows


def _searched(spec, material: str, advice: str, **change) -> dict:
    """The row of advice naming a design of ``material`` under ``spec`` changed (``change``): whether
    the search over that material finds a design there."""
    moved = replace(spec, **{"search": replace(spec.search, materials=(material,)), **change})
    return {"advice": f"{advice} ({material})", "design": None, "search": optimize(moved).success}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--count", type=int, default=50)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    lines = ["| spec | advice | the closest design meets every limit | the search finds a design |",
             "|---|---|---|---|"]
    told = held = specs = 0
    t0 = time.perf_counter()
    for seed in args.seeds:
        for s in generate_suite(args.count, seed):
            try:
                rows = check(s.spec)
            except FpdError as exc:   # a spec the search refuses (no room for the stations): no advice to follow
                print(f"s{seed}:{s.name}: {type(exc).__name__}: {str(exc)[:80]}", flush=True)
                continue
            specs += bool(rows)
            for r in rows:
                told += 1
                ok = r["search"] and r["design"] is not False
                held += ok
                design = "-" if r["design"] is None else ("yes" if r["design"] else "**no**")
                lines.append(f"| s{seed}:{s.name} | {r['advice']} | {design} | {'yes' if r['search'] else '**no**'} |")
                print(lines[-1], flush=True)
    summary = (f"{held} of {told} figures named by the diagnoses of {specs} infeasible specs hold "
               f"(seeds {', '.join(map(str, args.seeds))}, {args.count} specs each; "
               f"{time.perf_counter() - t0:.0f} s on {platform.machine()})")
    print(summary)
    if args.out is not None:
        atomic_write_text(args.out, "# The diagnosis's advice, followed\n\n" + summary + ".\n\n" + "\n".join(lines)
                          + "\n")
    return 0 if held == told else 1


if __name__ == "__main__":
    sys.exit(main())
