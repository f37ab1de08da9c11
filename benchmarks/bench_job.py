"""The main job's wall time, whole and by stage, on every optimiser example.

Per example, medians over ``--repeat`` runs of:

- the whole job as a user runs it: ``fpdesign optimize EXAMPLE -o DIR`` in a fresh process
  (CAD, plots, fronts and all), and with ``--no-cad --no-plots``;
- its stages, each timed in its own fresh process so that every one pays its own imports as
  the job does: the search (``search.optimize``), the trade-off fronts, the plots (PNG) and
  the CAD outputs (STEP, drawing and picture, which the job builds in a child process beside
  the fronts and the plots);
- and the start-up: ``fpdesign --help``.

With ``--suite``, instead: the whole job once on each spec of the bench suite (``fpdesign
bench``'s generated specs, seed 0), its time, and whether the folder holds exactly the files its
design.json lists (or, for a spec refused as it is read, that it said so in one line and wrote
nothing); then the median and the slowest. ``--seed N`` takes the suite generated from
seed N instead (specs it was not tuned on).

Run by hand:  python benchmarks/bench_job.py [--repeat 3] [--only NAME ...] [--suite [--seed N]]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
NAMES = ["gripper-finger", "weigh-bar", "probe", "prototype-b-optimized"]

# Each stage as a small program: it prints the seconds of its own work after its imports.
STAGE = '''
import json, sys, time, tempfile
t0 = time.perf_counter()
from designer.spec.reader import load_spec
from designer.search import optimize
spec = load_spec(sys.argv[1])
stage = sys.argv[2]
if stage == "search":
    optimize(spec)
elif stage == "fronts":
    from designer.search.tradeoff import fronts
    found = optimize(spec)
    t0 = time.perf_counter()
    if spec.objective == "error":  # the job draws fronts for the error objective only
        fronts(spec, found)
elif stage in ("plots", "cad"):
    from designer.result.pipeline import DesignOptions, design
    result = design(spec, DesignOptions(tradeoff=stage == "plots"))
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        if stage == "plots":
            from designer.outputs.plots import write_design_plots
            write_design_plots(result.record, tmp, tradeoff=result.tradeoff)
        else:
            from designer.outputs.cad.writer import write_cad_outputs
            write_cad_outputs(result.record, tmp)
print(json.dumps(time.perf_counter() - t0))
'''


def wall(args: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(args, check=True, capture_output=True)
    return time.perf_counter() - t0


def stage_seconds(example: Path, stage: str) -> float:
    """The stage's own work in a fresh process, its imports included (the search's and the
    stage's: what the job pays for it)."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", STAGE, str(example), stage], check=True, capture_output=True,
                         text=True).stdout
    total = time.perf_counter() - t0
    return json.loads(out.strip().splitlines()[-1]) if stage != "search" else total


def suite_jobs(cmd: list[str], seed: int | None = None) -> int:
    """The whole job on every generated spec of the bench suite (of ``seed``: the suite's own by
    default); 1 if a folder is not what its design.json says."""
    from designer.bench.suite import DEFAULT_SEED, generate_suite

    times, wrong = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for item in generate_suite(seed=DEFAULT_SEED if seed is None else seed):
            spec, out = Path(tmp) / f"{item.name}.yaml", Path(tmp) / item.name
            spec.write_text(item.text, encoding="utf-8")
            t0 = time.perf_counter()
            done = subprocess.run(cmd + ["optimize", str(spec), "-o", str(out), "--quiet"], capture_output=True)
            times.append((time.perf_counter() - t0, item.name))
            files = {f.name for f in out.iterdir()} if out.is_dir() else set()
            listed = set()
            if "design.json" in files:
                record = json.loads((out / "design.json").read_text(encoding="utf-8"))["files"]
                listed = {v for k, v in record.items() if k != "plots"} | set(record.get("plots", [])) | {"design.json"}
            said = done.stderr.decode(errors="replace").strip().splitlines()
            # exit 1 is a spec without a design that meets every limit: its folder is still written;
            # exit 2 a spec refused as it is read (one line, nothing written)
            refused = done.returncode == 2 and not out.exists() and len(said) == 1
            ok = refused or (done.returncode in (0, 1) and files == listed and "design.json" in files
                             and not any("Traceback" in line for line in said))
            if not ok:
                wrong.append(item.name)
            print(f"{item.name:28} exit {done.returncode}  {times[-1][0]:5.2f} s  {len(files):2} files"
                  f"{'  refused' if refused else '' if ok else '  NOT AS LISTED'}", flush=True)
            if said and (refused or not ok):
                print("    " + said[-1], flush=True)
    print(f"\n{len(times)} specs: median {statistics.median(t for t, _ in times):.2f} s, "
          f"{min(times)[0]:.2f}-{max(times)[0]:.2f} s (slowest {max(times)[1]}); "
          f"{len(wrong)} folders not as listed{': ' + ', '.join(wrong) if wrong else ''}")
    return 1 if wrong else 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--only", nargs="*", default=None)
    p.add_argument("--suite", action="store_true", help="the whole job on each of the bench suite's specs")
    p.add_argument("--seed", type=int, default=None, help="with --suite: the suite generated from this seed")
    args = p.parse_args(argv)
    names = args.only or NAMES
    cmd = [sys.executable, "-m", "designer.cli"]
    if args.suite:
        return suite_jobs(cmd, args.seed)
    rows = []
    for name in names:
        example = EXAMPLES / f"{name}.yaml"
        runs = {k: [] for k in ("job", "bare", "search", "fronts", "plots", "cad")}
        for _ in range(args.repeat):  # interleaved, so that every figure sees the same load
            with tempfile.TemporaryDirectory() as tmp:
                runs["job"].append(wall(cmd + ["optimize", str(example), "-o", f"{tmp}/a", "--quiet"]))
                runs["bare"].append(wall(cmd + ["optimize", str(example), "-o", f"{tmp}/b", "--quiet", "--no-cad",
                                                "--no-plots"]))
            for stage in ("search", "fronts", "plots", "cad"):
                runs[stage].append(stage_seconds(example, stage))
        med = {k: statistics.median(v) for k, v in runs.items()}
        rows.append((name, med))
        print(f"{name:24} job {med['job']:.2f} s  (no CAD, no plots {med['bare']:.2f} s)  search+start {med['search']:.2f}  "
              f"fronts {med['fronts']:.2f}  plots {med['plots']:.2f}  CAD {med['cad']:.2f} (child process)", flush=True)
    help_s = statistics.median(wall(cmd + ["--help"]) for _ in range(max(args.repeat, 5)))
    print()
    print("| example | whole job (s) | no CAD, no plots (s) | start-up + search (s) | fronts (s) | plots (s) | "
          "CAD, in a child process (s) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, m in rows:
        print(f"| {name} | {m['job']:.2f} | {m['bare']:.2f} | {m['search']:.2f} | {m['fronts']:.2f} | {m['plots']:.2f} "
              f"| {m['cad']:.2f} |")
    print(f"\n`fpdesign --help`: {help_s:.2f} s (median). Medians of {args.repeat} runs, interleaved.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
