"""Speed and accuracy of `fpdesign optimize` on every optimiser example.

Prints, per example: the median compute time of a full search (all materials x three
families, after start-up, in this process) with the shipped feature corrections
(docs/model.md §7) and without them (an empty table), run alternately so that both see the
same machine load, their ratio, the objective against the exhaustive reference search
(reference.reference_best: a dense grid polished by scipy, no casadi), and the start-up time of
the command (`fpdesign --help` and the imports an optimise run needs), measured separately.
Run by hand:  python benchmarks/bench_optimize.py [--repeat 5] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path
from unittest import mock

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
NAMES = ["gripper-finger", "weigh-bar", "probe", "prototype-b-optimized"]


def startup_seconds(repeat: int) -> tuple[float, float]:
    """Median wall time of `fpdesign --help`, and of importing what an optimise run loads."""
    help_runs, import_runs = [], []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "designer.cli", "--help"], check=True, capture_output=True)
        help_runs.append(time.perf_counter() - t)
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c",
                        "import designer.search, casadi, nlopt; from designer.spec import units; units.registry()"],
                       check=True, capture_output=True)
        import_runs.append(time.perf_counter() - t)
    return statistics.median(help_runs), statistics.median(import_runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--levels", type=int, default=7, help="grid levels of the reference search")
    parser.add_argument("--only", nargs="*", default=None, choices=NAMES, help="only these examples")
    args = parser.parse_args()

    from designer.model import corrections
    from designer.search import optimize, reference
    from designer.spec.reader import load_spec

    shipped = corrections.load()
    plain = corrections.Corrections({})

    def run(spec, table):
        with mock.patch.object(corrections, "load", lambda: table):
            return optimize(spec)

    print(f"{'example':24} {'candidates':>10} {'median s':>9} {'plain s':>8} {'ratio':>6} {'objective':>11} "
          f"{'reference':>11} {'gap':>8}  chosen")
    ratios = []
    for name in args.only or NAMES:
        spec = load_spec(EXAMPLES / f"{name}.yaml")
        run(spec, shipped)  # warm: casadi and IPOPT loaded, as after start-up
        run(spec, plain)
        times, plain_times = [], []
        for _ in range(args.repeat):
            outcome = run(spec, shipped)
            times.append(outcome.seconds)
            plain_times.append(run(spec, plain).seconds)
        ref = reference.reference_best(spec, levels=args.levels)
        gap = outcome.best.objective / ref.objective - 1
        ratio = statistics.median(times) / statistics.median(plain_times)
        ratios.append(ratio)
        print(f"{name:24} {len(outcome.candidates):>10} {statistics.median(times):>9.3f} "
              f"{statistics.median(plain_times):>8.3f} {ratio:>6.2f} {outcome.best.objective:>11.6g} "
              f"{ref.objective:>11.6g} {gap:>+8.3%}  {outcome.best.design.label()}")
    print(f"time with the corrections / without: median {statistics.median(ratios):.2f}, largest {max(ratios):.2f}")
    help_s, import_s = startup_seconds(args.repeat)
    print(f"start-up: `fpdesign --help` {help_s:.3f} s; importing the optimiser, casadi, nlopt and pint {import_s:.3f} s "
          "(medians)")


if __name__ == "__main__":
    main()
