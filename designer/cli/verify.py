"""verify: the 3-D finite-element check of a design.json (designer.checks.fea)."""

from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("verify", help="check a design with a 3-D finite-element model of its STEP solid")
    p.add_argument("design", help="design.json written by optimize or evaluate")
    p.add_argument("-o", "--output", default="verify", help="output folder for verify.md, verify.json and "
                                                           "surface-strain.png [verify]")
    p.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"),
                   help="mesh size: coarse, normal or fine [normal]; a second mesh 1.5 x coarser checks "
                        "convergence")
    p.set_defaults(func=run_verify)


def run_verify(args) -> int:
    from designer.checks import fea
    from designer.result.designfile import load_design
    from designer.cli.paths import output_folder

    out_dir = output_folder(args.output, what="the verify report")
    record = load_design(args.design)
    result = fea.verify_design(record, mesh=args.mesh, out_dir=out_dir, mesh_option="--mesh")
    _print_summary(result)
    print(f"wrote {out_dir / 'verify.md'}, {out_dir / 'verify.json'} and {out_dir / 'surface-strain.png'}")
    return 0 if result.passed else 1


def _print_summary(result) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"{result.name}: 3-D check ({result.mesh} mesh, {result.seconds:.0f} s)")
    table.add_column("quantity")
    table.add_column("3-D", justify="right")
    table.add_column("beam model", justify="right")
    table.add_column("3-D / model", justify="right")
    for i, g in enumerate(result.gauges):
        table.add_row(f"gauge {i + 1} strain at {g.station * 1e3:.1f} mm (µε)", f"{g.fea_strain * 1e6:.1f}",
                      f"{g.model_strain * 1e6:.1f}", f"{g.ratio:.3f}")
    table.add_row("free-end deflection (mm)", f"{result.deflection_fea * 1e3:.3f}",
                  f"{result.deflection_model * 1e3:.3f}", f"{result.deflection_fea / result.deflection_model:.3f}")
    table.add_row(f"peak stress (MPa), {result.stress_peak.where}",
                  f"{result.stress_peak.value / 1e6:.1f}", f"{result.stress_model_at_peak / 1e6:.1f}",
                  f"{result.stress_peak.value / result.stress_model_at_peak:.3f}")
    console = Console()
    console.print(table)
    for message in result.messages:
        console.print(f"- {message}", highlight=False, markup=False)
