"""Writing every plot of a design as PNG (and, when asked, SVG) files: all of them or none."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from designer.errors import InputError, brief, describe_allowed
from designer.outputs.drawing.figures import figure_bytes
from designer.outputs.plots.budget import plot_budget
from designer.outputs.plots.candidates import plot_candidates
from designer.outputs.plots.error_maps import plot_error_maps
from designer.outputs.plots.isolines import plot_voltage_isolines
from designer.outputs.plots.region import plot_operating_region
from designer.outputs.plots.sensor import SensorData
from designer.outputs.plots.tradeoff import TRADEOFF_ALIASES, TRADEOFF_AXES, plot_tradeoff, tradeoff_points

# Stable file names of write_design_plots (SPEC.md: the plots an optimize run writes).
PLOT_NAMES = ("operating-region", "voltage-isolines", "error-maps", "candidates",
              "tradeoff-deflection", "tradeoff-frequency")
BUDGET_PLOT = "error-budget"   # only for a design with an error budget (a spec's environment)
FORMATS = ("png", "svg")
DEFAULT_FORMATS = ("png",)   # SVG copies only when asked: each doubles a plot's drawing time
PNG_DPI = 150


def write_design_plots(design: Mapping, out_dir, formats: Sequence[str] = DEFAULT_FORMATS,
                       tradeoff: Mapping[str, Sequence[Mapping]] | None = None, progress=None,
                       claim=None, last_first: bool = False) -> list[Path]:
    """Write the plots of a design into ``out_dir``; all of them or none.

    Files: ``operating-region``, ``voltage-isolines``, ``error-maps``, ``candidates``, with an
    error budget (a spec's ``environment``) ``error-budget``, and, when
    trade-off points are given (``tradeoff={"max_deflection": [...], "min_frequency": [...]}``, or a
    ``"tradeoff"`` key of the design), ``tradeoff-deflection`` and ``tradeoff-frequency``; each in
    every format of ``formats`` (``"png"``, ``"svg"``). Returns the paths written. ``progress``,
    if given, is called as ``progress(done, total)`` after each plot. ``claim``, if given, is
    called with each plot's name before it is drawn, and the plot is left to another process when
    it returns False: the job's two processes share the plots, the CAD process from the first,
    the other one the design's own from the last (``last_first``), the trade-off plots last.
    """
    from designer.outputs.files import staged_directory

    formats = tuple(formats)
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise InputError(f"format: {bad[0] if bad else formats!r} is not allowed; must be "
                         f"{describe_allowed(FORMATS)}")
    SensorData.from_design(design)  # check the file before drawing anything
    if tradeoff is None:
        tradeoff = design.get("tradeoff") or {}
    if not isinstance(tradeoff, Mapping):
        raise InputError(f"tradeoff: {brief(tradeoff)} must map max_deflection / min_frequency to lists of points")
    fronts = {}
    for key, points in tradeoff.items():
        name = TRADEOFF_ALIASES.get(key, key)
        if name not in TRADEOFF_AXES:
            raise InputError(f"tradeoff.{key}: unknown front; must be {describe_allowed(TRADEOFF_AXES)}")
        if points:
            tradeoff_points(points, name)  # check every point before drawing anything
            fronts[name] = points

    makers = [("operating-region", lambda: plot_operating_region(design)),
              ("voltage-isolines", lambda: plot_voltage_isolines(design)),
              ("error-maps", lambda: plot_error_maps(design)),
              ("candidates", lambda: plot_candidates(design))]
    if (design.get("predicted") or {}).get("budget") is not None:
        makers.append((BUDGET_PLOT, lambda: plot_budget(design)))
    for name, points in fronts.items():
        chosen = _chosen_point(design, name)
        makers.append((TRADEOFF_AXES[name][2],
                       lambda p=points, c=chosen, n=name: plot_tradeoff(p, chosen=c, x=n)))

    if last_first:   # the design's own plots from the last, then the trade-off plots
        own = len(makers) - len(fronts)
        makers = makers[:own][::-1] + makers[own:]
    out_dir = Path(out_dir)
    written = []
    with staged_directory(out_dir) as scratch:
        for i, (name, make) in enumerate(makers):
            if claim is not None and not claim(name):
                continue
            fig = make()
            for fmt in formats:
                # (SVG with salted ids: the same design gives the same file)
                (scratch / f"{name}.{fmt}").write_bytes(figure_bytes(fig, fmt, PNG_DPI))
                written.append(out_dir / f"{name}.{fmt}")
            if progress is not None:
                progress(i + 1, len(makers))
    return written


def _chosen_point(design: Mapping, x: str) -> dict | None:
    """Where the chosen design sits on a front: its own deflection or frequency, and its e."""
    s = SensorData.from_design(design)
    value = s.deflection if x == "max_deflection" else s.natural_frequency
    objective = s.error_ratio if s.error_ratio is not None else s.objective
    if value is None or objective is None:
        return None
    return {"material": s.material, "section": s.section, "x": value, "objective": objective}
