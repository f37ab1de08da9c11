"""The bench's files: bench.md, bench.png, the stability tables, runs.csv, specs.csv and the suite."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

from designer.bench.figure import chart, chart_data
from designer.bench.run import FAILURE_KINDS, BenchResult, exact_gap, failures, gap, raw_gap
from designer.bench.summary import markdown, stability_markdown, stability_rows
from designer.errors import InputError


def _num(value) -> str:
    return "" if value is None else (repr(float(value)) if not math.isinf(value) else "inf")


def stability_csv(result: BenchResult, rows=None) -> str:
    rows = rows or stability_rows(result)
    buf = io.StringIO()
    keys = ["method", "kind", "specs", "feasible_specs", *FAILURE_KINDS, "pipeline_failures",
            "solves", "false_successes", "rounding_breaks", "solver_exceptions", "fallback_solves", "median_gap"]
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (_num(r[k]) if k == "median_gap" else r[k]) for k in keys})
    return buf.getvalue()


def runs_csv(result: BenchResult) -> str:
    buf = io.StringIO()
    keys = ["spec", "kind", "method", "seconds", "status", "objective", "gap", "exact_gap", "raw_objective",
            "raw_gap", "worst_violation", "violated", "design", "deflection", "mass", "candidates", "solves",
            "solver_successes", "false_successes", "rounding_breaks", "solver_exceptions", "fallback_solves",
            "fallbacks",
            "evaluations", *FAILURE_KINDS, "error", "unreadable_reason"]
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for r in result.runs:
        t = result.truth(r)
        f = failures(r, t)
        w.writerow({"spec": r.spec, "kind": r.kind, "method": r.method, "seconds": f"{r.seconds:.4f}",
                    "status": r.status, "objective": _num(r.objective), "gap": _num(gap(r, t)),
                    "exact_gap": _num(exact_gap(r, t)), "raw_objective": _num(r.raw_objective),
                    "raw_gap": _num(raw_gap(r, t)), "worst_violation": _num(r.worst_violation),
                    "violated": " ".join(r.violated), "design": r.design, "deflection": _num(r.deflection),
                    "mass": _num(r.mass), "candidates": r.candidates, "solves": r.solves,
                    "solver_successes": r.solver_successes, "false_successes": r.false_successes,
                    "rounding_breaks": r.rounding_breaks,
                    "solver_exceptions": r.solver_exceptions, "fallback_solves": r.fallback_solves,
                    "fallbacks": r.fallbacks, "evaluations": r.evaluations, **f, "error": r.error,
                    "unreadable_reason": r.unreadable})
    return buf.getvalue()


def specs_csv(result: BenchResult) -> str:
    buf = io.StringIO()
    keys = ["spec", "kind", "objective", "expected", "verdict", "lead_objective", "best_objective", "best_by",
            "reference_objective", "reference_feasible", "reference_seconds"]
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for item in result.suite:
        t = result.truths[item.name]
        w.writerow({"spec": t.spec, "kind": t.kind, "objective": t.objective, "expected": t.expected or "",
                    "verdict": t.verdict, "lead_objective": _num(t.lead), "best_objective": _num(t.best),
                    "best_by": t.best_by, "reference_objective": _num(t.reference),
                    "reference_feasible": t.reference_feasible, "reference_seconds": f"{t.reference_seconds:.4f}"})
    return buf.getvalue()


def write_bench(result: BenchResult, out_dir) -> list[Path]:
    """bench.md, bench.png, stability.md, stability.csv, runs.csv, specs.csv and suite/*.yaml, all
    or nothing."""
    from designer.outputs.files import atomic_write_bytes, atomic_write_text, staged_directory

    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"-o: {out_dir} is a file, not a folder; give a folder for the bench's files")
    names = []
    with staged_directory(out_dir) as scratch:
        fig = chart(chart_data(result))
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=150)
        atomic_write_bytes(scratch / "bench.png", buf.getvalue())
        files = {"bench.md": markdown(result, "bench.png"),
                 "stability.md": "# Stability: failures per method and kind of spec\n\n" + stability_markdown(result)
                 + "\n", "stability.csv": stability_csv(result), "runs.csv": runs_csv(result),
                 "specs.csv": specs_csv(result)}
        for name, text in files.items():
            atomic_write_text(scratch / name, text)
        for item in result.suite:
            if item.kind != "example":
                atomic_write_text(scratch / "suite" / f"{item.name}.yaml", item.text)
        names = sorted(p.relative_to(scratch) for p in scratch.rglob("*") if p.is_file())
    return [out_dir / n for n in names]

