"""The predicted error maps (the paper's Figs. 16-17): sigma_F/F, sigma_x and sigma_x/x over
the operating region from the estimator, so that what is drawn is what it predicts."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from designer.errors import DesignFileError
from designer.model import estimator
from designer.outputs.plots.common import design_title, fmt_number, log_force_axis, nice_levels, region_outline
from designer.outputs.plots.sensor import SensorData


@dataclass(frozen=True)
class ErrorMap:
    """Predicted 1-sigma errors on a force x position grid (arrays indexed [force, position])."""

    force: np.ndarray            # N, (nf,)
    position: np.ndarray         # m, (nx,)
    force_error: np.ndarray      # sigma_F / F, (nf, nx)
    position_error: np.ndarray   # sigma_x, m, (nf, nx)

    @property
    def relative_position_error(self) -> np.ndarray:
        """sigma_x / x."""
        return self.position_error / self.position[None, :]


def error_map(design: Mapping, force=None, position=None, n: int = 61) -> ErrorMap:
    """sigma_F/F and sigma_x over the operating region (default: n x n points, force
    log-spaced from F_min to F_max, position from x_min to x_max), from the estimator."""
    s = SensorData.from_design(design)
    force = np.geomspace(s.force_min, s.force_max, n) if force is None else np.asarray(force, float)
    position = np.linspace(s.position_min, s.position_max, n) if position is None \
        else np.asarray(position, float)
    f, x = np.meshgrid(force, position, indexing="ij")
    recorded = (design.get("predicted") or {}).get("budget")
    if recorded is not None:  # the whole error budget (docs/model.md §13), not the noise alone
        u_f, u_x = _combined(design, s, recorded, f, x)
        return ErrorMap(force, position, u_f, u_x)
    sigma_f, sigma_x = estimator.sigmas(s.sensitivity, s.stations, s.noise, f, x)
    return ErrorMap(force, position, np.broadcast_to(sigma_f / f, f.shape).copy(), np.asarray(sigma_x))


def _combined(design: Mapping, s: SensorData, recorded: Mapping, f, x):
    """The combined standard uncertainty of the error budget at every ``(f, x)``."""
    from designer.model import budget

    try:
        inputs = budget.inputs_from_record(recorded["inputs"], (s.force_min, s.force_max),
                                           (s.position_min, s.position_max))
        full = design["predicted"]["gauge_strain"]
    except (KeyError, TypeError) as exc:
        raise DesignFileError(f"predicted.budget.inputs: {exc} is missing; the error maps need the budget's "
                              "inputs") from exc
    strains = [e * f * (x - d) / (s.force_max * (s.position_max - d)) for e, d in zip(full, s.stations)]
    terms = budget.contributions(list(s.sensitivity), list(s.stations), f, x, strains, inputs)
    u_f, u_x = budget.combined(terms)
    return np.asarray(u_f), np.asarray(u_x)


def worst_errors(design: Mapping) -> tuple[float, float]:
    """The worst case over the region: sigma_F / F_min and sigma_x(F_min, x_max) of the noise
    (MODEL.md section 3), or with the error budget the largest combined uncertainties over the
    region's corners (docs/model.md §13)."""
    s = SensorData.from_design(design)
    m = error_map(design, force=[s.force_min, s.force_max], position=[s.position_min, s.position_max])
    if (design.get("predicted") or {}).get("budget") is None:
        return float(m.force_error[0, 1]), float(m.position_error[0, 1])
    return float(m.force_error.max()), float(m.position_error.max())


def plot_error_maps(design: Mapping, fig=None):
    """The paper's Figs. 16-17 from the linear propagation of MODEL.md section 3: filled maps of
    sigma_F/F (%), sigma_x (mm) and sigma_x/x (%) over position and force (log), the target
    contours and the worst case. The maps extend below F_min (faded) so the target contour shows."""
    s = SensorData.from_design(design)
    if fig is None:
        from matplotlib.figure import Figure

        fig = Figure(figsize=(16.5, 5.4), layout="constrained")
    axes = fig.subplots(1, 3)

    fe_min, pe_min = worst_errors(design)
    need_f = fe_min * s.force_min / s.force_target if s.force_target else math.inf
    need_x = pe_min * s.force_min / s.position_target if s.position_target else math.inf
    f_lo = min(s.force_min / 1.6, 0.75 * min(need_f, need_x))
    f_lo = max(f_lo, s.force_min / 2)  # the operating region keeps most of the panel
    force = np.geomspace(f_lo, s.force_max, 121)
    position = np.linspace(s.position_min, s.position_max, 91)
    emap = error_map(design, force=force, position=position)
    xg, fg = np.meshgrid(position * 1e3, force)

    total = (design.get("predicted") or {}).get("budget") is not None
    f_name, x_name = ("u_c(F)", "u_c(x)") if total else ("σ_F", "σ_x")
    panels = (
        (emap.force_error * 100, f"force error {f_name} / F (%)", "%",
         None if s.force_target is None else s.force_target * 100, fe_min * 100,
         "whole error budget" if total else "independent of position"),
        (emap.position_error * 1e3, f"position error {x_name} (mm)", "mm",
         None if s.position_target is None else s.position_target * 1e3, pe_min * 1e3,
         "rises with position"),
        (emap.relative_position_error * 100, f"position error {x_name} / x (%)", "%",
         None, pe_min / s.position_max * 100, "rises with position"),
    )
    for ax, (z, title, unit, target, worst, note) in zip(axes, panels):
        _error_panel(fig, ax, s, xg, fg, z, title, unit, target, worst, note, f_lo)
    what = ("Combined 1σ uncertainty of the whole error budget (noise, temperature, creep, calibration)" if total
            else "Predicted 1σ errors")
    fig.suptitle(f"{what}, σ_V = {fmt_number(s.noise * 1e3)} mV per bridge: {design_title(s)}", fontsize=11.5)
    return fig


def _error_panel(fig, ax, s: SensorData, xg, fg, z, title, unit, target, worst, note, f_lo):
    from matplotlib.colors import BoundaryNorm
    from matplotlib.patches import Rectangle

    levels = nice_levels(float(z.min()), float(z.max()))
    cmap = _colormap("YlOrRd")
    norm = BoundaryNorm(levels, cmap.N)
    filled = ax.contourf(xg, fg, z, levels=levels, cmap=cmap, norm=norm, zorder=1)
    lines = ax.contour(xg, fg, z, levels=levels, colors="#555555", linewidths=0.4, zorder=2)
    ax.clabel(lines, fmt=lambda v: f"{v:g}", fontsize=7, inline_spacing=1)
    bar = fig.colorbar(filled, ax=ax, ticks=levels, pad=0.02)
    bar.set_label(title)
    bar.ax.set_yticklabels([f"{v:g}" for v in levels])

    if s.force_min > f_lo:  # fade the loads below F_min: outside the operating region
        ax.add_patch(Rectangle((xg.min(), f_lo), xg.max() - xg.min(), s.force_min - f_lo,
                               facecolor="white", alpha=0.7, edgecolor="#a0a0a0", hatch="//",
                               linewidth=0, zorder=3))
    region_outline(ax, s, label=None, zorder=5)

    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="black", linewidth=1.6, label="operating region")]
    if target is not None:
        met = worst <= target
        if float(z.min()) <= target <= float(z.max()):
            ax.contour(xg, fg, z, levels=[target], colors="#0b3d91", linewidths=2.2,
                       linestyles="--", zorder=6)
        inside = fg >= s.force_min * (1 - 1e-9)   # the operating region (the grid's lower loads are faded)
        best = float(z[inside].min()) if inside.any() else float(z.min())
        state = ("met over the whole region" if met else "missed over the whole region" if best > target
                 else "missed in part of the region")
        handles.append(Line2D([], [], color="#0b3d91", linewidth=2.2, linestyle="--",
                              label=f"target {target:g} {unit}: {state}"))
    x_w, f_w = s.position_max * 1e3, s.force_min
    ax.plot([x_w], [f_w], marker="*", markersize=15, color="#0b3d91", markeredgecolor="white", zorder=8,
            clip_on=False)
    handles.append(Line2D([], [], marker="*", markersize=12, color="#0b3d91", linestyle="none",
                          label=f"worst case {fmt_number(worst)} {unit} (F_min, x_max)"))
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.92)

    log_force_axis(ax, float(fg.min()), float(fg.max()))
    ax.set_xlim(float(xg.min()), float(xg.max()))
    ax.set_xlabel("load position x from the clamp (mm)")
    ax.set_ylabel("force F (N)")
    ax.set_title(f"{title}: {note}, falls with load", fontsize=10)


def _colormap(name: str):
    import matplotlib

    return matplotlib.colormaps[name]
