"""fpdesign bench (issue 5) in the library: the generated suite, the verdicts, the gap, the
speed-accuracy front and the files. Tests that run the search methods or the reference search
are marked slow."""

from __future__ import annotations

import csv
import math
import statistics

import pytest

from designer import bench
from designer import errors, search
from designer.errors import InputError
from designer.spec.reader import parse_spec_text

TINY_METHODS = ("ipopt", "slsqp", "grid")


@pytest.fixture(scope="module")
def tiny():
    """Three generated specs (one of them infeasible by construction) and three methods."""
    suite = bench.generate_suite(3, seed=7, kinds=["millinewton", "infeasible-room", "short-beam"])
    return bench.run_bench(suite, TINY_METHODS, levels=4, seed=7)


@pytest.mark.slow
def test_suite_is_reproducible_from_its_seed_and_a_short_suite_starts_a_long_one():
    a = bench.generate_suite(len(bench.KINDS), seed=3)
    b = bench.generate_suite(len(bench.KINDS), seed=3)
    assert [s.text for s in a] == [s.text for s in b]
    assert [s.text for s in bench.generate_suite(4, seed=3)] == [s.text for s in a[:4]]
    other = bench.generate_suite(len(bench.KINDS), seed=4)
    assert all(x.text != y.text for x, y in zip(a, other))


@pytest.mark.slow
def test_suite_holds_every_kind_and_each_spec_reads_back_through_the_spec_reader():
    suite = bench.generate_suite(len(bench.KINDS), seed=0)
    assert [s.kind for s in suite] == list(bench.KINDS)
    for item in suite:
        assert parse_spec_text(item.text) == item.spec
    specs = {s.kind: s.spec for s in suite}
    assert specs["millinewton"].load.force_min < 0.01          # N
    assert specs["kilonewton"].load.force_max >= 1000
    assert specs["short-beam"].load.position_max < 0.02        # m
    assert specs["long-beam"].load.position_max >= 0.5
    imperial = next(s for s in suite if s.kind == "imperial")
    assert " in" in imperial.text and "lbf" in imperial.text and "mm" not in imperial.text
    tight, loose = specs["tight-limits"], specs["loose-limits"]
    assert tight.limits.max_deflection is not None and tight.limits.min_frequency is not None
    assert loose.limits.max_deflection is None
    expected = {s.kind: s.expected for s in suite}
    assert {k for k, v in expected.items() if v == "infeasible"} == set(bench.INFEASIBLE_KINDS)
    assert expected["nearly-infeasible"] == "feasible"


def test_suite_draws_again_where_the_product_would_refuse_the_spec():
    # Seed 1's 045-millinewton was first drawn as tubes only (17-4PH, 301, 17-7PH) under a 2.6 mm
    # width limit: the catalogue has 17-4PH tubes, none that narrow, so the product refuses the spec
    # ("search.sections: tube leaves no size to try", exit 2) and the bench recorded it as an
    # exception of every method. The suite takes the next draw instead: the search designs it.
    item = bench.suite._generate(44, "millinewton", 1)
    assert item.name == "045-millinewton"
    outcome = search.optimize(item.spec)
    assert outcome.best is not None


def test_unknown_kind_is_bad_input():
    with pytest.raises(InputError, match="kind 'huge' is not allowed"):
        bench.generate_suite(1, kinds=["huge"])


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("kind", bench.INFEASIBLE_KINDS)
def test_specs_built_infeasible_are_reported_infeasible(kind, seed):
    # Each is built on a proof (a lower bound on the force error, the room the stations need, or
    # the deflection of the stiffest beam allowed), so no method may find a design.
    (item,) = bench.generate_suite(1, seed=seed, kinds=[kind])
    assert item.expected == "infeasible"
    run = bench.run_method(item, "ipopt")
    assert run.status == "infeasible" and not run.error
    assert not run.feasible and run.violated
    truth = bench.establish_truth(item, [run], levels=3)
    assert not truth.feasible and not truth.reference_feasible


@pytest.mark.slow
def test_nearly_infeasible_spec_is_feasible_with_little_to_spare():
    # The noise is raised until the reference search's best design meets the targets with 1-5 %
    # to spare (bench.suite): the optimiser must find a feasible design at least as good. (With
    # the fitted domains of the feature corrections the reference's coarse grid can miss a
    # section family the optimiser finds, so its design may have more to spare than that.)
    from designer.search import reference

    (item,) = bench.generate_suite(1, seed=0, kinds=["nearly-infeasible"])
    outcome = search.optimize(item.spec)
    assert outcome.success and outcome.best.objective <= 1.0
    ref = reference.reference_best(item.spec, levels=bench.suite.CALIBRATION_LEVELS)
    assert 0.95 <= ref.objective <= 0.99 + 1e-9
    assert outcome.best.objective <= ref.objective * (1 + 1e-3)


@pytest.mark.slow
def test_tiny_bench_verdicts_and_failures(tiny):
    truths = tiny.truths
    assert len(tiny.runs) == 3 * len(TINY_METHODS)
    infeasible = [t for t in truths.values() if t.expected == "infeasible"]
    assert infeasible and all(not t.feasible for t in infeasible)
    assert not bench.construction_mismatches(tiny)
    for run in tiny.runs:
        truth = tiny.truth(run)
        assert not run.error
        if truth.feasible:
            # MODEL.md 5 by hand: the objective's excess over the lowest verified objective,
            # 0 inside the 0.1 % tie band; inf for a run without a design meeting every limit.
            excess = run.objective / truth.lead - 1 if run.feasible and run.status == "optimal" else math.inf
            assert bench.gap(run, truth) == pytest.approx(0.0 if excess <= 1e-3 else excess, rel=1e-12, abs=0)
        else:
            assert run.status == "infeasible" and bench.gap(run, truth) is None
    ipopt = next(r for r in bench.method_summary(tiny) if r["method"] == "ipopt")
    assert ipopt["violating"] == 0 and ipopt["missed"] == 0 and ipopt["exception"] == 0


@pytest.mark.slow
def test_tiny_bench_writes_chart_tables_and_summary(tiny, tmp_path):
    paths = bench.write_bench(tiny, tmp_path / "out")
    names = {p.relative_to(tmp_path / "out").as_posix() for p in paths}
    assert {"bench.md", "bench.png", "stability.md", "stability.csv", "runs.csv", "specs.csv"} <= names
    assert {f"suite/{s.name}.yaml" for s in tiny.suite} <= names
    out = tmp_path / "out"
    assert (out / "bench.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    md = (out / "bench.md").read_text()
    assert "![Solve time against objective gap](bench.png)" in md
    for m in TINY_METHODS:
        assert f"| {m} |" in md
    rows = list(csv.DictReader((out / "stability.csv").open()))
    assert {(r["method"], r["kind"]) for r in rows} == {(m, k) for m in TINY_METHODS
                                                         for k in ("millinewton", "infeasible-room", "short-beam")}
    runs = list(csv.DictReader((out / "runs.csv").open()))
    assert len(runs) == 9
    assert not list(out.parent.glob(".out.*"))  # no scratch folder left behind


@pytest.mark.slow
def test_chart_takes_an_axes_and_returns_its_figure(tiny):
    from matplotlib.figure import Figure

    fig = Figure()
    ax = fig.add_subplot()
    assert bench.chart(bench.chart_data(tiny), ax=ax) is fig
    assert ax.get_xscale() == "log" and ax.get_yscale() == "symlog"
    assert "s (log scale)" in ax.get_xlabel() and "%" in ax.get_ylabel()


def test_the_charts_method_labels_cover_no_marker_and_no_other_label():
    """Measured on the drawn figure (matplotlib's own text extents): the medians of
    benchmarks/bench_methods.md, where COBYLA (1.5 %, 0.72 s) and MMA (2.2 %, 0.91 s) sit a
    marker apart; a label beside COBYLA's point on the usual side lay under MMA's marker."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    rows = [("ipopt", 0.191, 0.128, 0.323, 0, 0), ("slsqp", 0.255, 0.104, 0.365, 0, 1.66),
            ("mma", 0.909, 0.283, 1.98, 0, 2.2), ("ccsaq", 0.568, 0.395, 1.15, 0, 7.45),
            ("cobyla", 0.716, 0.289, 1.37, 0, 1.52), ("isres", 1.78, 1.31, 3.07, 0.263, 88.9),
            ("direct", 0.694, 0.44, 1.5, 0, 38.4), ("grid", 0.0346, 0.016, 0.0578, 46.5, math.inf)]
    methods = [{"method": m, "median_seconds": t, "seconds_low": lo, "seconds_high": hi, "median_gap": mg / 100,
                "p90_gap": pg / 100, "on_front": m in ("ipopt", "grid")} for m, t, lo, hi, mg, pg in rows]
    data = {"methods": methods, "points": [{"method": "isres", "seconds": 1.0, "gap": 0.889}], "specs": 54,
            "feasible_specs": 30, "tie": 1e-3}
    fig = bench.chart(data)
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    ax = fig.axes[0]
    labels = {t.get_text(): t.get_window_extent(renderer) for t in ax.texts}
    assert set(labels) == {m for m, *_ in rows} - {"ipopt"} | {"ipopt (default)"}
    centres = [ax.transData.transform(t.xy) for t in ax.texts]   # each label points at its marker
    radius = 4.5 * fig.dpi / 72   # the markers are 9 points across
    for name, box in labels.items():
        for cx, cy in centres:
            nearest = (min(max(cx, box.x0), box.x1), min(max(cy, box.y0), box.y1))
            assert math.hypot(cx - nearest[0], cy - nearest[1]) >= radius, name
        assert not any(box.overlaps(other) for n, other in labels.items() if n != name), name


def test_gap_counts_the_tie_band_as_zero_and_a_missing_design_as_infinite():
    truth = bench.Truth("s", "k", None, True, 2.0, 2.0, "ipopt", 2.0, True, 0.0, "error")
    run = bench.Run("s", "k", "grid", 0.1, status="optimal", objective=2.0 * (1 + 0.0009), worst_violation=0.0)
    assert bench.gap(run, truth) == 0
    run.objective = 2.2
    assert bench.gap(run, truth) == pytest.approx(0.1)
    run.status, run.worst_violation = "infeasible", 0.3
    assert math.isinf(bench.gap(run, truth))
    assert bench.failures(run, truth) == {"exception": 0, "violating": 0, "missed": 1, "unreadable": 0}
    run.status = "optimal"
    assert bench.failures(run, truth)["violating"] == 1


def test_pareto_front():
    # By hand, lower time and gap being better: (0.5, 0) beats (1, 0) on time and ties on gap;
    # (0.1, 0.2) is the fastest; (0.2, 0.3) is beaten by (0.1, 0.2) on both; (2, inf) by all.
    points = [(1.0, 0.0), (0.5, 0.0), (0.1, 0.2), (0.2, 0.3), (2.0, math.inf)]
    assert bench.pareto_front(points) == {1, 2}


@pytest.mark.slow
def test_front_uses_the_tail_of_the_gap_and_time_is_paired_per_spec(tiny):
    rows = bench.method_summary(tiny)
    # Recomputed by hand from the runs, without the summary's helpers: each method's point is
    # (median seconds over the 3 specs, 90th-percentile gap over the feasible ones), the
    # percentile being the smallest gap that at least 90 % of the gaps do not exceed (the
    # inverted CDF: the ceil(0.9 n)-th smallest); a point is on the front when no other point
    # is as good on both and better on one, lower being better (bench.md's definition).
    point = {}
    for m in TINY_METHODS:
        runs = [r for r in tiny.runs if r.method == m]
        gaps = sorted(bench.gap(r, tiny.truth(r)) for r in runs if tiny.truth(r).feasible)
        point[m] = (statistics.median(r.seconds for r in runs), gaps[math.ceil(0.9 * len(gaps)) - 1])
    front = {m for m, (t, g) in point.items()
             if not any(u <= t and h <= g and (u < t or h < g) for n, (u, h) in point.items() if n != m)}
    by = {r["method"]: r for r in rows}
    for m in TINY_METHODS:
        assert (by[m]["median_seconds"], by[m]["p90_gap"]) == pytest.approx(point[m], rel=1e-12)
    assert {r["method"] for r in rows if r["on_front"]} == front
    ipopt = {r.spec: r.seconds for r in tiny.runs if r.method == "ipopt"}
    ratios = sorted(r.seconds / ipopt[r.spec] for r in tiny.runs if r.method == "slsqp")
    assert by["slsqp"]["time_vs_default"] == pytest.approx(ratios[1])  # the median of three
    ratios = sorted(r.seconds / ipopt[r.spec] for r in tiny.runs if r.method == "grid")
    assert by["grid"]["time_vs_default"] == pytest.approx(ratios[1])


def test_a_method_that_raises_is_recorded_not_raised(monkeypatch):
    (item,) = bench.generate_suite(1, seed=0, kinds=["millinewton"])

    def broken(*args, **kwargs):
        raise errors.SolverError("no solver returned a design that could be evaluated")

    monkeypatch.setattr(search, "optimize", broken)
    run = bench.run_method(item, "mma")
    assert run.error.startswith("SolverError: no solver returned")
    truth = bench.Truth(item.name, item.kind, None, True, 1.0, 1.0, "reference", 1.0, True, 0.0, "error")
    assert bench.failures(run, truth)["exception"] == 1


def test_bench_leaves_fixed_designs_out_of_the_examples(examples):
    suite, skipped = bench.example_suite(examples)
    assert {s.name for s in suite} >= {"gripper-finger", "weigh-bar", "probe", "prototype-b-optimized"}
    assert "prototype-a.yaml" in skipped
    assert all(s.spec.design is None and s.kind == "example" for s in suite)


def test_a_missed_design_names_the_lowest_objective_when_the_tie_rule_ranks_another_first():
    # MODEL.md 5: designs within the 0.1 % tie band rank by deflection, then mass, so the best
    # known design (cobyla's 0.456222 on the suite's 018-long-beam) need not have the lowest
    # objective (IPOPT's 0.456013 there); the failure list says both.
    from designer.bench.summary import failure_list

    run = bench.Run("018-long-beam", "long-beam", "grid", 1.0, status="infeasible", violated=("stress_root",))
    tied = bench.Truth("018-long-beam", "long-beam", None, True, 0.456013, 0.456222, "cobyla", 0.457, True, 0.0,
                       "error")
    result = bench.BenchResult([], ("grid",), [run], {"018-long-beam": tied}, 0, 1, 4)
    (line,) = failure_list(result)
    assert line["what"].endswith("best known 0.456222 by cobyla (ranked by the tie rule; the lowest objective "
                                 "0.456013)")
    untied = bench.Truth("018-long-beam", "long-beam", None, True, 0.456222, 0.456222, "cobyla", 0.457, True, 0.0,
                         "error")
    result = bench.BenchResult([], ("grid",), [run], {"018-long-beam": untied}, 0, 1, 4)
    assert failure_list(result)[0]["what"].endswith("best known 0.456222 by cobyla")


def test_the_summary_names_each_spec_where_the_default_is_outside_the_tie_band():
    # MODEL.md 5's tie band is 0.1 %: IPOPT at 0.4004 against the lowest 0.4 (0.1 % over) ties;
    # at 0.402 it is 0.5 % over and named with the best known design; a feasible spec it gave no
    # design for is named too; the other specs' runs are not.
    from designer.bench.summary import outside_the_band

    def run(spec, objective, status="optimal"):
        return bench.Run(spec, "long-beam", "ipopt", 1.0, status=status, objective=objective,
                         worst_violation=0.0 if status == "optimal" else 0.2)

    truths = {name: bench.Truth(name, "long-beam", None, True, 0.4, 0.4, "cobyla", 0.41, True, 0.0, "error")
              for name in ("a", "b", "c")}
    result = bench.BenchResult([], ("ipopt",), [run("a", 0.4004), run("b", 0.402), run("c", None, "infeasible")],
                               truths, 0, 3, 4)
    assert outside_the_band(result, "ipopt") == [
        "b (0.402, 0.5 % over; the lowest 0.4, best known 0.4 by cobyla)",
        "c (no design; the lowest 0.4, best known 0.4 by cobyla)"]
