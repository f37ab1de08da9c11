"""Benchmark: wall time and peak memory of `fpdesign verify` on every example's design.

For each example it makes the design once (``evaluate`` for the fixed-design prototypes,
``optimize --no-cad`` for the optimiser examples), then runs ``fpdesign verify DESIGN --mesh M``
``--repeat`` times, each in a fresh subprocess, and reports the median wall time, the largest
peak resident set size of the run and of any process it started (``ru_maxrss`` of the waited-for
children, read after each run in a fresh measuring process so that runs do not mask each
other) and the peak of the whole process tree's summed memory, and the figures of the check: the gauge-strain and deflection ratios to the beam model,
the peak stress ratio and the mesh-convergence changes.

    python benchmarks/bench_verify.py [--mesh normal] [--repeat 3] [--only NAME ...]
                                      [--suite NAME ...] [--out benchmarks/bench_verify.md] [--work DIR]

``--suite`` adds specs of the bench suite (``fpdesign bench``'s, seed 0) by name. ``--large`` adds
``large-round-bar``, a fixed design: the bench suite's 035-kilonewton as it was designed before
pockets were held to 4 gauge grids long (docs/model.md §7), a 789 mm bar of Ø87 mm with R0.2 mm
flats 34.9 mm long, whose check is the largest any design of the suite has asked for (outside the
model's domain, ``evaluate`` reports it infeasible; ``verify`` checks it all the same).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FIXED = ("prototype-a", "prototype-b", "prototype-b-inner", "prototype-c")
OPTIMISED = ("gripper-finger", "weigh-bar", "probe", "prototype-b-optimized")
EXAMPLES = FIXED + OPTIMISED
SUITE_COUNT = 50    # the bench suite's specs that --suite may name
LARGE = "large-round-bar"
LARGE_SPEC = """\
name: large-round-bar
load: {force: [126.5 N, 2.514 kN], position: [363.6 mm, 783.6 mm]}
electronics: {excitation: 2.5 V, gain: 500, noise_rti: 218.2 nV}
gauge: CEA-06-125UW-120
bridge: half
limits: {width: [18.9 mm, 230.1 mm], height: [18.9 mm, 182.1 mm], min_pocket_depth: 0.5 mm, min_wall: 1 mm,
         max_deflection: 15.67 mm}
targets: {force_error: 1.7 %, position_error: 8.431 mm}
tolerances: {class: none}
design:
  material: 2024-T3
  section: {kind: round, diameter: 87.26 mm}
  stations: [26.32 mm, 262.59 mm, 341.14 mm]
  feature: {kind: pocket, depth: 4.85 mm, length: 34.91 mm, width: 8.4 mm}
  length: 788.6 mm
"""
# A run is measured by a small Python parent that starts the command, waits for it and reads its
# children's rusage: ru_maxrss of RUSAGE_CHILDREN is the largest peak of any process waited for
# (verify, the child that builds its STEP and the one that solves the convergence mesh), in kB on
# Linux. Meanwhile it sums the resident memory of the whole process tree every 20 ms from /proc
# (Linux): the convergence mesh is solved beside the requested one, so their sum is what the
# machine must hold (0 where /proc is not there).
MEASURE = """
import os, resource, subprocess, sys, time

def tree(pid):
    total, stack = 0, [pid]
    while stack:
        p = stack.pop()
        try:
            with open(f"/proc/{p}/status") as f:
                total += next((int(line.split()[1]) for line in f if line.startswith("VmRSS:")), 0)
            with open(f"/proc/{p}/task/{p}/children") as f:
                stack += [int(c) for c in f.read().split()]
        except OSError:
            pass
    return total

t = time.perf_counter()
proc = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL)
peak = 0
while proc.poll() is None:
    peak = max(peak, tree(proc.pid))
    time.sleep(0.02)
print(proc.returncode, time.perf_counter() - t, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, peak)
"""


def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def make_design(name: str, work: Path, suite: dict) -> Path:
    """The example's, or the bench suite's spec's (``suite``: name -> spec text), design.json (made
    once and reused)."""
    out = work / name
    design = out / "design.json"
    if design.is_file():
        return design
    example = ROOT / "examples" / f"{name}.yaml"
    if name in suite:       # a spec of the bench suite, written beside its design
        example = work / f"{name}.yaml"
        example.write_text(suite[name], encoding="utf-8")
    if name == LARGE:
        example = work / f"{name}.yaml"
        example.write_text(LARGE_SPEC, encoding="utf-8")
    if name in FIXED or name == LARGE:
        cmd = ["evaluate", str(example), "-o", str(out), "--no-plots"]
    else:
        cmd = ["optimize", str(example), "-o", str(out), "--no-plots", "--quiet", "--no-cad"]
    subprocess.run([sys.executable, "-m", "designer.cli", *cmd], check=False, env=_env(),
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    if not design.is_file():
        raise SystemExit(f"{name}: no design.json was written by `fpdesign {cmd[0]}`")
    return design


def measure(design: Path, mesh: str, out: Path) -> tuple[int, float, float, float]:
    """One verify run in a fresh process: exit code, wall seconds, the largest process's peak RSS
    and the process tree's peak summed RSS (MB)."""
    cmd = [sys.executable, "-m", "designer.cli", "verify", str(design), "--mesh", mesh, "-o", str(out)]
    done = subprocess.run([sys.executable, "-c", MEASURE, *cmd], capture_output=True, text=True, env=_env())
    code, seconds, kb, tree_kb = done.stdout.split()
    return int(code), float(seconds), float(kb) / 1024, float(tree_kb) / 1024


def bench(names, mesh: str, repeat: int, work: Path, suite: dict) -> list[dict]:
    rows = []
    for name in names:
        design = make_design(name, work, suite)
        times, peaks, trees, code = [], [], [], 0
        out = work / f"{name}-verify"
        report = out / "verify.json"
        for _ in range(repeat):
            report.unlink(missing_ok=True)     # a failed run leaves no figures of an earlier one behind
            code, seconds, mb, tree_mb = measure(design, mesh, out)
            times.append(seconds)
            peaks.append(mb)
            trees.append(tree_mb)
        row = {"name": name, "code": code, "seconds": statistics.median(times), "runs": times, "rss": max(peaks),
               "tree": max(trees)}
        if report.is_file():
            r = json.loads(report.read_text())
            stress = r["stress"]
            row.update(ratios=[g["ratio"] for g in r["gauges"]], deflection=r["deflection"]["ratio"],
                       stress=stress["fea_peak"] / stress["model_at_peak"], where=stress["where"],
                       change=max(g["mesh_change"] for g in r["gauges"]),
                       deflection_change=r["deflection"]["mesh_change"], stress_change=stress["mesh_change"],
                       meshes=[(m["elements"], m["dofs"], m["cg_iterations"]) for m in r["meshes"]])
        rows.append(row)
        print(f"{name}: {row['seconds']:.1f} s (runs {', '.join(f'{t:.1f}' for t in times)}), {row['rss']:.0f} MB, "
              f"all processes {row['tree']:.0f} MB",
              file=sys.stderr)
    return rows


def table(rows: list[dict], mesh: str, repeat: int) -> str:
    lines = [f"`fpdesign verify --mesh {mesh}` on each design: median wall time of {repeat} run(s), each "
             "in a fresh process; the largest peak resident memory of one process (the run, the process it "
             "starts to build the STEP solid, or the one that solves the convergence mesh beside it), and the "
             "peak of their sum (sampled every 20 ms).", "",
             "| design | time (s) | peak RSS (MB) | all processes (MB) | gauge strain FEA/model | deflection FEA/model "
             "| peak stress FEA/model (where) | change on the 1.5x coarser mesh: strain, deflection, stress "
             "| elements, unknowns, CG iterations (run; convergence mesh) |",
             "|---|---:|---:|---:|---|---:|---|---|---|"]
    for r in rows:
        if "ratios" not in r:
            lines.append(f"| {r['name']} | {r['seconds']:.1f} | {r['rss']:.0f} | {r['tree']:.0f} | failed (exit {r['code']}) "
                         "| | | | |")
            continue
        meshes = "; ".join(f"{e}, {d}, {i}" for e, d, i in r["meshes"])
        lines.append(f"| {r['name']} | {r['seconds']:.1f} | {r['rss']:.0f} | {r['tree']:.0f} | "
                     f"{', '.join(f'{q:.3f}' for q in r['ratios'])} | {r['deflection']:.3f} | "
                     f"{r['stress']:.2f} ({r['where']}) | {r['change']:.2%}, {r['deflection_change']:.2%}, "
                     f"{r['stress_change']:.1%} | {meshes} |")
    lines += ["", f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}; "
              "times include starting Python, building the CAD solid, meshing and solving both meshes, and "
              "writing the report. The machine may be shared: compare runs made in one session.", ""]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("--repeat", type=int, default=3, help="runs per example; the median time is reported [3]")
    parser.add_argument("--only", nargs="*", default=None, help=f"examples to run (of {', '.join(EXAMPLES)})")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "bench_verify.md"))
    parser.add_argument("--suite", nargs="*", default=[], metavar="NAME",
                        help="specs of the bench suite to run as well, such as 024-kilonewton")
    parser.add_argument("--large", action="store_true", help=f"run {LARGE} as well (see above)")
    parser.add_argument("--work", default=None, help="folder for the designs and reports [a temporary folder]")
    args = parser.parse_args(argv)
    names = list(args.only or ([] if args.suite or args.large else EXAMPLES))
    unknown = sorted(set(names) - set(EXAMPLES))
    if unknown:
        parser.error(f"unknown example(s): {', '.join(unknown)}")
    suite = {}
    if args.suite:
        from designer.bench import generate_suite

        known = {s.name: s.text for s in generate_suite(SUITE_COUNT)}
        unknown = sorted(set(args.suite) - set(known))
        if unknown:
            parser.error(f"unknown suite spec(s): {', '.join(unknown)}; the suite's are {', '.join(known)}")
        suite = {name: known[name] for name in args.suite}
        names += args.suite
    if args.large:
        names.append(LARGE)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench-verify-") as tmp:
        work = Path(args.work) if args.work else Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        text = table(bench(names, args.mesh, max(1, args.repeat), work, suite), args.mesh, max(1, args.repeat))
    print(text)
    print(f"benchmark took {time.perf_counter() - start:.0f} s", file=sys.stderr)
    if args.out:
        Path(args.out).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
