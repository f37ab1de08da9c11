"""optimize, evaluate, simulate and materials."""

from __future__ import annotations

import importlib
import importlib.util
import math
import os
from pathlib import Path

from designer.cli.paths import not_empty, output_folder, seed
from designer.cli.progress import progress_display
from designer.errors import DesignFileError, SpecError


def register(sub) -> None:
    from designer.names import SCHEMES

    p = sub.add_parser("optimize", help="search materials, sections, pockets and stations for the best design")
    p.add_argument("spec", help="spec.yaml")
    p.add_argument("-o", "--output", default="out", help="output folder [out]")
    p.add_argument("--method", default="ipopt",
                   help="ipopt (default), slsqp, mma, ccsaq, cobyla, isres, direct or grid")
    p.add_argument("--no-cad", action="store_true", help="do not write the STEP model and its pictures")
    p.add_argument("--no-plots", action="store_true", help="do not write the plots")
    p.add_argument("--svg", action="store_true", help="also write the plots as SVG")
    p.add_argument("--verify", action="store_true", help="check the chosen design with a 3-D finite-element model")
    p.add_argument("--verify-mesh", choices=("coarse", "normal", "fine"), default=None,
                   help="with --verify: mesh of the 3-D check [normal]")
    p.add_argument("--verify-rounds", type=int, default=None, metavar="N",
                   help="with --verify: corrected rounds when the design fails in 3-D (the model adjusted by the "
                        "3-D/model ratios and solved again) [3]")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--catalogue", action="append", default=[], metavar="FILE",
                   help="a catalogue of your own materials, gauges and stock, beside the shipped one "
                        "(docs/spec.md 2.9); may be given more than once")
    p.set_defaults(func=run_optimize)

    e = sub.add_parser("evaluate", help="evaluate the fixed design: block of a spec")
    e.add_argument("spec", help="spec.yaml with a design: block")
    e.add_argument("-o", "--output", default="out", help="output folder [out]")
    e.add_argument("--no-cad", action="store_true", help="do not write the STEP model and its pictures")
    e.add_argument("--no-plots", action="store_true", help="do not write the plots")
    e.add_argument("--svg", action="store_true", help="also write the plots as SVG")
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.add_argument("--catalogue", action="append", default=[], metavar="FILE",
                   help="a catalogue of your own materials, gauges and stock (docs/spec.md 2.9)")
    e.set_defaults(func=run_evaluate)

    s = sub.add_parser("simulate", help="Monte Carlo of the estimator over the operating region")
    s.add_argument("design", help="spec.yaml with a design: block, or a design.json")
    s.add_argument("--draws", type=int, default=100_000, help="noise draws per grid point [100000]")
    s.add_argument("--grid", type=int, nargs=2, default=(7, 7), metavar=("NF", "NX"),
                   help="forces x positions in the grid [7 7, as the paper's section 4.3]")
    s.add_argument("--seed", type=seed, default=0, help="seed of the noise draws, 0 or more [0]")
    s.add_argument("--angle", type=float, default=30.0, help="biaxial designs: load angle in degrees [30]")
    s.add_argument("--readings", metavar="CSV", help="also write noisy bridge readings at the paper's loads")
    s.add_argument("--scheme", default=None, choices=SCHEMES,
                   help="with --readings: their loads: paper, 4, 9 or grid [paper]")
    s.set_defaults(func=run_simulate)

    m = sub.add_parser("materials", help="list the material, gauge and stock catalogue")
    m.add_argument("--json", action="store_true", help="machine-readable output")
    m.add_argument("--catalogue", action="append", default=[], metavar="FILE",
                   help="list a catalogue of your own beside the shipped one (docs/spec.md 2.9)")
    m.set_defaults(func=run_materials)


# ------------------------------------------------------------------ shared output

def _optional(module: str):
    """A module of an output that may not be installed in this build (CAD, plots)."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name == module:
            return None
        raise


def cad_child(cad: bool):
    """A child process that loads the CAD kernel while this one searches (``write_outputs``
    gives it the design), or None without CAD outputs or without cadquery."""
    if not cad or importlib.util.find_spec("cadquery") is None:
        return None
    from designer.outputs.background import Background

    # what write_cad_outputs imports lazily: the CAD kernel (1-3 s) and matplotlib's figure; and
    # the plots, which it draws while the fronts are computed here
    return Background(modules=("designer.outputs.cad.writer", "cadquery", "matplotlib.figure",
                               "designer.outputs.plots"))


def cad_and_design_plots(record: dict, scratch: Path, plot_options: dict | None) -> dict:
    """The CAD job of ``write_outputs`` (in its child process): the CAD outputs, then, with
    ``plot_options`` (``write_design_plots``' keywords), the plots that the parent has not
    claimed (``_Shared``): the design's own, then, once the parent has handed them over, the
    trade-off plots. ``{"cad": {kind: path} or a DesignFileError, "plots": [paths]}``."""
    from designer.outputs.cad.writer import write_cad_outputs

    try:
        cad = write_cad_outputs(record, scratch)
    except DesignFileError as exc:   # the parent decides whether it matters (an infeasible design)
        cad = exc
    plots = []
    if plot_options is not None:
        from designer.outputs.plots import write_design_plots

        # staged inside the job's scratch folder, which the parent removes if it stops this child
        staging = scratch / ".plots"
        shared = _Shared(scratch)
        written = write_design_plots(record, staging, tradeoff={}, claim=shared.claim, **plot_options)
        tradeoff = shared.fronts()
        if tradeoff:
            written += write_design_plots(record, staging, tradeoff=tradeoff, claim=shared.claim, **plot_options)
        for path in written:
            plots.append(scratch / path.name)
            os.replace(path, plots[-1])
        staging.rmdir()
    return {"cad": cad, "plots": plots}


class _Shared:
    """What the job's two processes share in the scratch folder's ``.claims`` (removed before
    the outputs move into place): an empty file per plot taken, created exclusively, and the
    trade-off fronts (or null) that the parent hands over to the child."""

    FRONTS = "fronts.json"

    def __init__(self, scratch: Path):
        self.folder = scratch / ".claims"
        self.folder.mkdir(exist_ok=True)

    def claim(self, name: str) -> bool:
        """True for the first of the two processes to ask for the plot ``name``."""
        try:
            os.close(os.open(self.folder / name, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            return False
        return True

    def hand_over(self, tradeoff) -> None:
        """The parent's fronts (None where there are none), for the child's ``fronts``."""
        from designer.outputs.files import atomic_write_json

        atomic_write_json(self.folder / self.FRONTS, tradeoff)

    def fronts(self):
        """The fronts the parent handed over, waiting for them. A parent that ended without them
        (killed: it stops this process itself otherwise) ends this one."""
        import json
        import multiprocessing
        import time

        path = self.folder / self.FRONTS
        parent = multiprocessing.parent_process()
        while not path.exists():
            if parent is not None and not parent.is_alive():
                os._exit(1)
            time.sleep(0.02)
        return json.loads(path.read_text(encoding="utf-8"))


def _unplottable(record: dict) -> str | None:
    """Why the plots of ``record``'s design cannot be drawn, None if they can. Only an infeasible
    record's least infeasible design may be so: one that is no beam (a slot wider than its bar,
    ``model.unbuildable``) has no sensor's figures to plot, whatever their signs; a design that
    meets every limit and cannot be drawn is a fault, raised."""
    from designer.outputs.plots.sensor import SensorData
    from designer.result.designfile import validate

    try:
        validate(record)
        SensorData.from_design(record)
    except DesignFileError as exc:
        if record.get("status") != "infeasible":
            raise
        return str(exc)
    return None


def write_outputs(record: dict, out_dir: Path, cad: bool = True, plots: bool = True, extra_plots=None,
                  writers=(), fronts=None, progress=None, child=None, inputs=()) -> None:
    """design.json, report.md and, when asked, the CAD model, the plots and the outputs of
    ``writers`` (callables taking the scratch folder, returning ``{name: path}``): all or nothing,
    and never over one of ``inputs`` (``(what, path)`` pairs, ``read_files``).

    The CAD model is built in a child process (``child``, one ``cad_child`` started earlier, or
    a new one) while this one computes ``fronts`` (a callable giving the trade-off fronts, or
    None) and draws the plots; the child then draws the plots this one has not begun (each
    process claims a plot before drawing it: the child from the first, this one the design's
    own from the last; then either the trade-off plots, which this one hands over when its
    fronts are done). ``progress(stage, done, total)`` hears of the plots and of the wait for
    the child."""
    import shutil

    from designer.outputs import report
    from designer.errors import InputError
    from designer.outputs.files import atomic_write_json, atomic_write_text, previous_outputs, staged_directory

    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"-o: {out_dir} is a file, not a folder; give a folder for design.json and the report")
    extra = dict(extra_plots or {})
    plot_module = _optional("designer.outputs.plots") if plots else None
    if plot_module is not None and (why := _unplottable(record)) is not None:
        record["messages"].append(f"no plots for this infeasible design: {why}")
        plot_module = None
    with staged_directory(out_dir, stale=previous_outputs(out_dir), inputs=inputs) as scratch:
        files = record.setdefault("files", {})
        cad_job = shared = None
        plotted = []
        if cad and importlib.util.find_spec("cadquery") is not None:
            from designer.outputs.background import Background

            options = None if plot_module is None else {k: v for k, v in extra.items() if k != "tradeoff"}
            shared = None if options is None else _Shared(scratch)
            job = (dict(record), scratch, options)
            cad_job = (child.submit(cad_and_design_plots, *job) if child is not None
                       else Background(cad_and_design_plots, *job))
        try:
            if fronts is not None:
                tradeoff = fronts()
                if tradeoff is not None:
                    extra["tradeoff"] = tradeoff
            if shared is not None:   # the child draws the trade-off plots too, if it is free first
                shared.hand_over(extra.get("tradeoff"))
            if plot_module is not None:
                plotted += plot_module.write_design_plots(
                    record, scratch, **extra, claim=None if shared is None else shared.claim,
                    last_first=shared is not None,
                    progress=None if progress is None else (lambda done, total: progress("plots", done, total)))
                files["plots"] = []   # (in its place among the files; filled below)
            for write in writers:
                files.update({k: Path(v).name for k, v in write(scratch).items()})
            if cad_job is not None:
                if progress is not None:
                    progress("CAD model, drawing and picture" + (", plots" if shared is not None else ""), 0, 1)
                done = cad_job.result()
                plotted += done["plots"]
                if isinstance(done["cad"], DesignFileError):
                    if record["status"] != "infeasible":
                        raise done["cad"]
                    # the least-infeasible design may not be buildable (features overlapping)
                    record["messages"].append(f"no CAD model for this infeasible design: {done['cad']}")
                else:
                    files.update({k: Path(v).name for k, v in done["cad"].items()})
        finally:
            if cad_job is not None:
                cad_job.stop()
        if shared is not None:
            shutil.rmtree(shared.folder, ignore_errors=True)
        if plot_module is not None:
            files["plots"] = sorted(Path(p).name for p in plotted)
        files["report"] = "report.md"
        atomic_write_text(scratch / "report.md", report.markdown(record))
        atomic_write_json(scratch / "design.json", record)


# ------------------------------------------------------------------ commands

def _with_cad_child(work, args) -> int:
    """``work(args, child)``, a ``cad_child`` loading the CAD kernel while this process loads its
    own and searches or evaluates; the child stopped however the work ends."""
    child = cad_child(not args.no_cad)
    try:
        return work(args, child)
    finally:
        if child is not None:
            child.stop()


def run_evaluate(args) -> int:
    return _with_cad_child(_evaluate, args)


def _evaluate(args, child) -> int:
    from designer.outputs import report
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import load_spec

    out_dir = output_folder(args.output, what="design.json and the report")
    spec = load_spec(args.spec, _user_catalogues(args))
    if spec.design is None:
        raise SpecError(f"design: missing in {args.spec}; `fpdesign evaluate` needs a design: block "
                        "(material, section, stations, feature); use `fpdesign optimize` to search instead")
    with progress_display(args.quiet, "evaluating") as progress:
        result = evaluate_fixed(spec)
        write_outputs(result.record, out_dir, cad=not args.no_cad, plots=not args.no_plots,
                      extra_plots={"formats": _plot_formats(args)}, progress=progress, child=child,
                      inputs=read_files(args, spec))
    report.print_summary(result.record)
    print(f"wrote {Path(args.output) / 'design.json'}")
    return 0 if result.success else 1


def run_optimize(args) -> int:
    return _with_cad_child(_optimize, args)


def _optimize(args, child) -> int:
    from designer.outputs import report
    from designer.result.pipeline import DesignOptions, design, tradeoff_fronts
    from designer.spec.reader import load_spec

    from designer.errors import describe_allowed
    from designer.search.problem import METHODS

    if args.method not in METHODS:
        raise SpecError(f"--method: {args.method!r} is not allowed; must be {describe_allowed(METHODS)}")
    rounds = DesignOptions.verify_rounds if args.verify_rounds is None else args.verify_rounds
    if rounds < 0:
        raise SpecError(f"--verify-rounds: {rounds} is not allowed; must be 0 or more")
    for flag, value in (("--verify-mesh", args.verify_mesh), ("--verify-rounds", args.verify_rounds)):
        if value is not None and not args.verify:  # (silently ignored, the user would think it checked)
            raise SpecError(f"{flag}: {value} given without --verify; add --verify to check the design in 3-D")
    out_dir = output_folder(args.output, what="design.json and the report")
    spec = load_spec(args.spec, _user_catalogues(args))
    with progress_display(args.quiet, "optimising") as progress:
        result = design(spec, DesignOptions(method=args.method, verify=args.verify,
                                            verify_mesh=args.verify_mesh or "normal", verify_rounds=rounds,
                                            tradeoff=False, progress=progress))
        writers = []
        if result.verification is not None:
            from designer.checks import fea

            writers.append(lambda scratch: fea.write_outputs(result.verification, scratch))
        # the fronts are computed while the CAD model builds in a child process
        fronts = (lambda: tradeoff_fronts(spec, result, progress)) if not args.no_plots else None
        write_outputs(result.record, out_dir, cad=not args.no_cad, plots=not args.no_plots,
                      extra_plots={"formats": _plot_formats(args)}, writers=writers, fronts=fronts,
                      progress=progress, child=child, inputs=read_files(args, spec))
    report.print_summary(result.record)
    print(f"wrote {Path(args.output) / 'design.json'}")
    return 0 if result.status == "optimal" else 1


def read_files(args, spec) -> list:
    """The files optimize and evaluate read, as ``(what, path)`` pairs: the spec, the catalogue
    files it names (relative to its folder) and those of ``--catalogue``."""
    from designer.spec.catalogue import user_file

    own = spec.catalogue[:len(spec.catalogue) - len(args.catalogue)]   # the spec's, then --catalogue's
    return ([("spec", Path(args.spec))] + [("catalogue", user_file(f, Path(args.spec).parent)) for f, _ in own]
            + [("catalogue", Path(f)) for f in args.catalogue])


def _plot_formats(args) -> tuple:
    return ("png", "svg") if args.svg else ("png",)


def _design_record(path: str) -> dict:
    from designer.result.evaluation import evaluate, fixed_design
    from designer.result.record import build_record

    if path.endswith(".json"):
        from designer.result.designfile import read_design

        # Judge the design afresh from what the file describes: its "predicted" block may be
        # stale, edited or absent (docs/spec.md does not list every key simulate needs).
        record = read_design(path)
        spec, design = record.spec, record.design
        ev = evaluate(design, spec)
    else:
        from designer.spec.reader import load_spec

        spec = load_spec(path)
        if spec.design is None:
            raise SpecError(f"design: missing in {path}; simulate needs a fixed design (a design: block or a "
                            "design.json)")
        ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    return build_record("feasible" if ev.feasible else "infeasible", spec, ev)


# simulate's bounds: each grid point draws in batches, so these bound the time (about a minute
# at the largest) rather than the memory.
MIN_DRAWS, MAX_DRAWS = 100, 10_000_000
MAX_GRID = 100


# simulate: where the Monte Carlo leaves linear propagation by more than this, at a smallest
# signal under LINEAR_SNR noise levels, the output says why
LINEAR_AGREEMENT, LINEAR_SNR = 0.1, 10.0


def run_simulate(args) -> int:
    import time

    from rich.console import Console
    from rich.table import Table

    from designer.checks.montecarlo import grid, simulate

    if not MIN_DRAWS <= args.draws <= MAX_DRAWS:
        raise SpecError(f"--draws: {args.draws} is not allowed; use {MIN_DRAWS} to {MAX_DRAWS:,}")
    for name, n in zip(("NF", "NX"), args.grid):
        if not 2 <= n <= MAX_GRID:
            raise SpecError(f"--grid: {name} = {n} is not allowed; use 2 to {MAX_GRID}")
    if not (math.isfinite(args.angle) and -360 <= args.angle <= 360):
        raise SpecError(f"--angle: {args.angle!r} is not allowed; give degrees from -360 to 360")
    not_empty(args.readings, "--readings", "a file name for the readings CSV")
    if args.scheme is not None and args.readings is None:
        raise SpecError(f"--scheme: {args.scheme} given without --readings; it chooses the loads of the readings "
                        "--readings CSV writes")
    args.scheme = args.scheme or "paper"
    if args.readings is not None:
        from designer.cli.paths import guard_inputs

        guard_inputs({"--readings": args.readings}, {"design": args.design})
    record = _design_record(args.design)
    d, p, s = record["design"], record["predicted"], record["spec"]
    (f_min, f_max), (x_min, x_max) = s["load"]["force"], s["load"]["position"]
    forces, positions = grid(f_min, f_max, x_min, x_max, *args.grid)
    angle = math.radians(args.angle) if d.get("axes", 1) == 2 else None
    t0 = time.perf_counter()
    res = simulate(p["sensitivity"], d["stations"], p["noise_voltage"], forces, positions, args.draws, args.seed, angle)
    seconds = time.perf_counter() - t0
    if args.readings is not None:   # the file first: a table printed is a run done
        readings = _optional("designer.calibration.readings")
        if readings is None:
            raise SpecError("--readings: this build has no readings module")
        readings.write_simulated_readings(record, Path(args.readings), scheme=args.scheme, seed=args.seed)

    table = Table(title=f"{s['name']}: Monte Carlo ({args.draws} draws per point) against the analytic 1σ")
    for col in ("F (N)", "x (mm)", "σF MC (N)", "σF model", "ratio", "σx MC (mm)", "σx model", "ratio",
                "mean |eF|", "mean |ex|"):
        table.add_column(col, justify="right")
    for i in range(len(forces)):
        table.add_row(f"{forces[i]:.4g}", f"{positions[i] * 1e3:.1f}",
                      f"{res.sigma_force_mc[i]:.4g}", f"{res.sigma_force[i]:.4g}",
                      f"{res.sigma_force_mc[i] / res.sigma_force[i]:.3f}",
                      f"{res.sigma_position_mc[i] * 1e3:.4g}", f"{res.sigma_position[i] * 1e3:.4g}",
                      f"{res.sigma_position_mc[i] / res.sigma_position[i]:.3f}",
                      f"{res.mean_abs_force_error[i]:.2%}", f"{res.mean_abs_position_error[i]:.2%}")
    console = Console()
    if not console.is_terminal:  # a pipe or a file: 80 columns would cut the numbers to "0.06…"
        console = Console(width=160)
    console.print(table)
    if angle is not None:
        console.print(f"biaxial at {args.angle:g}°: angle 1σ MC/model worst ratio "
                      f"{max(abs(res.sigma_angle_mc / res.sigma_angle - 1)):.2%}")
    console.print(f"{len(forces) * args.draws:,} draws in {seconds:.2f} s; largest |MC/model - 1| = "
                  f"{res.worst_ratio:.2%} (the Monte Carlo's own 1σ scatter is "
                  f"{1 / math.sqrt(2 * args.draws):.2%})")
    snr = p.get("min_signal_snr")
    if res.worst_ratio > LINEAR_AGREEMENT and isinstance(snr, (int, float)) and snr < LINEAR_SNR:
        console.print(f"the model's 1σ is the noise propagated linearly, which holds while every signal is well "
                      f"above the noise; this design's smallest signal is {snr:.3g} noise levels, where the "
                      f"estimator's ratios of noisy outputs have wide tails: the Monte Carlo's figures are its own")
    if args.readings is not None:
        print(f"wrote {args.readings}")
    return 0


def _user_catalogues(args) -> list:
    """The ``--catalogue`` files, read (``catalogue.read_user``)."""
    from designer.spec import catalogue

    for path in args.catalogue:
        not_empty(path, "--catalogue", "a catalogue file (docs/spec.md 2.9)")
    return [catalogue.read_user(path) for path in args.catalogue]


def _stock_entry(table, stock) -> dict:
    """One stock table for ``materials --json``: its figures, its family's materials and its rows,
    each with its sizes in SI and as the supplier writes them."""
    return {"name": table.name, "family": table.family, "materials": list(stock.families[table.family]),
            "shape": table.shape, "system": table.system, "unit": table.unit, "standard": table.standard,
            "source": table.source,
            "items": [{"designation": item.designation, "sizes": [float(v) for v in item.sizes]}
                      for item in table.items]}


def _span(values) -> str:
    """A few values listed, more as their range and count: ``10, 80``; ``1–128 (8)``."""
    if len(values) <= 2:
        return ", ".join(f"{v:g}" for v in values)
    return f"{values[0]:g}–{values[-1]:g} ({len(values)})"


def run_materials(args) -> int:
    import json
    from dataclasses import asdict

    from designer.spec import catalogue

    from designer.spec import frontends

    catalogue.use(_user_catalogues(args))
    mats, gauges, stock = catalogue.materials(), catalogue.gauges(), catalogue.stock()
    mills = catalogue.end_mills().end_mills
    fronts = frontends.catalogue()
    if args.json:
        print(json.dumps({"materials": [asdict(m) for m in mats.values()],
                          "gauges": [asdict(g) for g in gauges.values()],
                          "stock": [_stock_entry(t, stock) for t in stock.tables],
                          "end_mills": [asdict(m) for m in mills],
                          "front_ends": [asdict(f) for f in fronts.values()]}, indent=2))
        return 0
    from rich.console import Console
    from rich.table import Table

    # The figures in narrow columns, the sources (long citations) as numbered notes below each
    # table, so that the list reads at 80 columns.
    sources: list[str] = []

    def note(source: str) -> str:
        if source not in sources:
            sources.append(source)
        return f"[{sources.index(source) + 1}]"

    t = Table(title="materials (allowable = min(yield, fatigue) / safety factor)", box=None, padding=(0, 1))
    for col in ("name", "E\nGPa", "ν", "yield\nMPa", "UTS\nMPa", "fatigue\nMPa", "at\ncycles", "ρ\nkg/m³",
                "source"):
        t.add_column(col, justify="left" if col == "name" else "right", no_wrap=True)
    for m in mats.values():
        t.add_row(m.name, f"{m.E / 1e9:.1f}", f"{m.poisson:.3g}", f"{m.yield_strength / 1e6:.0f}",
                  f"{m.ultimate / 1e6:.0f}", f"{m.fatigue / 1e6:.0f}", f"{m.fatigue_cycles:.0e}",
                  f"{m.density:.0f}", note(m.source))
    g = Table(title="strain gauges", box=None, padding=(0, 1))
    for col in ("name", "G", "R\nΩ", "backing\nmm", "grid\nmm", "max\nµε", "source"):
        g.add_column(col, justify="left" if col == "name" else "right", no_wrap=True)
    for x in gauges.values():
        g.add_row(x.name, f"{x.factor:.3g}", f"{x.resistance:.0f}", f"{x.length * 1e3:.1f} × {x.width * 1e3:.1f}",
                  f"{x.grid_length * 1e3:.1f} × {x.grid_width * 1e3:.1f}", f"{x.max_strain * 1e6:.0f}",
                  note(x.source))
    b = Table(title="stock (search: {stock: metric | imperial | any})", box=None, padding=(0, 1))
    for col in ("table", "materials", "shape", "standard", "sizes", "source"):
        b.add_column(col, justify="left", no_wrap=col not in ("materials", "sizes"))
    for table in stock.tables:
        items = [item.designation for item in table.items]
        b.add_row(table.name, ", ".join(stock.families[table.family]), table.shape, table.standard,
                  f"{len(items)}: {items[0]} … {items[-1]}", note(table.source))
    e = Table(title="end mills (cad.corner_radius, the slots' and flats' tools)", box=None, padding=(0, 1))
    for col in ("table", "system", "diameters", "corner radii"):
        e.add_column(col, justify="left", no_wrap=col != "corner radii")
    for name in dict.fromkeys(m.table for m in mills):
        mine = [m for m in mills if m.table == name]
        scale = 1e3 if mine[0].unit == "mm" else 1 / 0.0254
        diameters = sorted({m.diameter for m in mine})
        radii = sorted({m.corner_radius for m in mine})
        e.add_row(name, mine[0].system, f"{len(diameters)}: Ø{diameters[0] * scale:g} … Ø{diameters[-1] * scale:g} "
                  f"{mine[0].unit}", f"R{radii[0] * scale:.3g} … R{radii[-1] * scale:.3g} {mine[0].unit}")
    f = Table(title="front-ends (electronics: {adc: NAME, rate: ..., gain: ...})", box=None, padding=(0, 1))
    for col in ("name", "kind", "gains", "rates\nHz", "noise\nnV RMS", "range\n±V_ref/gain", "source"):
        f.add_column(col, justify="left" if col in ("name", "kind") else "right", no_wrap=True)
    for fe in fronts.values():
        if fe.kind == "adc":
            noise = [rms for _, _, rms in fe.noise]
            f.add_row(fe.name, fe.kind, _span(fe.gains()), _span(fe.rates()),
                      f"{min(noise) * 1e9:.3g}–{max(noise) * 1e9:.0f}", f"{fe.full_scale:g}", note(fe.source))
        else:
            f.add_row(fe.name, fe.kind, f"{fe.gain_range[0]:g}–{fe.gain_range[1]:g}", "any",
                      f"{fe.noise_density * 1e9:.3g}/√Hz", f"{fe.full_scale:g}", note(fe.source))
    console = Console(highlight=False)
    console.print(t)
    console.print()
    console.print(g)
    console.print()
    console.print(b)
    console.print()
    console.print(e)
    console.print()
    console.print(f)
    console.print()
    console.print("sources:")
    for i, source in enumerate(sources, 1):
        console.print(f"[{i}] {source}", markup=False)
    return 0
