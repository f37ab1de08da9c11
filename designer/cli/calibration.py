"""Commands ``plan``, ``calibrate``, ``measure`` and ``simulate-readings`` (issue 6).

Thin: parse arguments, call ``designer.calibration`` and ``designer.calibration.readings``, print with rich.
"""

from __future__ import annotations

import math
from dataclasses import replace

from designer.cli.paths import guard_inputs, seed, whole_number

MM = 1e3   # m -> mm for display
MV = 1e3   # V -> mV for display


# Readings per load: more than this would only fill memory (each reading is a row).
MAX_REPEATS = 10_000
_repeats = whole_number(1, MAX_REPEATS)


def register(subparsers) -> None:
    from designer.names import NOISE_CHOICES, SCHEMES

    p = subparsers.add_parser(
        "plan", help="the calibration loads (4- and 9-point schemes) and their effect on accuracy",
        description="List the masses and positions of the paper's 4-point (corners) and 9-point (3 x 3) "
                    "calibration schemes over the design's region, with the predicted worst-case force and "
                    "position error with and without the calibration's own uncertainty.")
    p.add_argument("design", help="design.json")
    p.add_argument("-o", "--output", help="write the loads to this CSV (grams, millimetres)")
    p.add_argument("--repeats", type=_repeats, default=1, help="readings per load (default 1)")
    p.set_defaults(func=run_plan)

    p = subparsers.add_parser(
        "calibrate", help="fit k, d and c of every bridge to calibration readings",
        description="Fit V = c + k F x - k d F (the paper's eq. 27) to every bridge of readings.csv and "
                    "write the constants, their standard errors and R² to calibration.json.")
    p.add_argument("readings", help="readings.csv with force_N or mass_g, position_mm, [angle_deg,] V1, V2, ...")
    p.add_argument("--design", help="design.json: compare with its predictions and use its noise if needed")
    p.add_argument("-o", "--output", required=True, help="calibration.json to write")
    p.add_argument("--noise", choices=NOISE_CHOICES, default="auto",
                   help="sigma_V for standard errors: the residual RMS, the design's, or auto (default)")
    p.set_defaults(func=run_calibrate)

    p = subparsers.add_parser(
        "measure", help="force and position (and angle) from bridge readings",
        description="Force, position and, for biaxial sensors, the force angle for every row of "
                    "readings.csv, with the predicted 1-sigma of each.")
    p.add_argument("calibration", help="calibration.json from `fpdesign calibrate`")
    p.add_argument("readings", help="readings.csv; force and position columns, if any, are compared")
    p.add_argument("-o", "--output", help="write results to this CSV (N, mm, degrees)")
    p.add_argument("--noise", help="sigma_V per channel, e.g. '1.3 mV' (default: the calibration's)")
    p.set_defaults(func=run_measure)

    p = subparsers.add_parser(
        "simulate-readings", help="noisy bridge readings of a design at known loads",
        description="Write a readings.csv of simulated noisy readings of the design's sensor: the paper's "
                    "Table 2 loads for its prototypes (scheme paper), the 4- or 9-point calibration "
                    "schemes, or a 7 x 7 grid over the region. The seed names a simulated sensor (its "
                    "bridge offsets); each scheme gets independent noise.")
    p.add_argument("design", help="design.json")
    p.add_argument("-o", "--output", required=True, help="readings.csv to write")
    p.add_argument("--scheme", choices=SCHEMES, default="paper")
    p.add_argument("--seed", type=seed, default=0, help="names the simulated sensor, 0 or more [0]")
    p.add_argument("--repeats", type=_repeats, default=1, help="readings per load (default 1)")
    p.add_argument("--counts", action="store_true",
                   help="write the front-end's counts (C1, C2, ...) instead of volts (a design with electronics.adc)")
    p.set_defaults(func=run_simulate_readings)


#: Tables are wider than the 80 columns rich assumes when output is not a terminal.
PIPED_WIDTH = 120


def _console():
    from rich.console import Console

    console = Console(highlight=False)
    if not console.is_terminal:
        console = Console(highlight=False, width=max(console.width, PIPED_WIDTH))
    return console


def _print_warnings(console, warnings) -> None:
    from rich.markup import escape

    for w in warnings:
        console.print(f"[yellow]warning:[/yellow] {escape(w)}", soft_wrap=True)


# --------------------------------------------------------------------- plan

def run_plan(args) -> int:
    from rich.markup import escape
    from rich.table import Table

    from designer.calibration import readings
    from designer.calibration.data import STANDARD_GRAVITY
    from designer.calibration.design import design_constants
    from designer.calibration.schemes import plan

    guard_inputs({"-o": args.output}, {"design.json": args.design})
    design = design_constants(readings.read_design(args.design))
    result = plan(design, args.repeats)
    if args.output:
        readings.write_plan(args.output, result)
    console = _console()
    biaxial = design.axes == 2
    counts = "" if design.volts_per_count is None else f" = {design.noise / design.volts_per_count:.3g} counts"
    table = Table(title=f"Calibration plan for {escape(design.name)} (sigma_V {design.noise * MV:.3g} mV{counts}, "
                        f"{args.repeats} reading(s) per load)")
    for col in ("scheme", "loads", "σF/F worst", "σF/F + cal.", "σx worst", "σx + cal.") + (
            ("σθ worst", "σθ + cal.") if biaxial else ()):
        table.add_column(col, justify="right")
    for s in result.schemes:
        row = [f"{s.scheme}-point", str(s.loadings), f"{s.force_error:.3%}", f"{s.force_error_calibrated:.3%}",
               f"{s.position_error * MM:.3g} mm", f"{s.position_error_calibrated * MM:.3g} mm"]
        if biaxial:
            row += [f"{math.degrees(s.angle_error):.3g}°", f"{math.degrees(s.angle_error_calibrated):.3g}°"]
        table.add_row(*row)
    console.print(table)
    loads = Table(title="Loads (each scheme; the 9-point scheme includes the 4 corners)")
    for col in ("scheme", "point", "mass (g)", "force (N)", "position (mm)") + (("angle (°)",) if biaxial else ()):
        loads.add_column(col, justify="right")
    for s in result.schemes:
        for i in range(len(s.loads)):
            f = s.loads.force[i]
            row = [s.scheme, str(i + 1), f"{f / STANDARD_GRAVITY * 1e3:.5g}", f"{f:.4g}",
                   f"{s.loads.position[i] * MM:.5g}"]
            if biaxial:
                row.append(f"{math.degrees(s.loads.angle[i]):.0f}")
            loads.add_row(*row)
    console.print(loads)
    console.print("σ: worst 1-sigma over the region (force relative, position absolute); '+ cal.' adds the "
                  "uncertainty of the calibration constants fitted from that scheme.")
    if args.output:
        console.print(f"wrote {args.output}")
    return 0


# --------------------------------------------------------------------- calibrate

def run_calibrate(args) -> int:
    from rich.markup import escape
    from rich.table import Table

    from designer.calibration import readings
    from designer.calibration.design import design_constants
    from designer.calibration.fit import calibrate
    from designer.errors import DesignFileError

    guard_inputs({"-o": args.output}, {"readings": args.readings, "design.json": args.design})
    data = readings.read_readings(args.readings, need_loads=True)
    design = None
    if args.design:
        try:
            design = design_constants(readings.read_design(args.design))
        except DesignFileError as exc:   # (two JSON files may be given: say which one)
            raise DesignFileError(str(exc) if str(exc).startswith(str(args.design)) else
                                  f"--design {args.design}: {exc}") from exc
    per_count = None if design is None else design.volts_per_count
    data = readings.in_volts(data, per_count, "give --design, a design.json with electronics.adc" if design is None
                             else f"--design {args.design} has no front-end of the catalogue (electronics.adc)")
    result = replace(calibrate(data, design, args.noise, design_option="--design"), volts_per_count=per_count)
    readings.write_calibration(args.output, result)

    console = _console()
    table = Table(title=f"Calibration of {escape(args.readings)}: {result.points} points")
    columns = ["bridge", "k (V/(N·m))", "d (mm)", "c (mV)", "R²", "residual RMS (mV)"]
    if design is not None:
        columns += ["design k", "design d (mm)"]
    for col in columns:
        table.add_column(col, justify="right")

    def pm(value, se, scale=1.0, digits=5):
        text = f"{value * scale:.{digits}g}"
        return text if se is None else f"{text} ± {se * scale:.2g}"

    for b in result.bridges:
        row = [b.name, pm(b.k, b.se_k), pm(b.d, b.se_d, MM), pm(b.c, b.se_c, MV, 4),
               "-" if b.r2 is None else f"{b.r2:.6f}", f"{b.residual_rms * MV:.3g}"]
        if design is not None:
            row += [f"{b.design_k:.5g}", f"{b.design_d * MM:.4g}"]
        table.add_row(*row)
    console.print(table)
    noise = ("none" if result.noise is None else
             f"{result.noise * MV:.3g} mV ({result.noise_source}"
             + (f", {result.residual_dof} residual dof" if result.noise_source == "residual" else "") + ")")
    console.print(f"noise sigma_V used for standard errors and measurements: {noise}")
    _print_warnings(console, result.warnings)
    console.print(f"wrote {args.output}")
    return 0


# --------------------------------------------------------------------- measure

def run_measure(args) -> int:
    import numpy as np
    from rich.markup import escape
    from rich.table import Table

    from designer.calibration import readings
    from designer.calibration.measurement import CONSISTENT_RATIO, error_ratios, measure_readings
    from designer.spec import units

    guard_inputs({"-o": args.output}, {"calibration.json": args.calibration, "readings": args.readings})
    cal = readings.read_calibration(args.calibration)
    data = readings.in_volts(readings.read_readings(args.readings), cal.volts_per_count,
                             "calibrate with --design of a design with electronics.adc")
    noise = units.parse_positive(args.noise, "voltage", "--noise") if args.noise is not None else None
    m = measure_readings(cal, data, noise)
    if args.output:
        readings.write_results(args.output, m)
    console = _console()
    biaxial = m.angle is not None
    if not args.output:
        table = Table(title=f"Measurements from {escape(args.readings)}")
        for col in ("row", "force (N)", "position (mm)") + (("angle (°)",) if biaxial else ()):
            table.add_column(col, justify="right")
        def cell(value, sigma, digits=".4g"):   # without a noise figure, no 1-sigma ("± nan")
            return f"{value:{digits}}" + (f" ± {sigma:.2g}" if math.isfinite(sigma) else "")

        for i in range(len(m)):
            row = [str(i + 1), cell(m.force[i], m.sigma_force[i]),
                   cell(m.position[i] * MM, m.sigma_position[i] * MM)]
            if biaxial:
                row.append(cell(math.degrees(m.angle[i]), math.degrees(m.sigma_angle[i]), ".3g"))
            table.add_row(*row)
        console.print(table)
    if (data.force is None) != (data.position is None):
        console.print("the file's loads are not compared with the estimates: that needs a force (force_N or "
                      "mass_g) and a position_mm column, and it has " + ("only the force" if data.position is None
                                                                          else "only position_mm"))
    loaded = None if data.force is None or data.position is None else np.abs(data.force) > 0
    if loaded is not None and loaded.any():
        # relative errors as the paper's Table 4 gives them, over the rows that carry a load (the
        # position's over those away from the clamp: a load at 0 mm has no relative position error)
        ef = np.abs(m.force - data.force)[loaded] / np.abs(data.force[loaded])
        away = loaded & (data.position > 0)
        ex = np.abs(m.position - data.position)[away] / data.position[away]
        # three significant digits: a good sensor's errors are hundredths of a per cent ("0.00%" said nothing)
        position = (f"{np.mean(ex) * 100:.3g} %" + ("" if away.sum() == loaded.sum() else
                                                    f" (over the {int(away.sum())} of them away from the clamp)")
                    if away.any() else "none (every loaded row is at the clamp, 0 mm)")
        text = (f"against the file's loads ({int(loaded.sum())} loaded rows): mean absolute error force "
                f"{np.mean(ef) * 100:.3g} %, position {position}")
        if biaxial and data.angle is not None:
            ea = np.abs(np.degrees(np.angle(np.exp(1j * (m.angle - data.angle)))))[loaded]
            text += f", angle {np.mean(ea):.3g}°"
        ratios = error_ratios(m, data.force, data.position, data.angle if biaxial else None)
        if all(math.isfinite(r) for r in ratios):
            text += (f"; errors over their predicted 1σ, RMS: force {ratios[0]:.3g}, position {ratios[1]:.3g}"
                     + (f", angle {ratios[2]:.3g}" if len(ratios) == 3 else "")
                     + " (about 1 where the sensor measures as predicted)")
        console.print(text)
        if max(ratios) > CONSISTENT_RATIO:   # (NaN compares False)
            sigma_v = cal.noise if noise is None else noise
            # force and position read as calibrated, the angle not: the sensor has turned in its clamp
            turned = len(ratios) == 3 and max(ratios[:2]) <= CONSISTENT_RATIO
            _print_warnings(console, [f"the estimates miss the file's loads by {max(ratios):.3g} times their "
                                      f"predicted 1σ (RMS{', the angle' if turned else ''}; at most about "
                                      f"{CONSISTENT_RATIO:g} when the readings are of the calibrated sensor): "
                                      + ("the sensor has turned about its axis since calibrating (or the file's "
                                         "angle_deg measured from another direction), " if turned else "")
                                      + "readings of another sensor or calibration.json, a zero that has moved "
                                      f"since calibrating, or more noise than the σ_V {sigma_v * MV:.3g} mV used"])
    if cal.noise is None and noise is None:
        console.print("the calibration has no noise estimate; give --noise for the 1-sigma columns")
    outside = int(np.sum(m.outside))
    if outside:
        _print_warnings(console, [f"{outside} of {len(m)} rows lie outside the calibrated span "
                                  f"({cal.force_span[0]:.4g}-{cal.force_span[1]:.4g} N, "
                                  f"{cal.position_span[0] * MM:.4g}-{cal.position_span[1] * MM:.4g} mm): "
                                  "extrapolated (column outside_calibration)"])
    if args.output:
        console.print(f"wrote {args.output} ({len(m)} rows)")
    return 0


# --------------------------------------------------------------------- simulate-readings

def run_simulate_readings(args) -> int:
    from designer.calibration import readings
    from designer.calibration.design import design_constants
    from designer.calibration.schemes import scheme_loads

    guard_inputs({"-o": args.output}, {"design.json": args.design})
    record = readings.read_design(args.design)
    design = design_constants(record)
    readings.write_simulated_readings(record, args.output, args.scheme, args.seed, args.repeats, args.counts)
    loads = scheme_loads(design, args.scheme)
    source = ("the paper's Table 2" if args.scheme == "paper" and design.prototype
              else f"scheme {args.scheme} over the design's region")
    _console().print(f"wrote {args.output}: {len(loads) * args.repeats} readings of {design.name} at {source}, "
                     f"sigma_V {design.noise * MV:.3g} mV, seed {args.seed}")
    return 0
