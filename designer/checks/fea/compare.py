"""The 3-D check against the beam model: one run per mesh, the comparison, the verdict.

``verify_design`` meshes and solves the design twice (the requested mesh and one a step
coarser, for the convergence check; the coarser in a child process at the same time, on the
machine's other core), sets the figures beside the beam model's (gauge strains,
the surface strain with ``EI(s)`` from ``model.rigidity_segments``, deflection, stresses) and
re-checks every limit of the model with the 3-D figures where the check gives them.
"""

from __future__ import annotations

import contextlib
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from designer.checks.fea.geometry_mesh import (CONVERGENCE_COARSENING, MESH_LEVELS, Problem, build_problem,
                                               mesh_quarter, write_step_apart)
from designer.checks.fea.readout import (StressPeak, free_end_deflection, gauge_strains, stress_near, stress_peaks,
                                         surface_profile, worst_direction)
from designer.checks.fea.report import GaugeCheck, LimitCheck, MeshRun, VerifyResult, with_messages, write_outputs
from designer.checks.fea.solve import solution, solve
from designer.errors import InputError, describe_allowed
from designer.model import grooves
from designer.model.grooves import LIMIT_NAMES as GROOVE_LIMITS


@dataclass(frozen=True)
class Figures:
    """What one mesh gives: the gauge strains, the free-end deflection, the stress peaks (overall,
    at the features, at each station's feature), the stress at another run's peak (``at_peak``),
    the surface strain profile ``(x, z, eps_xx)`` and the run's size and time, and whether MeshAdapt
    meshed faces of it."""

    gauges: tuple
    deflection: float
    peak: StressPeak
    feature_peak: float
    station_peaks: tuple
    at_peak: float | None
    profile: tuple
    run: MeshRun
    mesh_adapt: bool        # faces with a flat surface mesh were meshed by MeshAdapt
    station_places: tuple = ()  # each station's (floor radius, outer face) peak (readout.stress_peaks)
    worst: tuple = ()       # a biaxial design's features' peak at the worst load direction, and its angle


def _run(step_path: Path, pb: Problem, level: str, refinement: float, mesh_adapt: bool = False):
    """Mesh, solve and read the design at one refinement: its Figures (``at_peak`` not read yet)
    and its Solution. ``mesh_adapt``: mesh the faces whose surface mesh is flat with MeshAdapt
    from the start (``mesh_quarter``)."""
    start = time.perf_counter()
    points, tets, adapted = mesh_quarter(step_path, pb, refinement, mesh_adapt)
    sol = solve(points, tets, pb)
    gauges = tuple(gauge_strains(sol, pb))
    deflection = free_end_deflection(sol, pb)
    peak, feature_peak, station_peaks, station_places = stress_peaks(sol, pb, refinement)
    profile = surface_profile(sol, pb, refinement)
    run = MeshRun(level=level, refinement=refinement, global_size=pb.global_size / refinement,
                  detail_size=pb.detail_size / refinement, elements=int(tets.shape[1]),
                  vertices=int(points.shape[1]), dofs=int(3 * sol.basis.N), cg_iterations=sol.iterations,
                  seconds=time.perf_counter() - start)
    return Figures(gauges, deflection, peak, feature_peak, station_peaks, None, profile, run, adapted,
                   station_places), sol


def _partner_run(step_path: Path, pb: Problem, level: str, refinement: float):
    """The convergence mesh's run, in a child process: its Figures and its solution as plain
    arrays ``(points, tets, u, iterations)``, from which the parent reads the stress at the main
    mesh's peak once that is known."""
    figures, sol = _run(step_path, pb, level, refinement)
    return figures, (sol.mesh.p, sol.mesh.t, sol.u, sol.iterations)


def _with_stress_at(figures: Figures, sol, pb: Problem, refinement: float, point) -> Figures:
    """``figures`` with the stress read at ``point`` (m) of ``sol`` (the main mesh's peak)."""
    start = time.perf_counter()
    at_peak = stress_near(sol, pb, refinement, point)
    run = replace(figures.run, seconds=figures.run.seconds + time.perf_counter() - start)
    return replace(figures, at_peak=at_peak, run=run)


def _both_meshes(step_path: Path, pb: Problem, mesh: str, refinement: float) -> tuple[Figures, Figures]:
    """The requested mesh here and the convergence mesh (CONVERGENCE_COARSENING coarser) in a
    child process at the same time; the convergence mesh's stress read at the main mesh's peak.
    Each process holds one mesh: the child's peak memory is the smaller mesh's. A main mesh that
    needed MeshAdapt on its flat faces has its convergence mesh made alike (again, here, should
    the child's not have needed it)."""
    from skfem import MeshTet

    from designer.outputs.background import Background

    level = f"{mesh} / {CONVERGENCE_COARSENING:g}"
    coarse = refinement / CONVERGENCE_COARSENING
    job = Background(_partner_run, step_path, pb, level, coarse)
    try:
        main, sol = _run(step_path, pb, mesh, refinement)
        if pb.biaxial:   # F along the other axis on the same mesh: every load direction (docs/model.md §9)
            start = time.perf_counter()
            lateral = solve(sol.mesh.p, sol.mesh.t, replace(pb, lateral=True))
            main = replace(main, worst=worst_direction(sol, lateral, pb, refinement),
                           run=replace(main.run, seconds=main.run.seconds + time.perf_counter() - start))
            del lateral
        del sol
        partner, (points, tets, u, iterations) = job.result()
    finally:
        job.stop()
    if main.mesh_adapt and not partner.mesh_adapt:
        partner, sol = _run(step_path, pb, level, coarse, mesh_adapt=True)
    else:
        sol = solution(MeshTet(points, tets), u, iterations)
    return main, _with_stress_at(partner, sol, pb, coarse, main.peak.location)


def model_profile(x: np.ndarray, z: np.ndarray, pb: Problem, segments) -> np.ndarray:
    """Beam-model strain ``M z / EI(s)`` at the same surface points, ``EI(s)`` the segments of
    ``model.rigidity_segments``."""
    return pb.force * (pb.position - x) * z / rigidity_at(x, segments)


def rigidity_at(x: np.ndarray, segments) -> np.ndarray:
    """``EI`` of ``(s0, s1, EI)`` segments at the points ``x``; a point on the boundary of two
    segments takes the smaller (a point on a feature's edge is on the feature)."""
    ei = np.full(np.shape(x), np.inf)
    for a, b, value in segments:
        ei = np.where((x >= a) & (x <= b), np.minimum(ei, value), ei)
    return ei


def verify_design(design: dict, mesh: str = "normal", out_dir: Path | None = None,
                  mesh_option: str | None = None) -> VerifyResult:
    """Check a design.json record in 3-D (see ``designer.checks.fea``); write outputs to ``out_dir``.

    ``mesh_option`` is how the caller lets a user choose the mesh (a command-line flag), named
    in the advice of messages; by default they say "the fine mesh level". Raises
    DesignFileError for a record that cannot be built, InputError for an unknown mesh level,
    SolverError when meshing or solving fails.
    """
    from designer import model

    start = time.perf_counter()
    spec, model_design, ev, beam, pb = _problem(design, mesh)
    refinement = MESH_LEVELS[mesh]
    with _step(design, beam) as step_path:
        main, partner = _both_meshes(step_path, pb, mesh, refinement)

    a = ev.analysis
    gauges = tuple(GaugeCheck(d, fea, float(m), coarse)
                   for d, fea, m, coarse in zip(pb.stations, main.gauges, a.gauge_strain, partner.gauges))
    allowable = float(ev.limits[0].limit)
    groove = (_groove_submodel(beam, mesh, pb.poisson) if any(lim.name in GROOVE_LIMITS for lim in ev.limits)
              else None)
    limits = _recheck(ev, spec, gauges, main, a, groove)
    x, z, eps = main.profile
    segments = model.rigidity_segments(model_design.geometry, a.props, pb.E)
    result = VerifyResult(
        name=beam.name, mesh=mesh, force=pb.force, position=pb.position, free_length=pb.free_length, cut=pb.cut,
        gauges=gauges, deflection_fea=main.deflection, deflection_model=float(a.deflection),
        deflection_coarse=partner.deflection, stress_peak=main.peak, stress_peak_coarse=partner.at_peak,
        stress_feature_fea=main.feature_peak, stress_stations_fea=main.station_peaks,
        stress_stations_places=main.station_places,
        stress_model=float(max(a.stress_root, a.stress_peak_axis)),   # (the check's load is along an axis)
        stress_concentration_model=float(a.stress_concentration),
        stress_feature_nominal=float(a.stress_notch),
        stress_root_model=float(a.stress_root), stress_allowable=allowable, limits=limits,
        runs=(main.run, partner.run), profile_x=tuple(float(v) for v in x),
        profile_fea=tuple(float(v) for v in eps),
        profile_model=tuple(float(v) for v in model_profile(x, z, pb, segments)),
        gauge_grid=(pb.grid_length, pb.grid_width), feature_length=pb.feature_length, feature=pb.feature, messages=(),
        seconds=0.0, floor_radius=beam.floor_radius,
        stress_feature_worst=main.worst[0] if main.worst else 0.0, worst_angle=main.worst[1] if main.worst else 0.0,
        stress_feature_worst_model=float(a.stress_peak))
    result = with_messages(result, spec.limits.fatigue, pb.feature, time.perf_counter() - start, mesh_option)
    if main.worst:
        peak, angle = main.worst
        judged = "; fatigue_feature is judged there" if any(c.name == "fatigue_feature" for c in limits) else ""
        result = replace(result, messages=result.messages + (
            f"biaxial: the features peak at {peak / 1e6:.1f} MPa under a load {min(angle, 90 - angle):g} degrees off "
            f"the nearest bending axis ({angle:g} degrees from the CAD's Z axis toward Y), the worst direction (the "
            f"same mesh solved for F along Y too), against the model's {float(a.stress_peak) / 1e6:.1f} MPa there "
            f"(K_t x {float(a.direction_factor):g}, docs/model.md §9): 3-D / model {peak / float(a.stress_peak):.2f}"
            + judged,),)
    if groove is not None:   # the beam's mesh is refined at the features; the groove has a submodel
        _, kt_model = grooves.groove_stress(model_design.geometry, spec)
        said = ", ".join(f"{c.name} {c.fea_value / 1e6:.1f} MPa against {c.limit / 1e6:.1f} MPa"
                         for c in limits if c.name in GROOVE_LIMITS)
        result = replace(result, messages=result.messages + (
            f"load grooves: the groove nearest the clamp, solved on a submodel in pure bending (its root meshed "
            f"at r/{groove.divisions:g}, {groove.tetrahedra:,} tetrahedra, {groove.seconds:.0f} s), has a 3-D K_t "
            f"of {groove.kt:.3g} against the model's {float(kt_model):.3g} (Roark's times "
            f"{grooves.FACTOR_3D[beam.section]:g}, docs/model.md §4); judged: {said}; the peak of this mesh "
            "leaves the grooves out",))
    if out_dir is not None:
        write_outputs(result, out_dir)
    return result


def _groove_submodel(beam, mesh: str, poisson: float):
    """The 3-D K_t of the groove nearest the clamp (``groove.groove_kt``) on ``beam``'s section, at
    the root divisions of the ``mesh`` level; the groove as the CAD cuts it."""
    from designer.checks.fea.groove import ROOT_DIVISIONS, groove_kt

    mm = 1e3
    dims = ({"width": beam.width * mm, "height": beam.height * mm} if beam.section == "rectangle" else
            {"diameter": beam.width * mm, **({"wall": beam.wall * mm} if beam.section == "tube" else {})})
    return groove_kt(beam.section, dims, beam.grooves.depth * mm, ROOT_DIVISIONS[mesh], poisson=poisson)


def _recheck(ev, spec, gauges, main: Figures, a, groove=None) -> tuple:
    """Every limit of the beam model again, with the 3-D figures where the check gives them
    (``groove``: the groove submodel's, with load grooves)."""
    from designer.model.analysis import fatigue_factor, notch_sensitivity
    from designer.model.electronics import volts_per_strain
    from designer.model.estimator import sigmas

    k = [float(ki) * g.ratio for ki, g in zip(a.sensitivities, gauges)]
    d = [g.station for g in gauges]
    load = spec.load
    sigma_f, sigma_x = sigmas(k, d, float(a.sigma_v), load.force_min, load.position_max)
    force_error, position_error = float(sigma_f) / load.force_min, float(sigma_x)
    what = "model with 3-D sensitivities"
    if spec.environment is not None:  # the whole error budget (docs/model.md §13) with the 3-D k and strains
        from designer.model.budget import effective_rigidity, region_budget

        strains = [float(e) * g.ratio for e, g in zip(a.gauge_strain, gauges)]
        rigidity = effective_rigidity(main.deflection, load.force_max, load.position_max, ev.design.geometry.length)
        u_f, u_x, _ = region_budget(k, d, strains, spec, ev.design.material_params(spec), rigidity=rigidity)
        force_error, position_error = float(u_f), float(u_x)
        what = "error budget with 3-D sensitivities"
    nominal, notch = float(a.stress_feature), float(a.stress_notch)
    kt_fea = main.feature_peak / notch
    fatigue = fatigue_factor(float(a.notch_sensitivity), kt_fea) * notch
    said = f"K_f from the 3-D K_t = {kt_fea:.2f} (peak at the features / nominal)"
    if main.worst:   # a biaxial sensor: at the worst load direction (§9)
        kt_fea = main.worst[0] / notch
        fatigue = max(fatigue_factor(float(a.notch_sensitivity), kt_fea) * notch, nominal)
        said = (f"K_f from the 3-D K_t = {kt_fea:.2f} (peak at the features under a load {main.worst[1]:g} degrees "
                "from the CAD's Z axis toward Y, the worst, / the notch's nominal), or the plain nominal where larger")
    fea = {
        "stress_feature": (nominal, "beam model: static yield is checked on the nominal stress"),
        "fatigue_feature": (fatigue, said),
        "gauge_strain": (gauges[0].fea_strain, "3-D gauge strain, station 1"),
        "min_signal_snr": (float(a.min_signal_snr) * gauges[-1].ratio, "model x 3-D strain ratio of the last gauge"),
        "deflection": (main.deflection, "3-D free-end deflection"),
        "force_error": (force_error, what),
        "position_error": (position_error, what),
        "adc_range": (volts_per_strain(spec.electronics.excitation, spec.gauge.factor, 1.0, spec.bridge_factor)
                      * gauges[0].fea_strain, "bridge output from the 3-D gauge strain, station 1"),
        "stress_root": (float(a.stress_root), "beam model: the idealised clamp is singular in 3-D"),
    }
    if groove is not None:
        static, fatigue = GROOVE_LIMITS
        nominal_g = float(next(lim.value for lim in ev.limits if lim.name == static))
        q = notch_sensitivity(grooves.ROOT_RADIUS, ev.design.material_params(spec).notch_length)
        fea[static] = (nominal_g, "beam model: static yield is checked on the nominal stress")
        fea[fatigue] = (float(fatigue_factor(q, groove.kt)) * nominal_g,
                        f"K_f from the groove's 3-D K_t = {groove.kt:.2f} (a submodel of the groove nearest the "
                        f"clamp in pure bending, root meshed at r/{groove.divisions:g})")
    # With tolerances (docs/model.md §14) a limit the corners check is judged at its worst corner:
    # the model's value there times the 3-D/model ratio the check measured on the nominal design.
    corner = {} if ev.tolerance is None else {
        lim.name: (lim, label) for lim, label in zip(ev.tolerance.limits, ev.tolerance.corners)}
    out = []
    for lim in ev.limits:
        model_value = float(lim.value)
        value, source = fea.get(lim.name, (model_value, "geometry: as the model"))
        if lim.name in corner:
            worst, label = corner[lim.name]
            ratio = value / model_value if model_value else 1.0
            model_value = float(worst.value)
            value = model_value * ratio
            source = f"at the worst tolerance corner ({label}): the model there x the 3-D/model ratio ({source})"
        scale = None if lim.scale is None else float(lim.scale)
        # the 3-D figures are held to the limits themselves, not to the room the model keeps
        # for its corrections' uncertainty (docs/model.md §4)
        out.append(LimitCheck(lim.name, model_value, value, float(lim.part_limit), lim.upper, source, lim.unit,
                              scale))
    return tuple(out)


def _problem(design: dict, mesh: str):
    """A design.json record's spec, model design, evaluation, CAD beam and 3-D Problem; InputError
    for an unknown mesh level."""
    from designer.outputs import cad
    from designer.result.designfile import parse_design
    from designer.result.evaluation import evaluate

    if mesh not in MESH_LEVELS:
        raise InputError(f"mesh: {mesh!r} is not allowed; must be {describe_allowed(MESH_LEVELS)}")
    record = parse_design(design)
    spec, model_design = record.spec, record.design
    ev = evaluate(model_design, spec)
    beam = cad.resolve(design)
    pb = build_problem(design, beam, ev.analysis, spec, model_design.material, model_design.geometry)
    return spec, model_design, ev, beam, pb


@contextlib.contextmanager
def _step(design: dict, beam):
    """The record's solid as STEP in a temporary folder, for the mesher (removed after)."""
    with tempfile.TemporaryDirectory(prefix="fpdesign-verify-") as tmp:
        step_path = Path(tmp) / f"{beam.file_stem}.step"
        write_step_apart(design, step_path)
        yield step_path


def one_mesh(design: dict, mesh: str = "normal") -> Figures:
    """The figures of a design.json record on the ``mesh`` level alone: no convergence mesh, no
    verdict. For a study that reads a figure again on designs whose check it has already made
    (``checks.peak_places``); a design's check is ``verify_design``."""
    _, _, _, beam, pb = _problem(design, mesh)
    with _step(design, beam) as step_path:
        figures, _ = _run(step_path, pb, mesh, MESH_LEVELS[mesh])
    return figures
