"""plot (the charts of a design.json)."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import DesignFileError, InputError

FORMAT_CHOICES = {"png": ("png",), "svg": ("svg",), "both": ("png", "svg")}


def register(sub) -> None:
    _register_plot(sub)


def _register_plot(sub) -> None:
    p = sub.add_parser(
        "plot", help="draw the plots of a design.json (operating region, isolines, error maps, ...)",
        description="Write the operating region, the bridge voltage isolines, the error maps, the "
                    "candidate ranking and, with --tradeoff or a 'tradeoff' key in the file, the "
                    "trade-off fronts of a design.json.")
    p.add_argument("design", help="design.json written by optimize or evaluate")
    p.add_argument("-o", "--output", default=None,
                   help="folder for the plots [the folder of design.json]")
    p.add_argument("--format", choices=tuple(FORMAT_CHOICES), default="both",
                   help="png, svg or both [both]")
    p.add_argument("--tradeoff", metavar="JSON", default=None,
                   help="trade-off points: {\"max_deflection\": [...], \"min_frequency\": [...]}, each "
                        "point {material, section, x, objective, feasible}")
    p.set_defaults(func=run_plot)


def run_plot(args) -> int:
    from .. import plots

    design = _load_design(args.design)
    tradeoff = _load_json(args.tradeoff, "--tradeoff") if args.tradeoff else None
    out_dir = Path(args.output) if args.output else Path(args.design).resolve().parent
    try:
        paths = plots.write_design_plots(design, out_dir, formats=FORMAT_CHOICES[args.format],
                                         tradeoff=tradeoff)
    except OSError as exc:
        raise InputError(f"{out_dir}: cannot write the plots there ({exc.strerror or exc}); "
                         "choose another folder with -o") from exc
    for path in paths:
        print(path)
    return 0


def _load_design(path: str) -> dict:
    """design.json read and validated by the design-file module."""
    from ..designfile import load_design

    return load_design(path)


def _load_json(path: str, what: str):
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError as exc:
        raise InputError(f"{what} {path}: no such file") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{what} {path}: cannot be read ({exc})") from exc
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise DesignFileError(f"{what} {path}: not valid JSON at line {exc.lineno}, column {exc.colno}: "
                              f"{exc.msg}") from exc
