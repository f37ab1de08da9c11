"""``fpdesign export``: the CAD model of a design (STEP, STL) and its drawing and picture."""

from __future__ import annotations

from pathlib import Path

from designer.cli.paths import guard_inputs
from designer.errors import InputError

# The suffixes of each output's format (any case): a picture written as PNG into model.jpg would
# not open as what its name says. A name without a suffix (a device, a pipe) is written as given.
SUFFIXES = {"step": (".step", ".stp"), "stl": (".stl",), "svg": (".svg",), "png": (".png",), "drawing_png": (".png",)}


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "export", help="write the beam's CAD model (STEP, STL), a dimensioned drawing and a 3-D picture",
        description="Write the beam of a design.json as a machinable CAD model: STEP and STL in millimetres "
                    "(origin on the beam's axis at the clamp face, +X to the free end, Z the load direction), "
                    "a dimensioned two-view drawing (SVG or PNG) and a rendered picture (PNG). "
                    "Clamp block, end mill and its corner radius, wire channels and load grooves follow the spec's "
                    "'cad' keys.")
    p.add_argument("design", help="design.json written by 'fpdesign optimize' or 'fpdesign evaluate'")
    p.add_argument("--step", metavar="FILE", help="the solid as STEP (AP214, mm, product named after the design)")
    p.add_argument("--stl", metavar="FILE", help="the solid as binary STL (mm, 0.01 mm chordal tolerance)")
    p.add_argument("--svg", metavar="FILE", help="the dimensioned drawing as SVG")
    p.add_argument("--drawing-png", metavar="FILE", dest="drawing_png", help="the dimensioned drawing as PNG")
    p.add_argument("--png", metavar="FILE", help="a rendered picture of the 3-D model as PNG")
    p.set_defaults(func=run_export)


def run_export(args) -> int:
    from designer.outputs.cad.writer import export
    from designer.result.designfile import load_design

    outputs = {"step": args.step, "stl": args.stl, "svg": args.svg, "png": args.png, "drawing_png": args.drawing_png}
    if not any(outputs.values()):
        raise InputError("export: nothing to write; give at least one of --step, --stl, --svg, --drawing-png, --png")
    guard_inputs({f"--{k.replace('_', '-')}": v for k, v in outputs.items()}, {"design.json": args.design})
    for kind, path in outputs.items():
        suffix = Path(path).suffix.lower() if path else ""
        if suffix and suffix not in SUFFIXES[kind]:
            raise InputError(f"--{kind.replace('_', '-')}: {path} names another format than it is written in; "
                             f"its suffix must be {' or '.join(SUFFIXES[kind])} (or none)")
    record = load_design(args.design)
    written = export(record, **outputs)
    for kind, path in written.items():
        print(f"wrote {path}")
    return 0
