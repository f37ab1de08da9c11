"""plot (the charts of a design.json) and bench (the search methods compared)."""

from __future__ import annotations

import sys
from pathlib import Path

from designer.cli.paths import output_folder, seed
from designer.errors import InputError

FORMAT_CHOICES = {"png": ("png",), "svg": ("svg",), "both": ("png", "svg")}


def register(sub) -> None:
    _register_plot(sub)
    _register_bench(sub)


def _register_plot(sub) -> None:
    p = sub.add_parser(
        "plot", help="draw the plots of a design.json (operating region, isolines, error maps, ...)",
        description="Write the operating region, the bridge voltage isolines, the error maps, the "
                    "candidate ranking and, with --tradeoff or a 'tradeoff' key in the file, the "
                    "trade-off fronts of a design.json.")
    p.add_argument("design", help="design.json written by optimize or evaluate")
    p.add_argument("-o", "--output", default=None,
                   help="folder for the plots [the folder of design.json]")
    p.add_argument("--format", choices=tuple(FORMAT_CHOICES), default="png",
                   help="png, svg or both [png]")
    p.add_argument("--tradeoff", metavar="JSON", default=None,
                   help="trade-off points: {\"max_deflection\": [...], \"min_frequency\": [...]}, each "
                        "point {material, section, x, objective, feasible}")
    p.set_defaults(func=run_plot)


def run_plot(args) -> int:
    from designer.outputs.plots.write import write_design_plots
    from designer.result.designfile import load_design, read_json

    out_dir = output_folder(args.output, what="the plots") if args.output is not None else Path(args.design).resolve().parent
    design = load_design(args.design)
    tradeoff = read_json(args.tradeoff, what="--tradeoff") if args.tradeoff else None
    try:
        paths = write_design_plots(design, out_dir, formats=FORMAT_CHOICES[args.format], tradeoff=tradeoff)
    except OSError as exc:
        raise InputError(f"cannot write {exc.filename or out_dir}: {exc.strerror or exc}; "
                         "choose another folder for the plots with -o") from exc
    for path in paths:
        print(path)
    return 0


# ------------------------------------------------------------------ bench

# bench's bounds, so that a typing slip cannot start a run of days: each generated spec runs
# every method (about 10 s), and the reference grid search grows as levels**variables (5 levels
# take seconds per spec, 12 about an hour).
MAX_COUNT = 1000
MAX_LEVELS = 12


def _register_bench(sub) -> None:
    b = sub.add_parser(
        "bench", help="compare every search method on a suite of specs (speed, accuracy, failures)",
        description="Run every search method on the optimiser examples and on generated specs (millinewtons "
                    "to kilonewtons, millimetre to metre beams, tight and loose limits, imperial units, nearly "
                    "infeasible and infeasible ones); measure each against the best known design and write a "
                    "speed-accuracy chart, stability tables and a summary.")
    b.add_argument("--specs", metavar="DIR", default=None,
                   help="folder of spec.yaml files to include (fixed designs are left out) [the examples folder]")
    b.add_argument("--count", type=int, default=50, metavar="N", help="generated specs [50]")
    b.add_argument("--methods", default=None, metavar="LIST",
                   help="comma-separated methods [ipopt,slsqp,mma,ccsaq,cobyla,isres,direct,grid]")
    b.add_argument("--seed", type=seed, default=0, metavar="S", help="seed of the generated specs [0]")
    b.add_argument("--levels", type=int, default=None, metavar="L",
                   help="grid points per variable of the reference search [5]")
    b.add_argument("-o", "--output", default="bench", help="output folder [bench]")
    b.add_argument("--quiet", action="store_true", help="no progress bar")
    b.set_defaults(func=run_bench)


def run_bench(args) -> int:
    from designer import bench
    from designer.search.problem import METHODS

    if not 0 <= args.count <= MAX_COUNT:
        raise InputError(f"--count: {args.count} is not allowed; use 0 to {MAX_COUNT}")
    levels = bench.REFERENCE_LEVELS if args.levels is None else args.levels
    if not 2 <= levels <= MAX_LEVELS:
        raise InputError(f"--levels: {levels} is not allowed; use 2 to {MAX_LEVELS}")
    output_folder(args.output, what="the bench's files")
    methods = METHODS
    if args.methods is not None:
        methods = tuple(m.strip() for m in args.methods.split(",") if m.strip())
        bad = [m for m in methods if m not in METHODS]
        if bad or not methods:
            raise InputError(f"--methods: {bad[0] if bad else args.methods!r} is not a method; give a "
                             f"comma-separated list from {', '.join(METHODS)}")
    folder = Path(args.specs) if args.specs else bench.default_examples_folder()
    if args.specs and not folder.is_dir():
        raise InputError(f"--specs: {folder} is not a folder; give a folder of spec.yaml files")
    examples, skipped = bench.example_suite(folder) if folder is not None else ([], [])
    suite = examples + bench.generate_suite(args.count, args.seed)
    if not suite:
        raise InputError("nothing to run: no example specs found and --count is 0; give --specs DIR or --count N")
    if not examples:
        # say so: the example specs ship with the source repository, not with an installed package
        where = (f"no optimiser specs in {folder}" if folder is not None else
                 "no examples folder beside the package (the examples ship with the source repository)")
        print(f"fpdesign bench: {where}; running the {args.count} generated specs only; give --specs DIR to "
              "add specs of your own", file=sys.stderr)
    result = _bench_with_progress(bench, suite, methods, levels, args, skipped)
    try:
        paths = bench.write_bench(result, Path(args.output))
    except OSError as exc:
        raise InputError(f"cannot write {exc.filename or args.output}: {exc.strerror or exc}; "
                         "choose another folder for the bench's files with -o") from exc
    from rich.console import Console

    console = Console()
    console.print(bench.terminal_table(result))
    for line in bench.construction_mismatches(result):
        console.print(f"[red]verdict contradicts the construction:[/red] {line}", markup=True)
    console.print(f"wrote {len(paths)} files to {args.output} (summary: {Path(args.output) / 'bench.md'})",
                  markup=False, highlight=False)
    return 0


def _bench_with_progress(bench, suite, methods, levels, args, skipped):
    from designer.cli.progress import progress_display

    kwargs = dict(methods=methods, levels=levels, seed=args.seed, count=args.count, skipped=skipped)
    with progress_display(args.quiet, "bench") as progress:
        advance = None if progress is None else (lambda done, total, name: progress(f"bench: {name}", done, total))
        return bench.run_bench(suite, progress=advance, **kwargs)
