"""Plots of a finished design and of the search's trade-offs (PNG and SVG).

The charts follow the source paper (Noh et al. 2025): the operating region bounded by the
moment isolines (its Fig. 3), the bridges' voltage isolines (Fig. 2) and the predicted
error maps over the operating region (Figs. 16-17), plus the ranking of every material and
section family the search tried and the fronts of accuracy against stiffness and speed.

The module has two halves. The first computes, from a design.json dictionary, the numbers
behind the plots (``operating_region``, ``error_map``, ``bridge_map``) as plain frozen
dataclasses and arrays, SI throughout; the error maps use ``designer.estimator`` so that
what is drawn is what the estimator predicts. The second draws them: every ``plot_*``
function takes the data and ``ax=None`` (or ``fig=None``), returns the matplotlib Figure,
never calls ``pyplot`` and never touches the global rcParams. matplotlib is imported only
inside the drawing functions. Axes carry engineering units (N, mm, mV, %, Hz).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from designer.model import estimator
from designer.errors import DesignFileError, InputError, describe_allowed

# Stable file names of write_design_plots (SPEC.md: the plots an optimize run writes).
PLOT_NAMES = ("operating-region", "voltage-isolines", "error-maps", "candidates",
              "tradeoff-deflection", "tradeoff-frequency")
FORMATS = ("png", "svg")
PNG_DPI = 150

# The quantities a trade-off front can be drawn against: axis label, SI -> axis factor, file name.
TRADEOFF_AXES = {
    "max_deflection": ("free-end deflection limit (mm)", 1e3, "tradeoff-deflection"),
    "min_frequency": ("minimum first natural frequency (Hz)", 1.0, "tradeoff-frequency"),
}
_TRADEOFF_ALIASES = {"deflection": "max_deflection", "frequency": "min_frequency",
                     "natural_frequency": "min_frequency"}
TRADEOFF_GROUPS = ("material", "section", "both")

# Colours and marks, passed explicitly to every artist (no global style).
_C_STRAIN = "#c0392b"      # gauge strain limit (maximum moment)
_C_STRESS = "#8e44ad"      # stress limits
_C_SIGNAL = "#1f5fa8"      # minimum detectable signal (minimum moment)
_C_REGION = "#cfe2f3"      # operating region fill
_C_GAUGE = "#d4a017"       # gauge stations (gold, as in the paper's figures)
_C_GRID = "#d9d9d9"
_C_BRIDGES = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b", "#e377c2")
_C_STATUS = {"optimal": "#2e8b57", "feasible": "#2e8b57", "infeasible": "#c0392b", "failed": "#7f7f7f"}
_SECTION_MARKERS = {"rectangle": "s", "round": "o", "tube": "D"}
_MATERIAL_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b",
                     "#e377c2", "#7f7f7f", "#bcbd22", "#17becf")

ERROR_OBJECTIVE_LABEL = ("error objective  e = max(σ_F/F_min ÷ target, σ_x ÷ target)\n"
                         "e ≤ 1 meets both targets")


# =========================================================================== the numbers

@dataclass(frozen=True)
class SensorData:
    """What the plots need from a design.json dictionary, SI units (m, N, V, Pa)."""

    name: str
    status: str
    material: str
    section: str                    # rectangle | round | tube
    feature: str                    # pocket | hole | none
    force_min: float
    force_max: float
    position_min: float
    position_max: float
    stations: tuple[float, ...]     # d_i from the clamp
    sensitivity: tuple[float, ...]  # k_i, V/(N m)
    noise: float                    # sigma_V per channel at the amplifier output, V
    length: float                   # free length, m
    min_snr: float
    gauge_strain: float             # eps_1 under F_max at x_max
    max_strain: float               # the gauge's strain limit
    stress_root: float              # Pa, under F_max at x_max
    stress_feature: float | None    # Pa, at the clamp-side edge of the first feature
    feature_edge: float | None      # m, where stress_feature acts
    stress_allowable: float
    force_target: float | None      # sigma_F / F_min
    position_target: float | None   # sigma_x(F_min, x_max), m
    axes: int
    objective_kind: str             # error | deflection | mass
    objective: float | None
    error_ratio: float | None       # the error objective e, whatever the objective
    deflection: float | None
    natural_frequency: float | None

    @classmethod
    def from_design(cls, design: Mapping) -> "SensorData":
        """Read and check the keys; a missing or impossible value raises DesignFileError."""
        if not isinstance(design, Mapping):
            raise DesignFileError(f"design.json: must be a JSON object, not {type(design).__name__}")
        spec = _key(design, "spec")
        body = _key(design, "design")
        pred = _key(design, "predicted")
        f_min, f_max = _range(_key(spec, "load", "spec"), "force", "spec.load")
        x_min, x_max = _range(spec["load"], "position", "spec.load")
        stations = _numbers(_key(body, "stations", "design"), "design.stations")
        if len(stations) < 2 or any(b <= a for a, b in zip(stations, stations[1:])):
            raise DesignFileError(f"design.stations: {list(stations)!r} must be at least 2 positions "
                                  "increasing from the clamp outwards")
        if not stations[-1] < x_min:
            raise DesignFileError(f"design.stations: the last station ({stations[-1] * 1e3:g} mm) must lie "
                                  f"before the operating region, which starts at {x_min * 1e3:g} mm")
        k = _numbers(_key(pred, "sensitivity", "predicted"), "predicted.sensitivity")
        axes = body.get("axes", 1)
        if axes not in (1, 2):
            raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
        if len(k) == axes * len(stations) and axes > 1:
            k = k[:len(stations)]  # one axis of a biaxial sensor; both axes are alike
        if len(k) != len(stations):
            raise DesignFileError(f"predicted.sensitivity: {len(k)} values for {len(stations)} stations; "
                                  "give one k_i per station")
        section = _key(body, "section", "design")
        feature = body.get("feature") or {"kind": "none"}
        limits = spec.get("limits") or {}
        targets = spec.get("targets") or {}
        stress_root = _positive(pred, "stress_root", "predicted", required=False)
        stress_feature = _positive(pred, "stress_feature", "predicted", required=False)
        if stress_root is None:  # older records: only the largest stress and no location
            stress_root, stress_feature = _positive(pred, "max_stress", "predicted"), None
        edge = _feature_edge(body, spec, stations[0]) if stress_feature is not None else None
        if edge is None:
            stress_feature = None
        return cls(
            name=str(spec.get("name") or "sensor"), status=str(design.get("status", "")),
            material=str(body.get("material", "")), section=str(_key(section, "kind", "design.section")),
            feature=str(feature.get("kind", "none")),
            force_min=f_min, force_max=f_max, position_min=x_min, position_max=x_max,
            stations=stations, sensitivity=k, noise=_noise(pred, spec),
            length=_positive(body, "length", "design"),
            min_snr=_positive(limits, "min_snr", "spec.limits", required=False) or 5.0,
            gauge_strain=_numbers(_key(pred, "gauge_strain", "predicted"), "predicted.gauge_strain")[0],
            max_strain=_max_strain(body, spec),
            stress_root=stress_root, stress_feature=stress_feature, feature_edge=edge,
            stress_allowable=_positive(pred, "stress_allowable", "predicted"),
            force_target=_positive(targets, "force_error", "spec.targets", required=False),
            position_target=_positive(targets, "position_error", "spec.targets", required=False),
            axes=axes, objective_kind=str(spec.get("objective", "error")),
            objective=_optional_number(pred.get("objective")),
            error_ratio=_optional_number(pred.get("error_ratio", pred.get("objective")
                                                  if spec.get("objective", "error") == "error" else None)),
            deflection=_optional_number(pred.get("deflection")),
            natural_frequency=_optional_number(pred.get("natural_frequency")),
        )

    @property
    def offsets(self) -> tuple[float, ...]:
        """Bridge offsets c_i: zero for a balanced, ideal bridge."""
        return (0.0,) * len(self.stations)

    @property
    def label(self) -> str:
        feature = "" if self.feature == "none" else f", {self.feature}s"
        return f"{self.material} {self.section}{feature}"


@dataclass(frozen=True)
class MomentLimit:
    """A limit that is a moment isoline ``F (x - pivot) = moment`` in the (x, F) plane."""

    name: str       # gauge_strain | stress_root | stress_feature | min_signal
    label: str
    moment: float   # N m
    pivot: float    # m: the point the moment is taken about

    def force(self, x):
        """The force on the isoline at position ``x`` (N); ``x`` must lie beyond the pivot."""
        return self.moment / (np.asarray(x, dtype=float) - self.pivot)


@dataclass(frozen=True)
class OperatingRegion:
    """The paper's Fig. 3: the specified region and the moment isolines that bound the
    measurable one (MODEL.md section 4, the paper's eqs. 13-22)."""

    force_min: float
    force_max: float
    position_min: float
    position_max: float
    stations: tuple[float, ...]
    upper: tuple[MomentLimit, ...]   # maximum-moment isolines: the strain and stress limits
    lower: MomentLimit               # minimum-moment isoline: the smallest detectable signal

    def upper_force(self, x):
        """The largest force the limits allow at ``x`` (N)."""
        return np.min([lim.force(x) for lim in self.upper], axis=0)

    @property
    def governing(self) -> MomentLimit:
        """The upper limit that sets the largest force at x_max."""
        return min(self.upper, key=lambda lim: float(lim.force(self.position_max)))

    @property
    def force_max_allowed(self) -> float:
        """Upper corner: the largest force at x_max (eq. 14 solved for F_max)."""
        return float(self.upper_force(self.position_max))

    @property
    def force_min_allowed(self) -> float:
        """Lower corner: the smallest detectable force at x_min (eq. 16 solved for F_min)."""
        return float(self.lower.force(self.position_min))

    @property
    def moment_max(self) -> float:
        """M_max = F_max (x_max - d_1) with the largest allowed F_max (eq. 14), N m."""
        return self.force_max_allowed * (self.position_max - self.stations[0])

    @property
    def moment_min(self) -> float:
        """M_min = F_min (x_min - d_N) (eq. 16), N m."""
        return self.lower.moment

    @property
    def strain_ratio(self) -> float:
        """R_eps = M_max / M_min (eq. 20)."""
        return self.moment_max / self.moment_min

    @property
    def force_ratio(self) -> float:
        """R_F the limits allow: R_eps (x_min - d_N) / (x_max - d_1) (eq. 21)."""
        return self.strain_ratio * (self.position_min - self.stations[-1]) / \
            (self.position_max - self.stations[0])

    @property
    def specified_force_ratio(self) -> float:
        return self.force_max / self.force_min


def operating_region(design: Mapping) -> OperatingRegion:
    """The moment isolines of a design (MODEL.md section 4).

    Every limit is linear in the load, so each one's moment is its value under F_max at x_max
    scaled to its bound: the gauge strain ``eps_1`` about ``d_1``, the root stress about the
    clamp and the stress at the first feature's edge about that edge. The smallest signal,
    ``k_N F (x - d_N) = min_snr sigma_V``, is a moment about ``d_N``.
    """
    s = SensorData.from_design(design)
    lever = s.position_max - s.stations[0]
    upper = [MomentLimit("gauge_strain", "gauge strain limit",
                         s.force_max * lever * s.max_strain / s.gauge_strain, s.stations[0]),
             MomentLimit("stress_root", "stress limit at the root",
                         s.force_max * s.position_max * s.stress_allowable / s.stress_root, 0.0)]
    if s.stress_feature is not None and s.feature != "none":
        upper.append(MomentLimit("stress_feature", f"stress limit at the {s.feature} edge",
                                 s.force_max * (s.position_max - s.feature_edge) * s.stress_allowable
                                 / s.stress_feature, s.feature_edge))
    lower = MomentLimit("min_signal", f"smallest signal ({s.min_snr:g} × noise)",
                        s.min_snr * s.noise / s.sensitivity[-1], s.stations[-1])
    return OperatingRegion(s.force_min, s.force_max, s.position_min, s.position_max, s.stations,
                           tuple(upper), lower)


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
    sigma_f = estimator.sigma_force(s.sensitivity, s.stations, s.noise)
    sigma_x = estimator.sigma_position(s.sensitivity, s.stations, s.noise, f, x)
    return ErrorMap(force, position, np.broadcast_to(sigma_f / f, f.shape).copy(), np.asarray(sigma_x))


def worst_errors(design: Mapping) -> tuple[float, float]:
    """The worst case over the region (MODEL.md section 3): sigma_F / F_min and sigma_x(F_min, x_max)."""
    s = SensorData.from_design(design)
    m = error_map(design, force=[s.force_min], position=[s.position_max])
    return float(m.force_error[0, 0]), float(m.position_error[0, 0])


def bridge_map(design: Mapping, force, position) -> np.ndarray:
    """Noise-free bridge outputs V_i (V) on a grid, indexed [force, position, station]."""
    s = SensorData.from_design(design)
    f, x = np.meshgrid(np.asarray(force, float), np.asarray(position, float), indexing="ij")
    return estimator.bridge_voltages(s.sensitivity, s.stations, s.offsets, f, x)


def example_load(design: Mapping) -> tuple[float, float]:
    """A representative load inside the region for Fig. 2: (x, F), m and N; the middle position
    (to 1 mm) and the geometric mean force (to 2 significant figures)."""
    s = SensorData.from_design(design)
    x = round((s.position_min + s.position_max) / 2, 3)
    f = float(f"{math.sqrt(s.force_min * s.force_max):.2g}")
    return x, min(max(f, s.force_min), s.force_max)


# --------------------------------------------------------------------------- reading helpers

def _key(obj, key: str, where: str = ""):
    path = f"{where}.{key}" if where else key
    if not isinstance(obj, Mapping):
        raise DesignFileError(f"{where or 'design.json'}: {obj!r} must be an object")
    if key not in obj or obj[key] is None:
        raise DesignFileError(f"{path}: missing; the plots need it")
    return obj[key]


def _is_number(value) -> bool:
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value))


def _optional_number(value) -> float | None:
    return float(value) if _is_number(value) else None


def _positive(obj, key: str, where: str, required: bool = True) -> float | None:
    if not isinstance(obj, Mapping) or obj.get(key) is None:
        if required:
            raise DesignFileError(f"{where}.{key}: missing; the plots need it")
        return None
    value = obj[key]
    if not _is_number(value) or value <= 0:
        raise DesignFileError(f"{where}.{key}: {value!r} must be a positive number (SI units)")
    return float(value)


def _numbers(values, where: str) -> tuple[float, ...]:
    if not isinstance(values, Sequence) or isinstance(values, str) or not values:
        raise DesignFileError(f"{where}: {values!r} must be a list of positive numbers")
    for i, v in enumerate(values):
        if not _is_number(v) or v <= 0:
            raise DesignFileError(f"{where}[{i}]: {v!r} must be a positive number (SI units)")
    return tuple(float(v) for v in values)


def _range(obj, key: str, where: str) -> tuple[float, float]:
    lo_hi = _numbers(_key(obj, key, where), f"{where}.{key}")
    if len(lo_hi) != 2 or not lo_hi[0] < lo_hi[1]:
        raise DesignFileError(f"{where}.{key}: {list(lo_hi)!r} must be [min, max] with min < max")
    return lo_hi


def _noise(pred, spec) -> float:
    """sigma_V, V: as predicted, else the output noise the normalised spec records."""
    value = _positive(pred, "noise_voltage", "predicted", required=False)
    el = spec.get("electronics") or {}
    for key in ("noise_output", "noise"):
        if value is None:
            value = _positive(el, key, "spec.electronics", required=False)
    if value is None:
        raise DesignFileError("predicted.noise_voltage: missing, and spec.electronics gives no output "
                              "noise; the error maps need sigma_V")
    return value


def _max_strain(body, spec) -> float:
    for where, gauge in (("design.gauge", body.get("gauge")), ("spec.gauge", spec.get("gauge"))):
        value = _positive(gauge, "max_strain", where, required=False) if isinstance(gauge, Mapping) else None
        if value is not None:
            return value
    raise DesignFileError("design.gauge.max_strain: missing; the strain limit isoline needs it")


def _feature_edge(body, spec, d1: float) -> float | None:
    """s of the first feature's clamp-side edge, d_1 - l_f/2 (MODEL.md sections 1 and 4)."""
    feature = body.get("feature") or {}
    kind = feature.get("kind", "none")
    if kind == "hole":
        length = feature.get("diameter")
    elif kind == "pocket":
        length = feature.get("length")
    else:
        gauge = body.get("gauge") or spec.get("gauge") or {}
        length = gauge.get("length") if isinstance(gauge, Mapping) else None
    if not _is_number(length) or not 0 <= length / 2 < d1:
        return None
    return d1 - length / 2


# =========================================================================== drawing

def _axes(ax, figsize):
    """``(figure, axes)``: the caller's axes, or a new pyplot-free figure."""
    if ax is not None:
        return ax.figure, ax
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    return fig, fig.add_subplot()


def _fmt(value: float, digits: int = 3) -> str:
    """A number to ``digits`` significant figures, without a trailing exponent for usual sizes."""
    if value == 0 or not math.isfinite(value):
        return f"{value:g}"
    places = max(0, digits - 1 - math.floor(math.log10(abs(value))))
    text = f"{value:.{places}f}"
    return text.rstrip("0").rstrip(".") if "." in text else text


def _nice_levels(lo: float, hi: float, mantissas=(1, 1.5, 2, 3, 5, 7)) -> list[float]:
    """Round contour levels from a 1-1.5-2-3-5-7 series that bracket [lo, hi]."""
    if not (lo > 0 and hi > lo):
        return [lo, hi] if hi > lo else [lo * 0.9, lo * 1.1]
    ladder = [m * 10.0 ** e for e in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 2)
              for m in mantissas]
    below = max(v for v in ladder if v <= lo)
    above = min(v for v in ladder if v >= hi)
    levels = [v for v in ladder if below <= v <= above]
    if len(levels) > 14 and len(mantissas) > 3:
        return _nice_levels(lo, hi, (1, 2, 5))
    if len(levels) > 14:
        return _nice_levels(lo, hi, (1,))
    return levels


def _log_force_axis(ax, lo: float, hi: float) -> None:
    from matplotlib.ticker import FuncFormatter, LogLocator

    ax.set_yscale("log")
    ax.set_ylim(lo, hi)
    ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_minor_locator(LogLocator(base=10, subs=tuple(range(1, 10))))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))


def _region_outline(ax, s: SensorData, label: str | None = "operating region", zorder: float = 4):
    from matplotlib.patches import Rectangle

    ax.add_patch(Rectangle((s.position_min * 1e3, s.force_min),
                           (s.position_max - s.position_min) * 1e3, s.force_max - s.force_min,
                           fill=False, edgecolor="black", linewidth=1.6, zorder=zorder, label=label))


def _title(s: SensorData) -> str:
    status = f" ({s.status})" if s.status and s.status not in ("optimal", "feasible") else ""
    axes = ", per axis" if s.axes > 1 else ""
    return f"{s.name}: {s.label}{axes}{status}"


# --------------------------------------------------------------------------- 1. operating region

def plot_operating_region(design: Mapping, ax=None):
    """The paper's Fig. 3 for this design: force (N, log) against position (mm) with the
    maximum-moment isolines (gauge strain, stress), the minimum-moment isoline (smallest
    detectable signal), F_min, F_max, x_min, x_max, the operating region and the gauge stations.
    The force ratio the limits allow (eq. 21) is written on the chart."""
    s = SensorData.from_design(design)
    region = operating_region(design)
    fig, ax = _axes(ax, (9.0, 5.8))

    f_hi_allowed, f_lo_allowed = region.force_max_allowed, region.force_min_allowed
    y_lo = min(f_lo_allowed, s.force_min) / 3
    at_end = [float(lim.force(s.position_max)) for lim in region.upper]
    y_hi = max(min(max(at_end), 10 * f_hi_allowed) * 1.5, s.force_max * 3)
    x_end = max(s.length, s.position_max)
    # dense near each pivot, where the isolines climb steeply
    pivots = sorted({lim.pivot for lim in region.upper} | {region.lower.pivot})
    x = np.unique(np.concatenate([np.linspace(0.0, x_end, 1200)[1:]] +
                                 [p + np.geomspace(1e-5 * x_end, x_end - p, 400) for p in pivots]))

    # measurable but outside the operating region (the paper's hatching)
    beyond = x > s.stations[-1] + 1e-9
    upper = region.upper_force(x)
    lower = np.where(beyond, region.lower.force(np.where(beyond, x, np.inf)), np.inf)
    ax.fill_between(x * 1e3, np.clip(lower, y_lo, y_hi), np.clip(upper, y_lo, y_hi),
                    where=beyond & (upper > lower), facecolor="none", edgecolor="#b0b0b0",
                    hatch="///", linewidth=0, zorder=1,
                    label="measurable, outside the operating region")
    ax.fill_between([s.position_min * 1e3, s.position_max * 1e3], s.force_min, s.force_max,
                    facecolor=_C_REGION, edgecolor="none", zorder=2)
    _region_outline(ax, s, label="operating region (specified)", zorder=5)

    styles = {"gauge_strain": (_C_STRAIN, "-"), "stress_root": (_C_STRESS, "--"),
              "stress_feature": (_C_STRESS, ":")}
    for lim in region.upper:
        colour, style = styles[lim.name]
        xs = x[x > lim.pivot + 1e-9]
        ax.plot(xs * 1e3, lim.force(xs), color=colour, linestyle=style, linewidth=2, zorder=6,
                label=f"{lim.label}:  {_moment_text(lim)} = {_fmt(lim.moment)} N·m")
    xs = x[beyond]
    ax.plot(xs * 1e3, region.lower.force(xs), color=_C_SIGNAL, linewidth=2, zorder=6,
            label=f"{region.lower.label}:  F·(x − d{len(s.stations)}) = {_fmt(region.lower.moment)} N·m")

    # design limits: F_min, F_max (labelled on the right, as in the paper), x_min, x_max
    for value, name in ((s.force_min, "F_min"), (s.force_max, "F_max")):
        ax.axhline(value, color="#555555", linestyle="--", linewidth=0.9, zorder=3)
        ax.annotate(f"{name} = {_fmt(value)} N", (1.0, value), xycoords=("axes fraction", "data"),
                    xytext=(4, 0), textcoords="offset points", va="center", fontsize=9)
    for value, name in ((s.position_min, "x_min"), (s.position_max, "x_max")):
        ax.axvline(value * 1e3, color="#555555", linestyle="-.", linewidth=0.9, zorder=3)
        ax.annotate(f"{name}\n{value * 1e3:g} mm", (value * 1e3, 1.0), xycoords=("data", "axes fraction"),
                    xytext=(0, 4), textcoords="offset points", ha="center", va="bottom", fontsize=9)

    # the corners the isolines set (the paper: they fix the largest and smallest design forces)
    gov = region.governing
    ax.plot([s.position_max * 1e3], [f_hi_allowed], "o", color=_C_STRAIN if gov.name == "gauge_strain"
            else _C_STRESS, markersize=7, markeredgecolor="black", zorder=8)
    ax.annotate(f"largest force at x_max\n{_fmt(f_hi_allowed)} N ({gov.label})",
                (s.position_max * 1e3, f_hi_allowed), xytext=(-10, 8), textcoords="offset points",
                ha="right", va="bottom", fontsize=8.5, zorder=9,
                bbox=dict(boxstyle="round,pad=0.2", facecolor="white", edgecolor="none", alpha=0.8))
    ax.plot([s.position_min * 1e3], [f_lo_allowed], "o", color=_C_SIGNAL, markersize=7,
            markeredgecolor="black", zorder=8)
    ax.annotate(f"smallest force at x_min\n{_fmt(f_lo_allowed)} N", (s.position_min * 1e3, f_lo_allowed),
                xytext=(10, -4), textcoords="offset points", ha="left", va="top", fontsize=8.5, zorder=9,
                bbox=dict(boxstyle="round,pad=0.2", facecolor="white", edgecolor="none", alpha=0.8))

    # gauge stations on the position axis
    for i, d in enumerate(s.stations, start=1):
        ax.axvline(d * 1e3, color=_C_GAUGE, linewidth=1.0, alpha=0.6, zorder=1)
        ax.plot([d * 1e3], [0.0], marker="^", markersize=11, color=_C_GAUGE, markeredgecolor="black",
                transform=ax.get_xaxis_transform(), clip_on=False, zorder=10,
                label="gauge stations" if i == 1 else None)
        ax.annotate(f"d{i}", (d * 1e3, 0.0), xycoords=("data", "axes fraction"), xytext=(0, 9),
                    textcoords="offset points", ha="center", fontsize=9, fontweight="bold")

    ratio = region.force_ratio
    verdict = "fits" if (f_hi_allowed >= s.force_max and f_lo_allowed <= s.force_min) else "does NOT fit"
    ax.text(0.985, 0.03,
            f"force ratio the limits allow (eq. 21):  R_F = {_fmt(ratio)}\n"
            f"  = {_fmt(f_hi_allowed)} N ÷ {_fmt(f_lo_allowed)} N\n"
            f"specified F_max/F_min = {_fmt(region.specified_force_ratio)}: the load range {verdict}",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=9, zorder=11,
            bbox=dict(boxstyle="round,pad=0.4", facecolor="white", edgecolor="#999999"))

    _log_force_axis(ax, y_lo, y_hi)
    ax.set_xlim(0.0, x_end * 1e3)
    ax.set_xlabel("load position x from the clamp (mm)")
    ax.set_ylabel("force F (N)")
    ax.set_title(f"Operating region: {_title(s)}", pad=30, fontsize=11)
    ax.grid(True, which="major", color=_C_GRID, linewidth=0.6, zorder=0)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=2, fontsize=8, frameon=False)
    return fig


def _moment_text(lim: MomentLimit) -> str:
    if lim.name == "gauge_strain":
        return "F·(x − d1)"
    if lim.name == "stress_root":
        return "F·x"
    return f"F·(x − {lim.pivot * 1e3:.4g} mm)"


# --------------------------------------------------------------------------- 2. voltage isolines

def plot_voltage_isolines(design: Mapping, ax=None, load=None):
    """The paper's Fig. 2: each bridge's voltage isolines (mV) over the operating region. A
    reading of every bridge picks one isoline each; the load is where they cross, shown for one
    example load (``load=(x, F)`` in m and N, by default ``example_load(design)``)."""
    s = SensorData.from_design(design)
    fig, ax = _axes(ax, (8.5, 5.8))
    span = s.position_max - s.position_min
    x_lo = max(s.position_min - 0.08 * span, s.stations[-1] + 0.25 * (s.position_min - s.stations[-1]))
    x_hi = s.position_max + 0.04 * span
    f_lo, f_hi = s.force_min / 1.25, s.force_max * 1.25
    force = np.geomspace(f_lo, f_hi, 241)
    position = np.linspace(x_lo, x_hi, 241)
    volts = bridge_map(design, force, position) * 1e3  # mV
    xg, fg = np.meshgrid(position * 1e3, force)

    x_e, f_e = load if load is not None else example_load(design)
    v_e = estimator.bridge_voltages(s.sensitivity, s.stations, s.offsets, f_e, x_e) * 1e3

    _region_outline(ax, s, zorder=3)
    ax.fill_between([s.position_min * 1e3, s.position_max * 1e3], s.force_min, s.force_max,
                    facecolor="#f2f6fb", edgecolor="none", zorder=0)
    from matplotlib.lines import Line2D

    handles = []
    shown = sorted({0, len(s.stations) - 1})
    for j, i in enumerate(shown):
        colour = _C_BRIDGES[j % len(_C_BRIDGES)]
        levels = _nice_levels(float(volts[..., i].min()), float(volts[..., i].max()), (1, 2, 5))
        cs = ax.contour(xg, fg, volts[..., i], levels=levels, colors=colour, linewidths=1.0,
                        linestyles="-" if j == 0 else "--", zorder=4)
        ax.clabel(cs, fmt=lambda v: f"{v:g}", fontsize=7.5, inline_spacing=2)
        ax.contour(xg, fg, volts[..., i], levels=[v_e[i]], colors=colour, linewidths=2.6, zorder=5)
        handles.append(Line2D([], [], color=colour, linestyle="-" if j == 0 else "--",
                              label=f"V{i + 1} isolines, mV (bridge at d{i + 1} = {s.stations[i] * 1e3:g} mm)"))
        handles.append(Line2D([], [], color=colour, linewidth=2.6,
                              label=f"V{i + 1} = {_fmt(v_e[i])} mV for the example load"))
    ax.plot([x_e * 1e3], [f_e], "o", color="black", markersize=8, zorder=7)
    ax.annotate(f"example load\nx = {x_e * 1e3:g} mm, F = {_fmt(f_e)} N", (x_e * 1e3, f_e),
                xytext=(12, 12), textcoords="offset points", fontsize=9, zorder=8,
                bbox=dict(boxstyle="round,pad=0.3", facecolor="white", edgecolor="#999999"))
    handles.append(Line2D([], [], color="black", linewidth=1.6, label="operating region"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.11), ncol=len(shown) + 1,
              fontsize=8, frameon=False)  # one column per bridge

    _log_force_axis(ax, f_lo, f_hi)
    ax.set_xlim(x_lo * 1e3, x_hi * 1e3)
    ax.set_xlabel("load position x from the clamp (mm)")
    ax.set_ylabel("force F (N)")
    ax.set_title(f"Bridge voltage isolines: {_title(s)}\n"
                 "each reading fixes one curve per bridge; the load is where they cross (eqs. 11-12)",
                 fontsize=10.5)
    ax.grid(True, which="major", color=_C_GRID, linewidth=0.6, zorder=0)
    return fig


# --------------------------------------------------------------------------- 3. error maps

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

    panels = (
        (emap.force_error * 100, "force error σ_F / F (%)", "%",
         None if s.force_target is None else s.force_target * 100, fe_min * 100,
         "independent of position"),
        (emap.position_error * 1e3, "position error σ_x (mm)", "mm",
         None if s.position_target is None else s.position_target * 1e3, pe_min * 1e3,
         "rises with position"),
        (emap.relative_position_error * 100, "position error σ_x / x (%)", "%",
         None, pe_min / s.position_max * 100, "rises with position"),
    )
    for ax, (z, title, unit, target, worst, note) in zip(axes, panels):
        _error_panel(fig, ax, s, xg, fg, z, title, unit, target, worst, note, f_lo)
    fig.suptitle(f"Predicted 1σ errors, σ_V = {_fmt(s.noise * 1e3)} mV per bridge: {_title(s)}",
                 fontsize=11.5)
    return fig


def _error_panel(fig, ax, s: SensorData, xg, fg, z, title, unit, target, worst, note, f_lo):
    from matplotlib.colors import BoundaryNorm
    from matplotlib.patches import Rectangle

    levels = _nice_levels(float(z.min()), float(z.max()))
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
    _region_outline(ax, s, label=None, zorder=5)

    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="black", linewidth=1.6, label="operating region")]
    if target is not None:
        met = worst <= target
        if float(z.min()) <= target <= float(z.max()):
            ax.contour(xg, fg, z, levels=[target], colors="#0b3d91", linewidths=2.2,
                       linestyles="--", zorder=6)
        state = "met over the whole region" if met else "missed in part of the region"
        handles.append(Line2D([], [], color="#0b3d91", linewidth=2.2, linestyle="--",
                              label=f"target {target:g} {unit}: {state}"))
    x_w, f_w = s.position_max * 1e3, s.force_min
    ax.plot([x_w], [f_w], marker="*", markersize=15, color="#0b3d91", markeredgecolor="white", zorder=8,
            clip_on=False)
    handles.append(Line2D([], [], marker="*", markersize=12, color="#0b3d91", linestyle="none",
                          label=f"worst case {_fmt(worst)} {unit} (F_min, x_max)"))
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.92)

    _log_force_axis(ax, float(fg.min()), float(fg.max()))
    ax.set_xlim(float(xg.min()), float(xg.max()))
    ax.set_xlabel("load position x from the clamp (mm)")
    ax.set_ylabel("force F (N)")
    ax.set_title(f"{title}: {note}, falls with load", fontsize=10)


def _colormap(name: str):
    import matplotlib

    return matplotlib.colormaps[name]


# --------------------------------------------------------------------------- 4. candidates

def plot_candidates(design: Mapping, ax=None):
    """Every material x section family the search tried, ranked by its objective (horizontal
    bars, best at the top), coloured by status; infeasible ones hatched, the chosen design
    outlined. A design without candidates (``evaluate``) shows itself alone."""
    s = SensorData.from_design(design)
    rows = _candidate_rows(design, s)
    fig, ax = _axes(ax, (10.0, max(3.0, 0.36 * len(rows) + 1.8)))
    kind = s.objective_kind
    scale, axis_label = {"error": (1.0, ERROR_OBJECTIVE_LABEL),
                         "deflection": (1e3, "objective: free-end deflection under F_max at x_max (mm)"),
                         "mass": (1e3, "objective: mass of the free length (g)")}.get(kind, (1.0, "objective"))
    values = [r["objective"] * scale if r["objective"] is not None else None for r in rows]
    known = [v for v in values if v is not None and v > 0]
    log = bool(known) and max(known) / min(known) > 30
    bottom = min(known) / 2 if log else 0.0
    missing_at = (max(known) if known else 1.0)

    y = np.arange(len(rows))
    for yi, row, value in zip(y, rows, values):
        colour = _C_STATUS.get(row["status"], "#7f7f7f")
        infeasible = row["status"] in ("infeasible", "failed")
        if value is None:
            ax.text(bottom if log else 0.0, yi, "  no design found", va="center", fontsize=8, color=colour)
            continue
        ax.barh(yi, value - bottom, left=bottom, height=0.7, color=colour, alpha=0.45 if infeasible else 0.85,
                hatch="xx" if infeasible else None, edgecolor="black" if row["chosen"] else colour,
                linewidth=2.2 if row["chosen"] else 0.6, zorder=3)
        detail = [f"{_fmt(row['deflection'] * 1e3)} mm" if row.get("deflection") is not None else "",
                  f"{_fmt(row['mass'] * 1e3)} g" if row.get("mass") is not None else ""]
        detail = ", ".join(d for d in detail if d)
        text = _fmt(value, 4) + (f"  ({detail})" if detail and kind == "error" else "") + \
            ("   ◀ chosen" if row["chosen"] else "")
        ax.text(value, yi, "  " + text, va="center", fontsize=8,
                fontweight="bold" if row["chosen"] else "normal", zorder=4)
    ax.set_yticks(y, [_candidate_label(r) for r in rows], fontsize=8.5)
    for tick, row in zip(ax.get_yticklabels(), rows):
        if row["chosen"]:
            tick.set_fontweight("bold")
    ax.set_ylim(len(rows) - 0.3, -0.7)  # best at the top
    if log:
        ax.set_xscale("log")
    if kind == "error":
        ax.axvline(1.0, color="black", linestyle="--", linewidth=1.2, zorder=5)
    right = max(known + [1.0 if kind == "error" else missing_at]) * (3.0 if log else 1.45)
    ax.set_xlim(bottom if log else 0.0, right)
    ax.set_xlabel(axis_label, fontsize=9)
    from matplotlib.patches import Patch

    statuses = list(dict.fromkeys(r["status"] for r in rows))
    handles = [Patch(facecolor=_C_STATUS.get(st, "#7f7f7f"), alpha=0.45 if st in ("infeasible", "failed") else 0.85,
                     hatch="xx" if st in ("infeasible", "failed") else None, label=st) for st in statuses]
    handles.append(Patch(facecolor="white", edgecolor="black", linewidth=2.2, label="chosen design"))
    if kind == "error":
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], color="black", linestyle="--", linewidth=1.2,
                              label="e = 1: targets met to the left"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.grid(True, axis="x", which="major", color=_C_GRID, linewidth=0.6, zorder=0)
    if len(rows) > 1:
        ax.set_title(f"Candidates, best first: {s.name} ({len(rows)} material × section)\n"
                     "objectives within 0.1 % tie: lower deflection, then lower mass first (in brackets)",
                     fontsize=10.5)
    else:
        ax.set_title(f"The evaluated design: {s.name} (no search, no other candidates)", fontsize=10.5)
    return fig


def _candidate_rows(design: Mapping, s: SensorData) -> list[dict]:
    raw = design.get("candidates") or []
    if not isinstance(raw, Sequence) or isinstance(raw, str):
        raise DesignFileError(f"candidates: {raw!r} must be a list of objects")
    chosen_labels = {s.section, f"{s.section}+{s.feature}"}
    rows = []
    for i, c in enumerate(raw):
        if not isinstance(c, Mapping):
            raise DesignFileError(f"candidates[{i}]: {c!r} must be an object")
        objective = c.get("objective")
        if objective is not None and not _is_number(objective):
            raise DesignFileError(f"candidates[{i}].objective: {objective!r} must be a number or null")
        rows.append({"material": str(c.get("material", "?")), "section": str(c.get("section", "?")),
                     "status": str(c.get("status", "")), "objective": objective,
                     "deflection": _optional_number(c.get("deflection")),
                     "mass": _optional_number(c.get("mass")),
                     "worst_violation": _optional_number(c.get("worst_violation")),
                     "chosen": str(c.get("material")) == s.material and str(c.get("section")) in chosen_labels})
    if not any(r["chosen"] for r in rows):
        rows.append({"material": s.material, "section": s.section, "status": s.status or "feasible",
                     "objective": s.objective, "deflection": s.deflection,
                     "mass": _optional_number((design.get("predicted") or {}).get("mass")),
                     "worst_violation": None, "chosen": True})
    chosen = [r for r in rows if r["chosen"]]
    for r in chosen[1:]:  # the same material and family twice: only the first is the design
        r["chosen"] = False
    return rank_candidates(rows)


def rank_candidates(rows: Sequence[Mapping]) -> list:
    """Order candidates as MODEL.md section 5 ranks designs: the ones that meet every limit by
    objective, where objectives within 0.1 % tie and the lower deflection, then the lower mass,
    goes first; then the infeasible ones, least violating first; then those without a design."""
    from designer.model import TIE_TOLERANCE  # the search's own tie rule

    def number(row, key):
        value = row.get(key)
        return math.inf if value is None else float(value)

    good = [r for r in rows if r.get("objective") is not None and r.get("status") not in ("infeasible", "failed")]
    bad = [r for r in rows if r.get("objective") is not None and r.get("status") in ("infeasible", "failed")]
    none = [r for r in rows if r.get("objective") is None]
    rest = sorted(good, key=lambda r: r["objective"])
    ranked = []
    while rest:
        lead = rest[0]["objective"]
        ties = [r for r in rest if r["objective"] - lead <= TIE_TOLERANCE * abs(lead)]
        pick = min(ties, key=lambda r: (number(r, "deflection"), number(r, "mass"), r["objective"]))
        ranked.append(pick)
        rest.remove(pick)
    ranked += sorted(bad, key=lambda r: (number(r, "worst_violation"), r["objective"]))
    return ranked + none


def _candidate_label(row: dict) -> str:
    return f"{row['material']} · {row['section']}"


# --------------------------------------------------------------------------- 5. trade-off fronts

def plot_tradeoff(points: Sequence[Mapping], chosen: Mapping | None = None, x: str = "max_deflection",
                  ax=None, by: str = "material"):
    """Trade-off front: the best error objective the search reaches against a limit.

    ``points``: solved designs, each ``{"material", "section", "x": limit value (SI), "objective",
    "feasible": bool}``; ``x``: ``"max_deflection"`` (m, drawn in mm) or ``"min_frequency"`` (Hz);
    ``by``: one line per ``"material"`` (best section at each x, marked by its shape), per
    ``"section"`` (best material) or per material and section (``"both"``). The lower envelope of
    the feasible points is the front; ``chosen`` (``{"x", "objective"}``) is starred.
    """
    x = _TRADEOFF_ALIASES.get(x, x)
    if x not in TRADEOFF_AXES:
        raise InputError(f"x: {x!r} is not allowed; must be {describe_allowed(TRADEOFF_AXES)}")
    if by not in TRADEOFF_GROUPS:
        raise InputError(f"by: {by!r} is not allowed; must be {describe_allowed(TRADEOFF_GROUPS)}")
    pts = _tradeoff_points(points, x)
    label, scale, _ = TRADEOFF_AXES[x]
    fig, ax = _axes(ax, (10.5, 5.6))
    from matplotlib.lines import Line2D

    groups = _tradeoff_groups(pts, by)
    materials = sorted({p["material"] for p in pts})
    colour_of = {m: _MATERIAL_COLOURS[i % len(_MATERIAL_COLOURS)] for i, m in enumerate(materials)}
    section_colour = {"rectangle": "#1f77b4", "round": "#ff7f0e", "tube": "#2ca02c"}
    styles = ("-", "--", ":", "-.")
    sections = list(dict.fromkeys(_family(p["section"]) for p in pts))

    front = _front(pts)
    if front:
        fx, fy = zip(*front)
        ax.plot(np.array(fx) * scale, fy, color="#bbbbbb", linewidth=9, alpha=0.7, zorder=1,
                solid_capstyle="round", label="front: best of all")
    handles = []
    for name, series in groups.items():
        if by == "section":
            colour, style = section_colour.get(_family(name), "#555555"), "-"
        elif by == "both":
            material, section = name
            colour = colour_of[material]
            style = styles[sections.index(_family(section)) % len(styles)]
        else:
            colour, style = colour_of[name], "-"
        xs = np.array([p["x"] for p in series]) * scale
        ys = np.array([np.nan if p["objective"] is None else p["objective"] for p in series], float)
        ok = np.array([p["feasible"] for p in series])
        ax.plot(xs, np.where(ok, ys, np.nan), color=colour, linestyle=style, linewidth=1.6, zorder=3)
        ax.plot(xs, ys, color=colour, linestyle=":", linewidth=0.9, alpha=0.6, zorder=2)
        for xi, yi, oki, p in zip(xs, ys, ok, series):
            if np.isnan(yi):
                continue
            marker = _SECTION_MARKERS.get(_family(p["section"]), "o")
            ax.plot([xi], [yi], marker=marker, markersize=6, linestyle="none", zorder=4,
                    color=colour, markerfacecolor=colour if oki else "white", markeredgewidth=1.2)
        handles.append(Line2D([], [], color=colour, linestyle=style, linewidth=1.6,
                              label=name if not isinstance(name, tuple) else f"{name[0]} · {name[1]}"))
    if by != "section":
        for sec in sections:
            handles.append(Line2D([], [], marker=_SECTION_MARKERS.get(sec, "o"), color="#444444",
                                  linestyle="none", markersize=6, label=f"{sec} (best section)"
                                  if by == "material" else sec))
    handles.append(Line2D([], [], marker="o", color="#444444", markerfacecolor="white", linestyle="none",
                          markersize=6, label="infeasible (least-violating design)"))
    if front:
        handles.append(Line2D([], [], color="#bbbbbb", linewidth=7, alpha=0.7, label="front: best of all"))
    if chosen is not None and _is_number(chosen.get("x")) and _is_number(chosen.get("objective")):
        ax.plot([chosen["x"] * scale], [chosen["objective"]], marker="*", markersize=18, color="gold",
                markeredgecolor="black", linestyle="none", zorder=6)
        handles.append(Line2D([], [], marker="*", markersize=14, color="gold", markeredgecolor="black",
                              linestyle="none", label="chosen design"))

    objectives = [p["objective"] for p in pts if p["objective"] is not None]
    if objectives:
        lo, hi = min(objectives), max(objectives)
        feasible = [p["objective"] for p in pts if p["feasible"] and p["objective"] is not None]
        top = min(hi, 20 * max(feasible)) if feasible else hi
        if max(top, 1.0) / lo > 8:
            ax.set_yscale("log")
            ax.set_ylim(lo / 1.4, max(top, 1.0) * 1.6)
        else:
            ax.set_ylim(0.0, max(top, 1.0) * 1.12)
    ax.axhline(1.0, color="black", linestyle="--", linewidth=1.1, zorder=2)
    handles.append(Line2D([], [], color="black", linestyle="--", linewidth=1.1, label="e = 1: targets met below"))
    from matplotlib.ticker import FuncFormatter, LogLocator

    if ax.get_yscale() == "log":
        ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: ""))
    ax.set_xlabel(label)
    ax.set_ylabel(ERROR_OBJECTIVE_LABEL, fontsize=9)
    what = "stiffness" if x == "max_deflection" else "speed"
    ax.set_title(f"Accuracy against {what}: best design per "
                 f"{'material and section' if by == 'both' else by}", fontsize=11)
    ax.grid(True, which="major", color=_C_GRID, linewidth=0.6, zorder=0)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    return fig


def _family(section: str) -> str:
    """``rectangle+hole`` -> ``rectangle``."""
    return section.split("+", 1)[0]


def _tradeoff_points(points, x: str) -> list[dict]:
    if not isinstance(points, Sequence) or isinstance(points, str):
        raise InputError(f"trade-off points for {x}: {points!r} must be a list of objects")
    out = []
    for i, p in enumerate(points):
        where = f"tradeoff.{x}[{i}]"
        if not isinstance(p, Mapping):
            raise InputError(f"{where}: {p!r} must be an object with material, section, x, objective, feasible")
        for key in ("material", "section"):
            if not isinstance(p.get(key), str):
                raise InputError(f"{where}.{key}: {p.get(key)!r} must be a name")
        if not _is_number(p.get("x")) or p["x"] <= 0:
            raise InputError(f"{where}.x: {p.get('x')!r} must be a positive number (SI units)")
        objective = p.get("objective")
        if objective is not None and (not _is_number(objective) or objective <= 0):
            raise InputError(f"{where}.objective: {objective!r} must be a positive number or null")
        if not isinstance(p.get("feasible"), bool):
            raise InputError(f"{where}.feasible: {p.get('feasible')!r} must be true or false")
        out.append({"material": p["material"], "section": p["section"], "x": float(p["x"]),
                    "objective": None if objective is None else float(objective),
                    "feasible": p["feasible"] and objective is not None})
    if not out:
        raise InputError(f"trade-off points for {x}: the list is empty")
    return out


def _best(points: list[dict]) -> dict:
    """The best of several designs at one x: feasible first, then the lowest objective."""
    def key(p):
        return (not p["feasible"], math.inf if p["objective"] is None else p["objective"])
    return min(points, key=key)


def _tradeoff_groups(pts: list[dict], by: str) -> dict:
    """{line name: [best point at each x, by increasing x]}."""
    if by == "both":
        name_of = lambda p: (p["material"], p["section"])  # noqa: E731
    elif by == "section":
        name_of = lambda p: _family(p["section"])  # noqa: E731
    else:
        name_of = lambda p: p["material"]  # noqa: E731
    buckets: dict = {}
    for p in pts:
        buckets.setdefault(name_of(p), {}).setdefault(p["x"], []).append(p)
    return {name: [_best(at[xv]) for xv in sorted(at)] for name, at in sorted(buckets.items())}


def _front(pts: list[dict]) -> list[tuple[float, float]]:
    """The best feasible objective at each x value."""
    best: dict[float, float] = {}
    for p in pts:
        if p["feasible"] and p["objective"] is not None:
            best[p["x"]] = min(best.get(p["x"], math.inf), p["objective"])
    return sorted(best.items())


# --------------------------------------------------------------------------- 6. writing

def write_design_plots(design: Mapping, out_dir, formats: Sequence[str] = FORMATS,
                       tradeoff: Mapping[str, Sequence[Mapping]] | None = None) -> list[Path]:
    """Write the plots of a design into ``out_dir``; all of them or none.

    Files: ``operating-region``, ``voltage-isolines``, ``error-maps``, ``candidates`` and, when
    trade-off points are given (``tradeoff={"max_deflection": [...], "min_frequency": [...]}``, or a
    ``"tradeoff"`` key of the design), ``tradeoff-deflection`` and ``tradeoff-frequency``; each in
    every format of ``formats`` (``"png"``, ``"svg"``). Returns the paths written.
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
        raise InputError(f"tradeoff: {tradeoff!r} must map max_deflection / min_frequency to lists of points")
    fronts = {}
    for key, points in tradeoff.items():
        name = _TRADEOFF_ALIASES.get(key, key)
        if name not in TRADEOFF_AXES:
            raise InputError(f"tradeoff.{key}: unknown front; must be {describe_allowed(TRADEOFF_AXES)}")
        if points:
            _tradeoff_points(points, name)  # check every point before drawing anything
            fronts[name] = points

    makers = [("operating-region", lambda: plot_operating_region(design)),
              ("voltage-isolines", lambda: plot_voltage_isolines(design)),
              ("error-maps", lambda: plot_error_maps(design)),
              ("candidates", lambda: plot_candidates(design))]
    for name, points in fronts.items():
        chosen = _chosen_point(design, name)
        makers.append((TRADEOFF_AXES[name][2],
                       lambda p=points, c=chosen, n=name: plot_tradeoff(p, chosen=c, x=n)))

    out_dir = Path(out_dir)
    written = []
    with staged_directory(out_dir) as scratch:
        for name, make in makers:
            fig = make()
            for fmt in formats:
                fig.savefig(scratch / f"{name}.{fmt}", format=fmt, dpi=PNG_DPI,
                            metadata={"Date": None} if fmt == "svg" else None)
                written.append(out_dir / f"{name}.{fmt}")
    return written


def _chosen_point(design: Mapping, x: str) -> dict | None:
    """Where the chosen design sits on a front: its own deflection or frequency, and its e."""
    s = SensorData.from_design(design)
    value = s.deflection if x == "max_deflection" else s.natural_frequency
    objective = s.error_ratio if s.error_ratio is not None else s.objective
    if value is None or objective is None:
        return None
    return {"material": s.material, "section": s.section, "x": value, "objective": objective}
