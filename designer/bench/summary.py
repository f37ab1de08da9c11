"""The bench's summaries: per method and per kind of spec, every failure, and bench.md."""

from __future__ import annotations

import math
import statistics

import numpy as np

from designer import model
from designer.bench.run import FAILURE_KINDS, SOLVER_TOLERANCE, BenchResult, exact_gap, failures, gap, raw_gap
from designer.bench.suite import KIND_NOTES

SPREAD = (25, 75)              # percentiles of the spread bars


# --------------------------------------------------------------------------- per method, per kind

def _median(values):
    return statistics.median(values) if values else None


def _percentile(values, q):
    """A percentile that is one of the values (inf allowed: a run without a design)."""
    if not values:
        return None
    return float(np.percentile(np.asarray(values, dtype=float), q, method="inverted_cdf"))


def method_summary(result: BenchResult) -> list[dict]:
    """Per method: medians and spreads of time and gap, counts of every failure, and whether its
    (median time, 90th-percentile gap) point is on the speed-accuracy front.

    The gap's median is 0 for every method that finds the best design on most specs, so it
    cannot tell them apart; the 90th percentile says how far off the method's bad answers are.
    ``on_median_front`` records the front of (median time, median gap) as well."""
    rows = []
    for m in result.methods:
        runs = [r for r in result.runs if r.method == m]
        feasible_runs = [r for r in runs if result.truth(r).feasible]
        times = [r.seconds for r in runs]
        gaps = [gap(r, result.truth(r)) for r in feasible_runs]
        raw = [raw_gap(r, result.truth(r)) for r in feasible_runs]
        exact = [g for g in (exact_gap(r, result.truth(r)) for r in feasible_runs) if g is not None]
        fails = [failures(r, result.truth(r)) for r in runs]
        rows.append({
            "method": m, "specs": len(runs), "feasible_specs": len(feasible_runs),
            "median_seconds": _median(times), "seconds_low": _percentile(times, SPREAD[0]),
            "seconds_high": _percentile(times, SPREAD[1]), "total_seconds": sum(times),
            "median_gap": _median_gap(gaps), "gap_low": _percentile(gaps, SPREAD[0]),
            "gap_high": _percentile(gaps, SPREAD[1]), "p90_gap": _percentile(gaps, 90),
            "mean_exact_gap": statistics.fmean(exact) if exact else None,
            "at_best": sum(1 for g in gaps if g == 0), "raw_median_gap": _median_gap(raw),
            "raw_at_best": sum(1 for g in raw if g == 0),
            "exception": sum(f["exception"] for f in fails), "violating": sum(f["violating"] for f in fails),
            "missed": sum(f["missed"] for f in fails), "unreadable": sum(f["unreadable"] for f in fails),
            "solves": sum(r.solves for r in runs), "solver_successes": sum(r.solver_successes for r in runs),
            "false_successes": sum(r.false_successes for r in runs),
            "rounding_breaks": sum(r.rounding_breaks for r in runs),
            "solver_exceptions": sum(r.solver_exceptions for r in runs),
            "fallback_solves": sum(r.fallback_solves for r in runs),
            "fallback_specs": sum(1 for r in runs if r.fallback_solves),
        })
    front = pareto_front([(r["median_seconds"], r["p90_gap"]) for r in rows])
    median_front = pareto_front([(r["median_seconds"], r["median_gap"]) for r in rows])
    for i, r in enumerate(rows):
        r["failures"] = sum(r[k] for k in FAILURE_KINDS)
        r["on_front"] = i in front
        r["on_median_front"] = i in median_front
        r["time_vs_default"] = _paired_time_ratio(result, r["method"])
    return rows


def _paired_time_ratio(result: BenchResult, method: str, default: str = "ipopt") -> float | None:
    """The median over specs of the method's time over the default method's on the same spec:
    on a shared machine a paired ratio is steadier than a ratio of medians."""
    base = {r.spec: r.seconds for r in result.runs if r.method == default}
    ratios = [r.seconds / base[r.spec] for r in result.runs
              if r.method == method and base.get(r.spec, 0) > 0]
    return statistics.median(ratios) if ratios else None


def _median_gap(gaps):
    return _percentile(gaps, 50)


def pareto_front(points) -> set:
    """Indices of the points no other point beats on both (time, gap), lower being better."""
    out = set()
    for i, (t, g) in enumerate(points):
        if t is None or g is None:
            continue
        dominated = any(u is not None and h is not None and u <= t and h <= g and (u < t or h < g)
                        for j, (u, h) in enumerate(points) if j != i)
        if not dominated:
            out.add(i)
    return out


def stability_rows(result: BenchResult) -> list[dict]:
    """Failures per method and kind of spec (long form: one row per method x kind)."""
    rows = []
    for m in result.methods:
        for kind in result.kinds:
            runs = [r for r in result.runs if r.method == m and r.kind == kind]
            fails = [failures(r, result.truth(r)) for r in runs]
            row = {"method": m, "kind": kind, "specs": len(runs),
                   "feasible_specs": sum(1 for r in runs if result.truth(r).feasible)}
            for key in FAILURE_KINDS:
                row[key] = sum(f[key] for f in fails)
            row["pipeline_failures"] = sum(row[k] for k in FAILURE_KINDS)
            row.update(solves=sum(r.solves for r in runs), false_successes=sum(r.false_successes for r in runs),
                       rounding_breaks=sum(r.rounding_breaks for r in runs),
                       solver_exceptions=sum(r.solver_exceptions for r in runs),
                       fallback_solves=sum(r.fallback_solves for r in runs))
            gaps = [gap(r, result.truth(r)) for r in runs if result.truth(r).feasible]
            row["median_gap"] = _median_gap(gaps)
            rows.append(row)
    return rows


def failure_list(result: BenchResult) -> list[dict]:
    """Every failing run, with what went wrong."""
    out = []
    for r in result.runs:
        t = result.truth(r)
        f = failures(r, t)
        if f["exception"]:
            what = f"raised {r.error}"
        elif f["violating"]:
            what = f"reported optimal but breaks {', '.join(r.violated)} (worst {r.worst_violation:.3g})"
        elif f["missed"]:
            what = (f"called infeasible ({', '.join(r.violated[:4]) or 'no design'}); best known "
                    f"{t.best:.6g} by {t.best_by}")
            if t.lead < t.best:   # the tie rule ranks a design within the band by deflection, then mass
                what += f" (ranked by the tie rule; the lowest objective {t.lead:.6g})"
        elif f["unreadable"]:
            what = f"wrote a design.json (status {r.status}) that its reader refuses: {r.unreadable}"
        else:
            continue
        out.append({"method": r.method, "spec": r.spec, "kind": r.kind, "what": what})
    return out


def outside_the_band(result: BenchResult, method: str) -> list[str]:
    """The feasible specs on which ``method`` answered outside the tie band of the lowest verified
    objective: spec, gap, its objective and the best known design's."""
    out = []
    for r in result.runs:
        t = result.truth(r)
        g = gap(r, t) if r.method == method else None
        if g:
            found = "no design" if math.isinf(g) else f"{r.objective:.6g}, {_pct(g)} over"
            out.append(f"{r.spec} ({found}; the lowest {t.lead:.6g}, best known {t.best:.6g} by {t.best_by})")
    return out


def construction_mismatches(result: BenchResult) -> list[str]:
    """Specs whose verdict differs from the one they were built to have (a model or bench defect)."""
    return [f"{t.spec}: built {t.expected}, found {t.verdict}" for t in result.truths.values()
            if t.expected is not None and t.expected != t.verdict]


# --------------------------------------------------------------------------- tables

def _pct(value, digits: int = 3) -> str:
    if value is None:
        return "–"
    if math.isinf(value):
        return "no design"
    if value == 0:
        return "0"
    return f"{value * 100:.{digits}g} %"


def _sec(value) -> str:
    return "–" if value is None else f"{value:.3g}"


def _ratio(value) -> str:
    return "–" if value is None else f"{value:.2f}×"


def _md_table(header: list, rows: list, text_columns: int = 1) -> str:
    """A Markdown table; the first ``text_columns`` columns left-aligned, numbers right-aligned."""
    out = ["| " + " | ".join(header) + " |",
           "|" + "|".join("---" if i < text_columns else "---:" for i in range(len(header))) + "|"]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def summary_tables(result: BenchResult, rows=None) -> tuple[str, str]:
    """The per-method tables as Markdown: speed and accuracy; failures."""
    rows = rows or method_summary(result)
    lo, hi = SPREAD
    speed = _md_table(
        ["method", "median time, s", f"time p{lo}-p{hi}, s", "time / ipopt's", "median gap", f"gap p{lo}-p{hi}",
         "p90 gap", "at best", "raw median gap", "on the front"],
        [[r["method"], _sec(r["median_seconds"]), f"{_sec(r['seconds_low'])}-{_sec(r['seconds_high'])}",
          _ratio(r["time_vs_default"]), _pct(r["median_gap"]), f"{_pct(r['gap_low'])} to {_pct(r['gap_high'])}",
          _pct(r["p90_gap"]), f"{r['at_best']}/{r['feasible_specs']}", _pct(r["raw_median_gap"]),
          "yes" if r["on_front"] else "no"]
         for r in rows])
    fails = _md_table(
        ["method", "exceptions", "violating", "missed", "unreadable", "solves", "false successes",
         "rounding breaks", "solver exceptions", "specs with a fallback"],
        [[r["method"], r["exception"], r["violating"], r["missed"], r["unreadable"], r["solves"],
          r["false_successes"], r["rounding_breaks"], r["solver_exceptions"], r["fallback_specs"]] for r in rows])
    return speed, fails


def stability_markdown(result: BenchResult, rows=None) -> str:
    rows = rows or stability_rows(result)
    kinds = result.kinds
    counts = {k: sum(1 for s in result.suite if s.kind == k) for k in kinds}
    header = ["method"] + [f"{k} ({counts[k]})" for k in kinds] + ["total"]
    cell = {(r["method"], r["kind"]): r for r in rows}

    def matrix(key_fn):
        body = []
        for m in result.methods:
            vals = [key_fn(cell[(m, k)]) for k in kinds]
            body.append([m] + [str(v) for v in vals] + [str(sum(vals))])
        return _md_table(header, body)

    return "\n\n".join([
        "Pipeline failures (what `fpdesign optimize --method M` returns): exceptions + designs reported "
        "optimal that break a limit on re-check + feasible specs called infeasible + design.json records "
        "that `designfile.load_design` refuses. Columns: kind of spec (number of specs).",
        matrix(lambda r: r["pipeline_failures"]),
        "Raw solver failures (from the Solve records, before the pipeline's check and fallback): runs that "
        "said success but whose design breaks a limit (before or only after rounding to 0.01 mm), plus runs "
        "whose solver raised.",
        matrix(lambda r: r["false_successes"] + r["rounding_breaks"] + r["solver_exceptions"]),
    ])


def markdown(result: BenchResult, chart_file: str = "bench.png") -> str:
    """bench.md: settings, the per-method table, the chart, the stability tables and every failure."""
    import platform

    summary = method_summary(result)
    speed_table, failure_table = summary_tables(result, summary)
    n_ex = sum(1 for s in result.suite if s.kind == "example")
    n_gen = len(result.suite) - n_ex
    truths = list(result.truths.values())
    n_feasible = sum(1 for t in truths if t.feasible)
    default = next((r for r in summary if r["method"] == "ipopt"), None)
    lines = [
        "# Search methods compared: speed, accuracy and stability",
        "",
        f"`fpdesign bench` ran {len(result.methods)} methods ({', '.join(result.methods)}) on {len(result.suite)} "
        f"specs: {n_ex} optimiser examples and {n_gen} generated from seed {result.seed} "
        f"({n_feasible} feasible, {len(truths) - n_feasible} infeasible). Reference search: "
        f"`reference.reference_best` at {result.levels} levels. Total {result.seconds / 60:.1f} min on "
        f"{os_cpu()} ({platform.python_implementation()} {platform.python_version()}); the machine was shared, "
        "so times are medians of single runs and only their ratios mean much.",
        "",
        "- **time**: wall time of one `optimize` call (every material x section family, with the method's "
        "start points, checks and fallback), after a warm-up.",
        "- **gap**: reported objective over the lowest verified objective any method or the reference "
        f"found for that spec, minus one. Within the {model.TIE_TOLERANCE:.1%} tie band it counts as 0: "
        "there MODEL.md section 5 ranks designs by deflection, then mass, not by objective. *no design*: "
        "the spec is feasible but the method returned no design that meets every limit. Medians are over "
        "the feasible specs; spreads are the "
        f"{SPREAD[0]}th-{SPREAD[1]}th percentiles.",
        "- **raw median gap**: the same for the method's own runs alone, without the fallback method "
        "(`optimize` falls back to IPOPT, and IPOPT to SLSQP, when no start gives a verified design; IPOPT "
        "does not when every start ended in a verdict: locally infeasible, or the targets out of reach).",
        "- **violating**: reported optimal, but the design rebuilt from its design.json record "
        "(`designfile.rebuild` + `evaluation.evaluate`) breaks a limit. **missed**: called infeasible though "
        "a design that meets every limit is known. **exceptions**: `optimize` raised. **unreadable**: the "
        "design.json record is refused by the product's own reader (`designfile.validate`), so `plot`, "
        "`export` or `simulate` cannot use it.",
        "- **solves**: runs of the method itself. **false successes**: runs that reported success though "
        f"their own answer breaks a limit they were given by more than {SOLVER_TOLERANCE:g} (normalised; "
        "with the error objective the targets are the objective, not limits); **rounding breaks**: runs "
        "that reported success and met every limit, but no design rounded to 0.01 mm near the answer does; "
        "**solver exceptions**: runs whose solver raised (caught by the adapter). The pipeline checks every "
        "run, so these cost time, not correctness.",
        "- **time / ipopt's**: the median over specs of the method's time over IPOPT's on the same spec "
        "(paired, so steadier than a ratio of medians on a shared machine).",
        "- **front**: no other method has both a lower (or equal) median time and a lower (or equal) "
        "90th-percentile gap. The median gap is 0 for every method that finds the best design on most "
        "specs and cannot tell them apart; the 90th percentile says how far off a method's bad answers are.",
        "",
        "## Per method",
        "",
        speed_table,
        "",
        f"![Solve time against objective gap]({chart_file})",
        "",
        failure_table,
        "",
    ]
    if default is not None:
        misses = outside_the_band(result, default["method"])
        lines += [_default_verdict(default, summary) + " Its answer is outside the tie band "
                  + (f"on {len(misses)} of {default['feasible_specs']} feasible specs: " + "; ".join(misses) + "."
                     if misses else f"on none of the {default['feasible_specs']} feasible specs."), ""]
    lines += ["## Stability", "", stability_markdown(result), ""]
    fails = failure_list(result)
    lines += ["## Every pipeline failure", ""]
    if fails:
        lines += [_md_table(["method", "spec", "kind", "what happened"],
                            [[f["method"], f["spec"], f["kind"], f["what"].replace("|", "/")] for f in fails],
                            text_columns=4)]
    else:
        lines += ["None."]
    lines += [""]
    mism = construction_mismatches(result)
    lines += ["## Verdicts", "",
              "Specs built to be infeasible carry a proof (a lower bound on the force error, the room the "
              "stations need, or the deflection of the stiffest beam allowed); nearly infeasible ones carry "
              "a design that meets every limit with 1-5 % to spare on the targets.", ""]
    kind_rows = []
    for k in result.kinds:
        ts = [t for t in truths if t.kind == k]
        kind_rows.append([k, KIND_NOTES[k], len(ts), sum(t.feasible for t in ts), sum(not t.feasible for t in ts)])
    lines += [_md_table(["kind", "what it is", "specs", "feasible", "infeasible"], kind_rows, text_columns=2), ""]
    lines += ["Built verdicts contradicted: " + ("; ".join(mism) if mism else "none.")]
    if result.skipped:
        lines += ["", "Example files left out (fixed designs, `design:` block, and catalogues): " + ", ".join(result.skipped) + "."]
    lines += ["", "Files: `runs.csv` (every run), `specs.csv` (every spec's verdict and best known design), "
              "`stability.csv`, `suite/*.yaml` (the generated specs).", ""]
    return "\n".join(lines)


def _default_verdict(default: dict, summary: list) -> str:
    """What the bench says of the default method, in words."""
    clean = not (default["violating"] or default["missed"] or default["exception"])
    out = "On this suite the default method's pipeline " + (
        "never returned a design that breaks a limit and never called a feasible spec infeasible; "
        if clean else f"returned {default['violating']} designs that break a limit, called {default['missed']} "
                      f"feasible specs infeasible and raised {default['exception']} times (listed below); ")
    out += ("IPOPT is on the speed-accuracy front (median time, 90th-percentile gap). " if default["on_front"]
            else "IPOPT is NOT on the speed-accuracy front (median time, 90th-percentile gap). ")
    if default["on_median_front"]:
        return out + "It is also on the front of medians (median time, median gap)."
    better = [r for r in summary if r is not default and r["median_seconds"] is not None
              and r["median_gap"] is not None and r["median_seconds"] <= default["median_seconds"]
              and r["median_gap"] <= default["median_gap"]]
    parts = [f"{r['method']} (median {_sec(r['median_seconds'])} s against {_sec(default['median_seconds'])} s, "
             f"{_ratio(r['time_vs_default'])} of IPOPT's time on the median spec; median gap "
             f"{_pct(r['median_gap'])} against {_pct(default['median_gap'])}; 90th percentile "
             f"{_pct(r['p90_gap'])} against {_pct(default['p90_gap'])}; best known design found on "
             f"{r['at_best']} specs against {default['at_best']})" for r in better]
    return out + "On medians alone it is dominated by " + "; ".join(parts) + "."


def os_cpu() -> str:
    import os

    n = os.cpu_count() or 0
    return f"{n} CPU core{'s' if n != 1 else ''}"


def terminal_table(result: BenchResult, rows=None):
    """The per-method table as a rich Table (the command prints it)."""
    from rich.table import Table

    rows = rows or method_summary(result)
    table = Table(title=f"fpdesign bench: {len(result.suite)} specs, "
                        f"{sum(t.feasible for t in result.truths.values())} feasible")
    for name in ("method", "median s", "median gap", "p90 gap", "at best", "exc/viol/\nmiss/unread",
                 "raw false/\nround/exc", "front"):
        table.add_column(name, justify="left" if name == "method" else "right")
    for r in rows:
        table.add_row(r["method"], _sec(r["median_seconds"]), _pct(r["median_gap"]), _pct(r["p90_gap"]),
                      f"{r['at_best']}/{r['feasible_specs']}",
                      f"{r['exception']}/{r['violating']}/{r['missed']}/{r['unreadable']}",
                      f"{r['false_successes']}/{r['rounding_breaks']}/{r['solver_exceptions']}",
                      "yes" if r["on_front"] else "no")
    return table

