"""The verdict of the 3-D check and its report: the result record (verify.json, and
design.json's ``verification``), the messages, the Markdown report and the surface-strain plot.
matplotlib is imported inside the plot.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from designer.checks.fea.geometry_mesh import CONVERGENCE_COARSENING
from designer.checks.fea.readout import StressPeak
from designer.model import FEASIBILITY_TOLERANCE

# The strain plot's axis reaches this many times the largest beam-model strain; peaks at sharp
# corners beyond it are named in a note instead.
PLOT_HEADROOM = 1.6
# Convergence: relative change between the two meshes that counts as converged. For a
# second-order rate the finer mesh's error is at most 0.8 x the change (1 / (1.5^2 - 1)) and in
# practice far less (Prototype B: 1.8 % coarse to normal, then 0.2 % normal to fine).
CONVERGED_STRAIN = 0.02
CONVERGED_DEFLECTION = 0.01
# The peak stress is a point value at a floor radius or hole edge, resolved by a few elements:
# converged when it moves at most 5 % between the meshes (the peak's own verdict, beside the
# strains'). A sharp inside corner never passes: its peak grows without bound as the mesh is
# refined (the gripper finger's flats before they had floor radii: +9 %, +11 %, +14 % per step).
CONVERGED_STRESS = 0.05
# Two meshes that are both too coarse for a floor radius agree on a wrong peak: a peak on a
# pocket's floor radius counts as converged only where the mesh edges meeting at it are on
# average at most this share of the radius (about three along its quarter arc). The gripper
# finger's R0.2 flats against a mesh graded to the radius (which reads 200 and 184 MPa at the
# two ends of the first flat): edges of 0.07-0.09 mm (fine) read 1-3 % low; 0.10-0.11 mm
# (normal) 2-6 % low; 0.18-0.20 mm (coarse) 21-23 % low, yet within 2 % of the next coarser mesh.
RESOLVED_RADIUS_SHARE = 0.5
# A gauge-strain ratio further than this from 1 is worth a sentence in the report.
RATIO_NOTE = 0.03

MPA = 1e6
MICRO = 1e-6


@dataclass(frozen=True)
class GaugeCheck:
    """One gauge's strain: the 3-D check's, the beam model's and the convergence mesh's."""

    station: float          # d_i, m
    fea_strain: float       # mean eps_xx over the grid footprint under F_max at x_max
    model_strain: float     # MODEL.md eq. 3
    coarse_strain: float    # the same on the convergence mesh

    @property
    def ratio(self) -> float:
        return self.fea_strain / self.model_strain

    @property
    def mesh_change(self) -> float:
        return abs(self.fea_strain - self.coarse_strain) / abs(self.fea_strain)


@dataclass(frozen=True)
class LimitCheck:
    """A limit of MODEL.md section 4 with the beam model's value and the value the 3-D check gives."""

    name: str
    model_value: float
    fea_value: float
    limit: float
    upper: bool
    source: str             # how fea_value was obtained
    unit: str = ""
    scale: float | None = None  # as model.Limit: the normalising scale (None: the limit itself)

    def _holds(self, value: float) -> bool:
        """The model's rule: the normalised violation at most FEASIBILITY_TOLERANCE (model.Limit)."""
        gap = value - self.limit if self.upper else self.limit - value
        scale = self.scale if self.scale is not None else abs(self.limit)
        return gap / (scale or 1.0) <= FEASIBILITY_TOLERANCE

    @property
    def satisfied(self) -> bool:
        return self._holds(self.fea_value)

    @property
    def model_satisfied(self) -> bool:
        return self._holds(self.model_value)


@dataclass(frozen=True)
class MeshRun:
    """One mesh of the check: its level, sizes, unknowns, iterations and time."""

    level: str
    refinement: float
    global_size: float      # m
    detail_size: float      # m
    elements: int
    vertices: int
    dofs: int
    cg_iterations: int
    seconds: float


@dataclass(frozen=True)
class VerifyResult:
    """The 3-D check of one design under ``force`` at ``position`` (F_max at x_max), SI."""

    name: str
    mesh: str
    force: float
    position: float
    free_length: float
    cut: float                      # x_cut, m
    gauges: tuple                   # GaugeCheck per station
    deflection_fea: float           # free end, m (downward positive)
    deflection_model: float
    deflection_coarse: float
    stress_peak: StressPeak         # FEA, away from the clamp face
    stress_peak_coarse: float       # the convergence mesh's stress at that peak (readout.stress_near)
    stress_feature_fea: float       # FEA peak within the feature zones
    stress_model: float             # the beam model's largest stress (K_t x nominal at the feature, or the root's)
    stress_root_model: float
    stress_allowable: float
    limits: tuple                   # LimitCheck
    runs: tuple                     # MeshRun: the requested mesh, then the convergence mesh
    profile_x: tuple                # surface strain along the top centre line, m
    profile_fea: tuple
    profile_model: tuple
    gauge_grid: tuple               # (grid_length, grid_width), m
    feature_length: float
    messages: tuple
    seconds: float
    floor_radius: float = 0.0       # the pockets' floor radius (cad.corner_radius), m; 0 without pockets
    stress_concentration_model: float = 1.0  # the model's K_t
    feature: str = ""               # the design's feature kind (pocket, hole, none)
    stress_feature_nominal: float = 0.0    # the beam model's nominal stress at the feature's clamp-side edge
    stress_stations_fea: tuple = ()  # FEA peak within each station's feature zone
    stress_stations_places: tuple = ()  # ... and its (floor radius, outer face) peaks (readout.stress_peaks)
    stress_feature_worst: float = 0.0   # a biaxial design's features' peak at the worst load direction (0: none)
    worst_angle: float = 0.0            # ... that direction, degrees from the CAD's Z axis toward Y
    stress_feature_worst_model: float = 0.0   # the model's peak there (c K_t x the notch's nominal)

    @property
    def stress_feature_model(self) -> float:
        """The beam model's peak at the feature: K_t x nominal."""
        return self.stress_concentration_model * self.stress_feature_nominal

    @property
    def stress_model_at_peak(self) -> float:
        """The beam model's stress where the 3-D peak sits: K_t x nominal at a feature, else the
        nominal bending stress of the full section there, the root's scaled by the moment
        ``F (x - s)`` (a plain bar's peak is read half a depth or more from the clamp face, where
        the moment is smaller than at the root)."""
        if self.stress_peak.at_feature:
            return self.stress_feature_model
        s = self.stress_peak.location[0]
        return self.stress_root_model * max(self.position - s, 0.0) / self.position

    @property
    def ratios(self) -> tuple:
        return tuple(g.ratio for g in self.gauges)

    @property
    def converged(self) -> bool:
        return (max(g.mesh_change for g in self.gauges) <= CONVERGED_STRAIN
                and self.deflection_change <= CONVERGED_DEFLECTION)

    @property
    def deflection_change(self) -> float:
        return abs(self.deflection_fea - self.deflection_coarse) / abs(self.deflection_fea)

    @property
    def stress_change(self) -> float:
        return abs(self.stress_peak.value - self.stress_peak_coarse) / self.stress_peak.value

    @property
    def stress_resolved(self) -> bool:
        """False when the peak sits on a pocket's floor radius and the mesh edges there are on
        average longer than RESOLVED_RADIUS_SHARE of it."""
        return (not self.stress_peak.on_floor_radius
                or self.stress_peak.element_size <= RESOLVED_RADIUS_SHARE * self.floor_radius)

    @property
    def stress_converged(self) -> bool:
        """The peak stress's own verdict: it moved at most CONVERGED_STRESS between the meshes,
        where the mesh resolves it."""
        return self.stress_change <= CONVERGED_STRESS and self.stress_resolved

    @property
    def passed(self) -> bool:
        return all(c.satisfied for c in self.limits)

    def as_dict(self) -> dict:
        """Every figure as plain JSON types (verify.json, design.json's ``verification``)."""
        return {
            "name": self.name, "mesh": self.mesh, "passed": self.passed, "converged": self.converged,
            "load": {"force": self.force, "position": self.position}, "free_length": self.free_length,
            "cut": self.cut,
            "gauges": [{"station": g.station, "fea_strain": g.fea_strain, "model_strain": g.model_strain,
                        "ratio": g.ratio, "coarse_strain": g.coarse_strain, "mesh_change": g.mesh_change}
                       for g in self.gauges],
            "deflection": {"fea": self.deflection_fea, "model": self.deflection_model,
                           "ratio": self.deflection_fea / self.deflection_model,
                           "coarse": self.deflection_coarse, "mesh_change": self.deflection_change},
            "stress": {"fea_peak": self.stress_peak.value, "location": list(self.stress_peak.location),
                       "where": self.stress_peak.where, "fea_feature": self.stress_feature_fea,
                       "fea_stations": list(self.stress_stations_fea),
                       "fea_stations_floor_radius": [f for f, _ in self.stress_stations_places],
                       "fea_stations_outer_face": [o for _, o in self.stress_stations_places],
                       "coarse_peak": self.stress_peak_coarse, "mesh_change": self.stress_change,
                       "converged": self.stress_converged, "converged_within": CONVERGED_STRESS,
                       "element_size": self.stress_peak.element_size, "on_floor_radius": self.stress_peak.on_floor_radius,
                       "resolved": self.stress_resolved,
                       "floor_radius": self.floor_radius,
                       "model_max": self.stress_model, "model_at_peak": self.stress_model_at_peak,
                       "model_root": self.stress_root_model,
                       "model_feature": self.stress_feature_model, "model_kt": self.stress_concentration_model,
                       "nominal_feature": self.stress_feature_nominal,
                       "allowable": self.stress_allowable,
                       **({"worst_direction": {"degrees": self.worst_angle, "fea_feature": self.stress_feature_worst,
                                               "model_feature": self.stress_feature_worst_model}}
                          if self.stress_feature_worst else {})},
            "limits": [{"name": c.name, "model": c.model_value, "fea": c.fea_value, "limit": c.limit,
                        "sense": "<=" if c.upper else ">=", "satisfied": c.satisfied,
                        "model_satisfied": c.model_satisfied, "source": c.source, "unit": c.unit}
                       for c in self.limits],
            "meshes": [asdict(r) for r in self.runs],
            "profile": {"x": list(self.profile_x), "fea": list(self.profile_fea), "model": list(self.profile_model)},
            "messages": list(self.messages), "seconds": self.seconds,
        }

    def plot(self, ax=None):
        return plot_surface_strain(self, ax=ax)


# ----------------------------------------------------------------- what it means

def with_messages(r: VerifyResult, fatigue: bool, feature: str, seconds: float,
                  mesh_option: str | None = None) -> VerifyResult:
    """``r`` with its messages (what the figures mean) and the time the check took.

    ``fatigue``: the allowable stress includes fatigue; ``feature``: the design's strain feature;
    ``mesh_option``: how the caller lets a user choose the mesh (a command-line flag), for the
    advice to refine; without it the advice says "the fine mesh level".
    """
    finer = f"{mesh_option} fine" if mesh_option else "the fine mesh level"
    msgs = []
    for i, g in enumerate(r.gauges):
        line = (f"gauge {i + 1} at {g.station * 1e3:.1f} mm: 3-D {g.fea_strain / MICRO:.0f} µε, beam model "
                f"{g.model_strain / MICRO:.0f} µε, ratio {g.ratio:.3f}")
        if abs(g.ratio - 1) > RATIO_NOTE:
            more = "over" if g.ratio < 1 else "under"
            line += (f": the beam model {more}-predicts this gauge's strain by {abs(1 / g.ratio - 1):.0%}; "
                     f"its sensitivity k is {g.ratio:.2f} x the model's (calibration measures the real k, "
                     f"but the predicted errors and signal scale by {1 / g.ratio:.2f})")
        msgs.append(line)
    by_name = {c.name: c for c in r.limits}
    strain = by_name.get("gauge_strain")
    if strain is not None:
        where = f" ({strain.source.split(':')[0]})" if strain.source.startswith("at the worst") else ""
        msgs.append(f"gauge strain at station 1{where}: {strain.fea_value / MICRO:.0f} µε against the gauge's "
                    f"{strain.limit / MICRO:.0f} µε limit: {'within' if strain.satisfied else 'OVER'} the limit")
    peak = r.stress_peak
    x, y, z = (v * 1e3 for v in peak.location)
    line = (f"peak stress {peak.value / MPA:.1f} MPa at X = {x:.1f} mm, Y = ±{abs(y):.2f} mm, "
            f"Z = ±{abs(z):.2f} mm ({peak.where})")
    if feature != "none" and r.stress_feature_nominal > 0:
        kt = r.stress_feature_fea / r.stress_feature_nominal
        line += (f"; at the features {r.stress_feature_fea / MPA:.1f} MPa, K_t {kt:.2f} on the nominal "
                 f"{r.stress_feature_nominal / MPA:.1f} MPa, against the beam model's K_t "
                 f"{r.stress_concentration_model:.2f} ({r.stress_feature_model / MPA:.1f} MPa, 3-D / model "
                 f"{r.stress_feature_fea / r.stress_feature_model:.2f})")
    msgs.append(line)
    fatigue = ("fatigue: K_f x the nominal stress at the features" if not r.stress_feature_worst else
               "fatigue: K_f of the worst load direction's 3-D K_t x the notch's nominal, or the plain nominal "
               "where larger")
    for name, what in (("stress_feature", "static: the nominal stress at the features"), ("fatigue_feature", fatigue)):
        c = by_name.get(name)
        if c is not None:
            msgs.append(f"{what}: {c.fea_value / MPA:.1f} MPa against {c.limit / MPA:.1f} MPa: "
                        f"{'within' if c.satisfied else 'OVER'} the allowable")
    change = (f"the peak stress moved {r.stress_change:.1%} on a mesh {CONVERGENCE_COARSENING:g} x coarser "
              f"({r.stress_peak_coarse / MPA:.1f} MPa at the same place)")
    fine = r.mesh == "fine"
    advice = "treat the peak as a lower bound" if fine else f"rerun with {finer} before trusting it"
    if r.stress_converged:
        msgs.append(f"peak-stress convergence: {change}: converged (within {CONVERGED_STRESS:.0%})")
    elif not r.stress_resolved:
        msgs.append(f"peak-stress convergence: NOT converged: the peak sits on a pocket's R{r.floor_radius * 1e3:.2g} "
                    f"floor radius and the mesh edges there average {peak.element_size * 1e3:.3f} mm, more than "
                    f"{RESOLVED_RADIUS_SHARE * r.floor_radius * 1e3:.3g} mm ({RESOLVED_RADIUS_SHARE:g} of the radius): "
                    f"{'even the fine' if fine else 'this'} mesh does not resolve it, so that {change} says little; "
                    f"{advice}")
    elif feature == "pocket" and peak.at_feature:
        msgs.append(f"peak-stress convergence: NOT converged: {change}, more than {CONVERGED_STRESS:.0%}; the peak "
                    f"sits at a pocket's floor radius, which {'even the fine' if fine else 'this'} mesh does not "
                    f"resolve: {advice}")
    else:
        msgs.append(f"peak-stress convergence: NOT converged: {change}, more than {CONVERGED_STRESS:.0%}; {advice}")
    msgs.append(f"free-end deflection: 3-D {r.deflection_fea * 1e3:.3f} mm, beam model "
                f"{r.deflection_model * 1e3:.3f} mm (ratio {r.deflection_fea / r.deflection_model:.3f})")
    worst = max(g.mesh_change for g in r.gauges)
    if r.converged:
        msgs.append(f"mesh convergence: the gauge strains moved at most {worst:.2%} and the deflection "
                    f"{r.deflection_change:.2%} on a mesh {CONVERGENCE_COARSENING:g} x coarser: converged")
    else:
        msgs.append(f"mesh convergence: NOT converged (gauge strains moved up to {worst:.2%}, deflection "
                    f"{r.deflection_change:.2%} on a mesh {CONVERGENCE_COARSENING:g} x coarser); "
                    f"rerun with {finer}")
    failed = [c.name for c in r.limits if not c.satisfied]
    if failed:
        msgs.append("FAILS with the 3-D figures: " + ", ".join(failed))
    else:
        msgs.append("every limit holds with the 3-D figures")
    return replace(r, messages=tuple(msgs), seconds=seconds)


# ----------------------------------------------------------------- outputs

def plot_surface_strain(result: VerifyResult, ax=None):
    """Surface strain along the top centre line: 3-D check against the beam model."""
    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(8, 4.2), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    x = np.asarray(result.profile_x) * 1e3
    ax.plot(x, np.asarray(result.profile_model) / MICRO, color="0.35", lw=1.4, ls="--",
            label="beam model, M z / (E I) at the same points")
    ax.plot(x, np.asarray(result.profile_fea) / MICRO, color="C0", lw=1.2, label="3-D FEA, top centre line")
    gl, gw = result.gauge_grid
    for i, g in enumerate(result.gauges):
        ax.axvspan((g.station - result.feature_length / 2) * 1e3, (g.station + result.feature_length / 2) * 1e3,
                   color="C1", alpha=0.12, lw=0,
                   label=None if i else "gauge site (no feature)" if result.feature == "none" else "feature")
        ax.errorbar([g.station * 1e3], [g.fea_strain / MICRO], xerr=[[gl * 1e3 / 2], [gl * 1e3 / 2]], fmt="o",
                    color="C3", ms=5, capsize=3, label="3-D gauge (grid mean)" if i == 0 else None)
        ax.plot([g.station * 1e3], [g.model_strain / MICRO], "s", mfc="none", color="k", ms=6,
                label="beam-model gauge" if i == 0 else None)
        ax.annotate(f"{g.ratio:.2f}", (g.station * 1e3, g.fea_strain / MICRO), textcoords="offset points",
                    xytext=(6, 6), fontsize=8, color="C3")
    ax.set_xlabel("distance from the clamp face X (mm)")
    ax.set_ylabel("axial surface strain (µε)")
    ax.set_title(f"{result.name}: surface strain under {result.force:.3g} N at {result.position * 1e3:.0f} mm "
                 f"(mesh {result.mesh}; labels: 3-D / model)", fontsize=9)
    ax.set_xlim(0, result.cut * 1e3)
    reach = PLOT_HEADROOM * max(max(np.abs(result.profile_model)), max(abs(g.fea_strain) for g in result.gauges)) / MICRO
    fea_um = np.asarray(result.profile_fea) / MICRO
    ax.set_ylim(min(0.0, float(fea_um.min())) if fea_um.min() > -reach else -0.25 * reach, reach)
    if fea_um.max() > reach or fea_um.min() < -0.25 * reach:
        ax.text(0.01, 0.02, f"off scale: sharp-corner peaks from {fea_um.min():.0f} to {fea_um.max():.0f} µε",
                transform=ax.transAxes, fontsize=8, color="C0")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return fig


def report_markdown(r: VerifyResult) -> str:
    """The verify report as Markdown."""
    um = 1 / MICRO
    lines = [f"# 3-D check of {r.name}", "",
             f"Load {r.force:.4g} N at {r.position * 1e3:.1f} mm (F_max at x_max). "
             f"Quadratic tetrahedra on the quarter beam from the clamp face to X = {r.cut * 1e3:.1f} mm; "
             "the load beyond enters as its shear and moment on the cut face. "
             f"Verdict: **{'every limit holds' if r.passed else 'FAILS'}** with the 3-D figures; "
             f"mesh {'converged' if r.converged else 'NOT converged'} (gauge strains and deflection); "
             f"peak stress {'converged' if r.stress_converged else 'NOT converged'} "
             f"({r.stress_change:.1%} change, within {CONVERGED_STRESS:.0%} needed"
             f"{'' if r.stress_resolved else '; the mesh does not resolve the floor radius there'}).", "",
             "## Gauge strains", "",
             "| station (mm) | 3-D (µε) | beam model (µε) | 3-D / model | coarser mesh (µε) | change |",
             "|---:|---:|---:|---:|---:|---:|"]
    for g in r.gauges:
        lines.append(f"| {g.station * 1e3:.1f} | {g.fea_strain * um:.1f} | {g.model_strain * um:.1f} | "
                     f"{g.ratio:.3f} | {g.coarse_strain * um:.1f} | {g.mesh_change:.2%} |")
    lines += ["", "## Deflection and stress", "",
              "| quantity | 3-D | beam model | limit |", "|---|---:|---:|---:|",
              f"| free-end deflection (mm) | {r.deflection_fea * 1e3:.3f} | {r.deflection_model * 1e3:.3f} | |",
              f"| peak stress (MPa), {r.stress_peak.where} (model: at the same place) | "
              f"{r.stress_peak.value / MPA:.1f} | {r.stress_model_at_peak / MPA:.1f} | |",
              f"| peak stress at the same place on the coarser mesh (MPa): change {r.stress_change:.1%}, "
              f"{'converged' if r.stress_converged else '**NOT converged**'} | {r.stress_peak_coarse / MPA:.1f} | | |",
              f"| peak stress at the features (MPa; model: K_t {r.stress_concentration_model:.2f} x nominal) | "
              f"{r.stress_feature_fea / MPA:.1f} | {r.stress_feature_model / MPA:.1f} | |",
              f"| root stress (MPa), beam model kept | | {r.stress_root_model / MPA:.1f} | "
              f"{r.stress_allowable / MPA:.1f} |", "",
              "## Limits re-checked", "",
              "| limit | beam model | 3-D | limit | holds | 3-D value from |", "|---|---:|---:|---:|:-:|---|"]
    for c in r.limits:
        lines.append(f"| {c.name} | {_fmt(c.model_value, c.unit)} | {_fmt(c.fea_value, c.unit)} | "
                     f"{'≤' if c.upper else '≥'} {_fmt(c.limit, c.unit)} | {'yes' if c.satisfied else '**no**'} | "
                     f"{c.source} |")
    lines += ["", "## Meshes", "",
              "| mesh | element size (mm) | detail size (mm) | elements | unknowns | CG iterations | seconds |",
              "|---|---:|---:|---:|---:|---:|---:|"]
    for m in r.runs:
        lines.append(f"| {m.level} | {m.global_size * 1e3:.2f} | {m.detail_size * 1e3:.2f} | {m.elements} | "
                     f"{m.dofs} | {m.cg_iterations} | {m.seconds:.1f} |")
    lines += ["", "## What it means", ""] + [f"- {m}" for m in r.messages]
    lines += ["", "![surface strain](surface-strain.png)", ""]
    return "\n".join(lines)


def _fmt(value: float, unit: str) -> str:
    if unit == "Pa":
        return f"{value / MPA:.1f} MPa"
    if unit == "strain":
        return f"{value / MICRO:.0f} µε"
    if unit == "m":
        return f"{value * 1e3:.3f} mm"
    if unit == "Hz":
        return f"{value:.2f} Hz"
    return f"{value:.4g}"


def write_outputs(result: VerifyResult, out_dir: Path) -> dict[str, Path]:
    """``verify.md``, ``verify.json`` and ``surface-strain.png`` in ``out_dir``, all or nothing; their
    names under the keys design.json's ``files`` lists them by (``verify_report``: ``report`` is
    report.md's)."""
    from designer.outputs.files import atomic_write_json, atomic_write_text, staged_directory

    out_dir = Path(out_dir)
    names = {"verify_report": "verify.md", "json": "verify.json", "plot": "surface-strain.png"}
    with staged_directory(out_dir) as scratch:
        atomic_write_text(scratch / names["verify_report"], report_markdown(result))
        atomic_write_json(scratch / names["json"], result.as_dict())
        fig = plot_surface_strain(result)
        fig.savefig(scratch / names["plot"], dpi=130)
    return {k: out_dir / v for k, v in names.items()}
