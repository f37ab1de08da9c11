"""``fpdesign bench``: every search method over a suite of specs, against the best known design.

The suite is the optimiser examples plus specs generated from a fixed seed, each of one
*kind*: forces from millinewtons to kilonewtons, beams from a few millimetres to a metre,
tight and loose limits, imperial units, nearly infeasible specs and three kinds that are
infeasible by construction (a lower bound proves it: see ``_infeasible_noise``,
``_infeasible_room`` and ``_infeasible_deflection``). Generated specs are written as
spec.yaml text and read by the real spec reader.

For every spec the best known design is the best verified design over all methods and the
exhaustive reference search (``reference.reference_best``, no casadi, no nlopt), ranked as
the optimiser ranks; the spec is feasible when any of them found a design that meets every
limit. Every method's answer is re-checked from its design.json record alone
(``designfile.rebuild`` + ``evaluation.evaluate``); its gap, time and failures are recorded
both for the pipeline's final answer and for the raw solver runs (``Candidate.solves``).

Computation only: the chart is drawn by ``chart`` from the summary, written by ``write_bench``.
"""

from __future__ import annotations

import csv
import io
import json
import math
import statistics
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import yaml

from designer.spec import catalogue
from designer.errors import FpdError, InputError, SpecError, describe_allowed
from designer.search.optimize import METHODS, TIE_TOLERANCE

DEFAULT_COUNT = 50
DEFAULT_SEED = 0
REFERENCE_LEVELS = 5           # grid points per variable of the reference search (coarse, fast)
CALIBRATION_LEVELS = 5         # the same, for placing a nearly infeasible spec near its limit
VIOLATION_TOLERANCE = 1e-9     # as evaluation.Evaluation.violations
SOLVER_TOLERANCE = 1e-6        # a solver's unrounded answer within this (normalised) meets a limit
SPREAD = (25, 75)              # percentiles of the spread bars
GAP_LINEAR_PERCENT = 0.01      # the symlog chart is linear below 0.01 %

KINDS = ("millinewton", "kilonewton", "infeasible-noise", "imperial", "short-beam", "nearly-infeasible",
         "long-beam", "infeasible-room", "tight-limits", "infeasible-deflection", "loose-limits")
INFEASIBLE_KINDS = ("infeasible-noise", "infeasible-room", "infeasible-deflection")
KIND_NOTES = {
    "example": "the optimiser examples (examples/*.yaml without a design: block)",
    "millinewton": "forces of a few mN to 0.5 N on 15-60 mm beams, small gauge and clearances",
    "kilonewton": "forces up to 5 kN on 0.15-1 m beams, large sections",
    "infeasible-noise": "noise at 1-3x the level at which the force target is unreachable (proved by a bound)",
    "imperial": "lengths in inches and forces in lbf, 3-12 in beams",
    "short-beam": "beams of 6-15 mm, a 1 mm gauge and sub-millimetre clearances",
    "nearly-infeasible": "noise raised until the best reference design meets the targets with 1-5 % to spare",
    "long-beam": "beams of 0.5-1 m under 0.5-50 N",
    "infeasible-room": "load region starting before the stations fit (MODEL.md section 1 geometry rules)",
    "tight-limits": "tight deflection, frequency and section limits, safety factor 3",
    "infeasible-deflection": "deflection limit below the stiffest beam's deflection (proved by a bound)",
    "loose-limits": "no deflection limit, wide sections, loose targets",
}
SECTION_KINDS = ("rectangle", "round", "tube")


# --------------------------------------------------------------------------- the suite

@dataclass(frozen=True)
class SuiteSpec:
    """One problem of the suite: its spec.yaml text, the parsed spec and what is known of it."""

    name: str
    kind: str
    text: str
    spec: object                      # designer.spec.Spec
    expected: str | None = None       # "feasible" or "infeasible" when known by construction


def generate_suite(count: int = DEFAULT_COUNT, seed: int = DEFAULT_SEED, kinds=None) -> list[SuiteSpec]:
    """``count`` generated specs, the kinds taken in turn; spec ``i`` depends only on (seed, i, kind),
    so a shorter suite is the start of a longer one."""
    kinds = tuple(kinds or KINDS)
    for k in kinds:
        if k not in KINDS:
            raise InputError(f"kind {k!r} is not allowed; must be {describe_allowed(KINDS)}")
    return [_generate(i, kinds[i % len(kinds)], seed) for i in range(count)]


def _generate(index: int, kind: str, seed: int) -> SuiteSpec:
    # Rarely a draw leaves no feasible reference design to calibrate on; the next draw is taken.
    for attempt in range(20):
        rng = np.random.default_rng([seed, index, KINDS.index(kind), attempt])
        name = f"{index + 1:03d}-{kind}"
        made = _MAKERS[kind](rng, name)
        if made is not None:
            raw, expected = made
            text = _yaml(raw, kind)
            return SuiteSpec(name, kind, text, _parse(text, name), expected)
    raise FpdError(f"could not generate a {kind} spec from seed {seed}")  # pragma: no cover


def _parse(text: str, name: str):
    from designer.spec.reader import parse_spec_text

    return parse_spec_text(text, source=name, default_name=name)


def _yaml(raw: dict, kind: str) -> str:
    head = f"# fpdesign bench, generated: {kind}: {KIND_NOTES[kind]}\n"
    return head + yaml.safe_dump(raw, sort_keys=False, allow_unicode=True, width=100)


def _q(value: float, unit: str, digits: int = 4) -> str:
    """``value`` (in ``unit``) as spec text, to ``digits`` significant digits."""
    return f"{float(f'{value:.{digits}g}'):g} {unit}"


def _log_uniform(rng, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


@dataclass
class _Draft:
    """Everything a generated spec needs, in SI, before it is written out as spec text."""

    f_min: float
    f_max: float
    x_min: float
    x_max: float
    materials: list
    sections: list
    feature: str = "pocket"
    stations: int = 2
    bridge: str = "half"
    objective: str = "error"
    excitation: float = 5.0
    gain: float = 128.0
    noise_strain: float = 1e-7           # RMS strain-referred noise
    noise_form: str = "noise_strain"     # how the spec gives it
    gauge: object = "BF350-3AA"          # a catalogue name or a dict of fields
    gauge_length: float = 6.9e-3
    max_strain: float = 1.5e-3
    factor: float = 2.0
    limits: dict = field(default_factory=dict)   # SI values or ranges
    force_error: float = 0.01
    position_error: float = 1e-3
    units: str = "si"                    # si | imperial


def _draw_common(rng, f_range, x_range, materials=(2, 3), sections=(1, 2)) -> _Draft:
    names = list(catalogue.materials())
    n_mat = int(rng.integers(materials[0], materials[1] + 1))
    mats = [names[i] for i in sorted(rng.choice(len(names), size=n_mat, replace=False))]
    n_sec = int(rng.integers(sections[0], sections[1] + 1))
    secs = [SECTION_KINDS[i] for i in sorted(rng.choice(3, size=n_sec, replace=False))]
    feature = str(rng.choice(["pocket", "pocket", "pocket", "pocket", "none", "hole"]))
    if feature == "hole":
        secs = ["rectangle"]
    f_min = _log_uniform(rng, *f_range[0])
    f_max = f_min * _log_uniform(rng, *f_range[1])
    x_max = _log_uniform(rng, *x_range)
    d = _Draft(f_min=f_min, f_max=f_max, x_min=0.0, x_max=x_max, materials=mats, sections=secs, feature=feature,
               stations=int(rng.choice([2, 2, 2, 3])), bridge=str(rng.choice(["quarter", "half", "full"])),
               objective=str(rng.choice(["error", "error", "error", "mass", "deflection"])),
               excitation=float(rng.choice([2.5, 3.3, 5.0, 10.0])), gain=float(rng.choice([1, 64, 128, 500, 1000])),
               noise_form=str(rng.choice(["noise_strain", "noise_rti", "noise"])))
    d.gauge = str(rng.choice(["BF120-3AA", "BF350-3AA"]))
    return d


def _small_gauge(d: _Draft, length: float, width: float) -> None:
    d.gauge = {"name": "miniature", "factor": 2.0, "length": length, "width": width, "max_strain": 1.5e-3}
    d.gauge_length = length


def _feature_length(d: _Draft) -> float:
    margin = d.limits.get("pocket_margin", 1e-3)
    if d.feature == "pocket":
        return d.gauge_length + 2 * margin
    if d.feature == "hole":
        return 2 * d.limits.get("min_wall", 1e-3)
    return d.gauge_length


def _room(d: _Draft) -> float:
    """The smallest x_min with room for the stations (as optimize.minimum_room)."""
    lim = d.limits
    lf = d.limits.get("min_wall", 1e-3) if d.feature == "hole" else _feature_length(d)
    return (lim.get("clamp_clearance", 5e-3) + d.stations * lf + (d.stations - 1) * lim.get("gauge_gap", 2e-3)
            + lim.get("load_clearance", 5e-3))


def _place_load(rng, d: _Draft, share=(0.15, 0.6)) -> None:
    """x_min between the room the stations need and x_max; x_max grown if the beam is too short."""
    room = _room(d) + (2 * d.limits.get("min_wall", 1e-3) if d.feature == "hole" else 0.0)
    d.x_max = max(d.x_max, 1.6 * room)
    d.x_min = room + rng.uniform(*share) * (d.x_max - room)


def _strongest_strain(d: _Draft, safety: float | None = None) -> float:
    """The largest strain a gauge may see: its rating, or the best material's allowable stress / E."""
    safety = safety or d.limits.get("safety_factor", 2.0)
    best = max(min(m.yield_strength, m.fatigue) / safety / m.E
               for m in (catalogue.material(n) for n in d.materials))
    return min(d.max_strain, best)


def _size_sections(rng, d: _Draft, spread=(1.5, 4.0), low=(0.1, 0.4)) -> None:
    """Section limits around the square section that carries F_max at x_max at 100 MPa."""
    h = (6 * d.f_max * d.x_max / 100e6) ** (1 / 3)
    hi = h * rng.uniform(*spread)
    lo = max(h * rng.uniform(*low), 0.3e-3)
    d.limits.setdefault("width", (lo, hi * rng.uniform(1.0, 1.5)))
    d.limits.setdefault("height", (lo, hi))
    if d.feature == "pocket" and "min_pocket_depth" not in d.limits:
        d.limits["min_pocket_depth"] = min(0.5e-3, 0.05 * hi)
    d.limits.setdefault("min_wall", min(1e-3, 0.1 * hi))


def _set_targets_and_noise(rng, d: _Draft, e_goal: tuple) -> None:
    """Targets, then the noise for which a strain-limited design would reach ``e`` ~ e_goal.

    The estimate: with every station's strain at most the allowed strain under F_max at x_max,
    kδ·F_max ≤ V_s·G·g·n·ε/4 for station spacing δ, and σ_F/F_min ≥ 2σ_ε F_max/(√N ε F_min)
    (least squares on N stations); the usable spacing shrinks that by (x_max - d_1)/δ.
    """
    d.force_error = rng.uniform(0.005, 0.03)
    first = d.limits.get("clamp_clearance", 5e-3) + _feature_length(d) / 2
    last = d.x_min - d.limits.get("load_clearance", 5e-3) - _feature_length(d) / 2
    spacing = max(last - first, 0.2 * (d.x_min - first))
    arm = (d.x_max - 0.5 * (first + last))
    d.position_error = d.force_error * arm * rng.uniform(0.7, 2.5)
    eps = _strongest_strain(d)
    geometric = (d.x_max - first) / spacing
    d.noise_strain = (_log_uniform(rng, *e_goal) * d.force_error * math.sqrt(d.stations) * eps * d.f_min
                      / (2 * d.f_max * geometric))


def _raw(d: _Draft) -> dict:
    """The spec as a YAML-ready mapping of values with units."""
    imperial = d.units == "imperial"
    inch, lbf = 0.0254, 4.4482216152605

    def length(v, unit="mm"):
        if imperial:
            return _q(v / inch, "in")
        return _q(v * 1e3, "mm") if unit == "mm" else _q(v, "m")

    def force(v):
        if imperial:
            return _q(v / lbf, "lbf")
        return _q(v * 1e3, "mN") if v < 1 else (_q(v / 1e3, "kN") if v >= 1e3 else _q(v, "N"))

    n = {"quarter": 1, "half": 2, "full": 4}[d.bridge]
    sigma_v = d.excitation * d.factor * d.gain * n * d.noise_strain / 4
    if d.noise_form == "noise_rti":
        noise = {"noise_rti": _q(sigma_v / d.gain * 1e9, "nV")}
    elif d.noise_form == "noise":
        noise = {"noise": _q(sigma_v * 1e3, "mV")}
    else:
        noise = {"noise_strain": _q(d.noise_strain * 1e6, "ue")}
    gauge = d.gauge if isinstance(d.gauge, str) else {
        "name": d.gauge["name"], "factor": d.gauge["factor"], "length": length(d.gauge["length"]),
        "width": length(d.gauge["width"]), "max_strain": _q(d.gauge["max_strain"] * 1e6, "ue")}
    limits = {}
    for key, value in d.limits.items():
        if key in ("width", "height"):
            limits[key] = [length(value[0]), length(value[1])]
        elif key in ("safety_factor", "max_pocket_fraction", "min_snr"):
            limits[key] = float(f"{value:.4g}")
        elif key == "min_frequency":
            limits[key] = _q(value, "Hz")
        elif key == "fatigue":
            limits[key] = bool(value)
        else:
            limits[key] = length(value)
    return {
        "name": None,
        "load": {"force": [force(d.f_min), force(d.f_max)], "position": [length(d.x_min), length(d.x_max)]},
        "electronics": {"excitation": _q(d.excitation, "V"), "gain": d.gain, **noise},
        "gauge": gauge, "bridge": d.bridge, "stations": d.stations, "limits": limits,
        "targets": {"force_error": _q(d.force_error * 100, "%", 3), "position_error": length(d.position_error)},
        "search": {"materials": list(d.materials), "sections": list(d.sections), "feature": d.feature},
        "objective": d.objective,
    }


def _finish(d: _Draft, name: str, expected: str | None = None):
    raw = _raw(d)
    raw["name"] = name
    return raw, expected


# -- the kinds --------------------------------------------------------------------------

def _millinewton(rng, name):
    d = _draw_common(rng, ((1e-3, 5e-3), (20, 100)), (15e-3, 60e-3))
    _small_gauge(d, 1.5e-3, 1.2e-3)
    d.limits.update(clamp_clearance=1e-3, load_clearance=1e-3, tip_margin=1e-3, pocket_margin=0.2e-3,
                    gauge_gap=0.5e-3, min_wall=0.2e-3, min_pocket_depth=0.05e-3)
    _place_load(rng, d)
    _size_sections(rng, d)
    _set_targets_and_noise(rng, d, (0.15, 0.6))
    return _finish(d, name)


def _kilonewton(rng, name):
    d = _draw_common(rng, ((20.0, 200.0), (5, 25)), (0.15, 1.0))
    d.gauge = "CEA-06-125UW-120"
    d.gauge_length, d.max_strain, d.factor = 10.7e-3, 1.2e-3, 2.1
    _place_load(rng, d)
    _size_sections(rng, d)
    d.limits["max_deflection"] = 0.02 * d.x_max
    _set_targets_and_noise(rng, d, (0.15, 0.6))
    return _finish(d, name)


def _imperial(rng, name):
    d = _draw_common(rng, ((0.5, 5.0), (10, 40)), (0.075, 0.3))
    d.units = "imperial"
    _place_load(rng, d)
    _size_sections(rng, d)
    d.limits["max_deflection"] = 0.01 * d.x_max * rng.uniform(0.5, 2.0)
    _set_targets_and_noise(rng, d, (0.15, 0.6))
    return _finish(d, name)


def _short_beam(rng, name):
    d = _draw_common(rng, ((0.01, 0.05), (10, 50)), (6e-3, 15e-3))
    d.feature = str(rng.choice(["pocket", "none"]))
    d.sections = [s for s in d.sections] if d.feature != "hole" else ["rectangle"]
    _small_gauge(d, 1.0e-3, 0.8e-3)
    d.limits.update(clamp_clearance=0.3e-3, load_clearance=0.3e-3, tip_margin=0.5e-3, pocket_margin=0.1e-3,
                    gauge_gap=0.2e-3, min_wall=0.1e-3, min_pocket_depth=0.02e-3)
    _place_load(rng, d)
    _size_sections(rng, d, low=(0.3, 0.5))
    _set_targets_and_noise(rng, d, (0.15, 0.6))
    return _finish(d, name)


def _long_beam(rng, name):
    d = _draw_common(rng, ((0.5, 2.0), (10, 25)), (0.5, 1.0))
    _place_load(rng, d)
    _size_sections(rng, d)
    _set_targets_and_noise(rng, d, (0.15, 0.6))
    return _finish(d, name)


def _moderate(rng):
    d = _draw_common(rng, ((0.2, 5.0), (10, 40)), (0.06, 0.3))
    _place_load(rng, d)
    return d


def _tight_limits(rng, name):
    d = _moderate(rng)
    d.limits["safety_factor"] = 3.0
    _size_sections(rng, d, spread=(1.1, 1.6), low=(0.5, 0.8))
    h = d.limits["height"][1]
    # a strain-limited uniform beam deflects w = (2/3) eps x^2 / h at its tip
    d.limits["max_deflection"] = rng.uniform(1.5, 4.0) * 2 / 3 * _strongest_strain(d) * d.x_max ** 2 / h
    d.limits["min_frequency"] = rng.uniform(5, 40)
    _set_targets_and_noise(rng, d, (0.3, 0.8))
    return _finish(d, name)


def _loose_limits(rng, name):
    d = _moderate(rng)
    d.sections = list(SECTION_KINDS) if d.feature != "hole" else ["rectangle"]
    _size_sections(rng, d, spread=(3.0, 6.0), low=(0.05, 0.2))
    d.limits["fatigue"] = False
    _set_targets_and_noise(rng, d, (0.05, 0.2))
    return _finish(d, name)


def _nearly_infeasible(rng, name):
    """Noise raised until the reference search's best design meets the targets with 1-5 % to spare."""
    from designer.search import reference
    from designer.result.evaluation import evaluate

    d = _moderate(rng)
    d.objective = "error"
    d.noise_form = "noise_strain"
    _size_sections(rng, d)
    _set_targets_and_noise(rng, d, (0.2, 0.5))
    raw, _ = _finish(d, name)
    spec = _parse(_yaml(raw, "nearly-infeasible"), name)
    best = reference.reference_best(spec, levels=CALIBRATION_LEVELS)
    if best is None or not best.feasible:
        return None
    scale = rng.uniform(0.95, 0.99) / best.objective
    for _ in range(30):
        trial = replace(d, noise_strain=d.noise_strain * scale)
        raw, _ = _finish(trial, name)
        ev = evaluate(best.design, _parse(_yaml(raw, "nearly-infeasible"), name))
        if ev.feasible:
            return raw, "feasible"
        scale *= 0.97   # the strain-ratio limit binds before the targets: back off
    return None


def _infeasible_noise(rng, name):
    """Noise above the bound σ_F/F_min ≥ 2σ_ε F_max/(√N ε_max F_min) = target (see above)."""
    d = _moderate(rng)
    d.noise_form = "noise_strain"
    _size_sections(rng, d)
    _set_targets_and_noise(rng, d, (0.2, 0.5))
    floor = d.force_error * math.sqrt(d.stations) * d.max_strain * d.f_min / (2 * d.f_max)
    d.noise_strain = floor * rng.uniform(1.2, 3.0)
    return _finish(d, name, "infeasible")


def _infeasible_room(rng, name):
    d = _moderate(rng)
    _size_sections(rng, d)
    _set_targets_and_noise(rng, d, (0.2, 0.5))
    d.x_min = _room(d) * rng.uniform(0.6, 0.95)
    return _finish(d, name, "infeasible")


def _infeasible_deflection(rng, name):
    """max_deflection below F_max x_max^3 / (3 E I) of the stiffest material and largest section."""
    d = _moderate(rng)
    _size_sections(rng, d)
    _set_targets_and_noise(rng, d, (0.2, 0.5))
    w, h = d.limits["width"][1], d.limits["height"][1]
    inertia = max({"rectangle": w * h ** 3 / 12, "round": math.pi * min(w, h) ** 4 / 64,
                   "tube": math.pi * min(w, h) ** 4 / 64}[s] for s in d.sections)
    stiffest = max(catalogue.material(m).E for m in d.materials)
    floor = d.f_max * d.x_max ** 3 / (3 * stiffest * inertia)
    d.limits["max_deflection"] = floor * rng.uniform(0.2, 0.8)
    return _finish(d, name, "infeasible")


_MAKERS = {"millinewton": _millinewton, "kilonewton": _kilonewton, "infeasible-noise": _infeasible_noise,
           "imperial": _imperial, "short-beam": _short_beam, "nearly-infeasible": _nearly_infeasible,
           "long-beam": _long_beam, "infeasible-room": _infeasible_room, "tight-limits": _tight_limits,
           "infeasible-deflection": _infeasible_deflection, "loose-limits": _loose_limits}


def example_suite(folder) -> tuple[list[SuiteSpec], list[str]]:
    """The optimiser specs of ``folder`` (``*.yaml``); fixed designs (a ``design:`` block) are
    left out and named in the second list."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"--specs: {folder} is not a folder; give a folder of spec.yaml files")
    suite, skipped = [], []
    for path in sorted(folder.glob("*.yaml")) + sorted(folder.glob("*.yml")):
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"--specs: {path} cannot be read ({exc})") from exc
        try:
            spec = _parse(text, path.stem)
        except SpecError as exc:
            raise SpecError(f"{path}: {exc}") from exc
        if spec.design is not None:
            skipped.append(path.name)
            continue
        suite.append(SuiteSpec(path.stem, "example", text, spec, None))
    return suite, skipped


def default_examples_folder() -> Path | None:
    """The examples folder shipped beside the package (a source tree or an editable install)."""
    folder = Path(__file__).resolve().parents[2] / "examples"
    return folder if folder.is_dir() else None


# --------------------------------------------------------------------------- one method on one spec

@dataclass
class Run:
    """One method on one spec: what the pipeline answered, re-checked, and what its solvers did."""

    spec: str
    kind: str
    method: str
    seconds: float
    error: str = ""                   # an exception optimize() raised: the run gave no answer
    unreadable: str = ""              # why designfile.validate refused the design.json record
    status: str = ""                  # the record's status: optimal | infeasible
    objective: float | None = None    # of the reported design, re-evaluated from design.json
    worst_violation: float | None = None
    violated: tuple = ()
    deflection: float | None = None
    mass: float | None = None
    design: str = ""
    candidates: int = 0
    solves: int = 0                   # runs of the method itself (not its fallback)
    solver_successes: int = 0
    false_successes: int = 0          # said success, but its own answer breaks a limit it was given
    rounding_breaks: int = 0          # said success and met the limits, but no rounded design does
    solver_exceptions: int = 0        # the solver raised (caught by the adapter)
    fallback_solves: int = 0          # runs of the fallback method
    fallbacks: int = 0                # lines in record['solver']['fallbacks']
    raw_objective: float | None = None  # best verified design from the method's own runs alone
    evaluations: int = 0
    record: dict | None = field(default=None, repr=False)

    @property
    def feasible(self) -> bool:
        """The re-checked answer meets every limit."""
        return self.worst_violation is not None and self.worst_violation <= VIOLATION_TOLERANCE


def run_method(item: SuiteSpec, method: str) -> Run:
    """``optimize`` with one method; every exception is caught and recorded, never raised."""
    from designer.search import optimize

    t0 = time.perf_counter()
    try:
        outcome = optimize.optimize(item.spec, method)
    except Exception as exc:  # noqa: BLE001 - the bench records every failure
        return Run(item.name, item.kind, method, time.perf_counter() - t0,
                   error=f"{type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - t0
    run = Run(item.name, item.kind, method, seconds, status=outcome.record["status"],
              candidates=len(outcome.candidates), fallbacks=len(outcome.record["solver"].get("fallbacks", [])),
              evaluations=outcome.evaluations)
    _recheck(run, outcome.record)
    _solver_counts(run, item.spec, outcome)
    return run


def _recheck(run: Run, record: dict) -> None:
    """Re-evaluate the reported design from its design.json record alone."""
    from designer.result import designfile
    from designer.result.evaluation import evaluate

    try:
        copy_ = json.loads(json.dumps(record, allow_nan=False))
    except (ValueError, TypeError) as exc:
        run.unreadable = f"not valid JSON: {exc}"
        return
    try:
        designfile.validate(copy_)
    except FpdError as exc:  # the product's own reader refuses it; still judged below if it can be
        run.unreadable = str(exc)
    try:
        spec, design = designfile.rebuild(copy_)
        ev = evaluate(design, spec)
    except (FpdError, ValueError, KeyError, TypeError, ArithmeticError) as exc:
        run.unreadable = run.unreadable or f"cannot be rebuilt: {type(exc).__name__}: {exc}"
        return
    run.record = copy_
    run.objective = float(ev.objective)
    run.worst_violation = float(ev.worst_violation)
    run.violated = tuple(v.name for v in ev.violations)
    run.deflection = float(ev.analysis.deflection)
    run.mass = float(ev.analysis.mass)
    run.design = ev.design.label() + ("" if ev.design.geometry.feature in ("pocket", "none")
                                      else f"+{ev.design.geometry.feature}")


def _solver_counts(run: Run, spec, outcome) -> None:
    """The raw solver behaviour from the Solve records: successes, false successes, exceptions,
    and the best verified design the method found on its own (without its fallback)."""
    from designer.search.optimize import FamilyProblem, pick, round_and_check

    own = []
    for cand in outcome.candidates:
        problem = FamilyProblem.__new__(FamilyProblem)  # variables only: no casadi graph
        problem.spec, problem.family = spec, cand.family
        problem.names, problem.lower, problem.upper = problem._variables()
        material = catalogue.material(cand.material)
        for s in cand.solves:
            if s.method != run.method:
                run.fallback_solves += 1
                continue
            run.solves += 1
            if _raised(s):
                run.solver_exceptions += 1
            try:
                ev = round_and_check(problem.design(s.x, material), spec)
            except (FpdError, ValueError, ArithmeticError):
                ev = None
            if s.success:
                run.solver_successes += 1
                if ev is None or _breaks_limits(ev, spec):
                    if _unrounded_breaks(problem.design(s.x, material), spec):
                        run.false_successes += 1
                    else:
                        run.rounding_breaks += 1
            if ev is not None:
                own.append(ev)
    best = pick(own)
    if best is not None and best.feasible:
        run.raw_objective = float(best.objective)


def _raised(solve) -> bool:
    """The adapters turn a solver's exception into a failed Solve whose message names it."""
    message = solve.message
    return not solve.success and (message.startswith("IPOPT raised")
                                  or (message.startswith("nlopt ") and not message.startswith("nlopt result")))


def _unrounded_breaks(design, spec) -> bool:
    """The solver's own answer, before rounding, breaks a limit by more than SOLVER_TOLERANCE."""
    from designer.result.evaluation import evaluate

    try:
        with np.errstate(all="ignore"):
            ev = evaluate(design, spec)
    except (FpdError, ValueError, ArithmeticError):
        return True
    targets = ("force_error", "position_error") if spec.objective == "error" else ()
    worst = [float(lim.normalised) for lim in ev.limits if lim.name not in targets]
    return not all(math.isfinite(w) and w <= SOLVER_TOLERANCE for w in worst)


def _breaks_limits(ev, spec) -> bool:
    """A limit the solver was asked to meet is broken. With the error objective the targets are
    the objective (e <= 1 is a verdict, not a constraint of the solve)."""
    targets = ("force_error", "position_error") if spec.objective == "error" else ()
    return any(v.name not in targets for v in ev.violations)


# --------------------------------------------------------------------------- the best known design

@dataclass(frozen=True)
class Truth:
    """What is known of one spec after every method and the reference search."""

    spec: str
    kind: str
    expected: str | None
    feasible: bool
    lead: float | None          # the lowest verified objective (the tie band is measured from it)
    best: float | None          # the best known design's objective (MODEL.md 5 ranking)
    best_by: str                # who found it
    reference: float | None     # the reference search's objective
    reference_feasible: bool
    reference_seconds: float
    objective: str

    @property
    def verdict(self) -> str:
        return "feasible" if self.feasible else "infeasible"


def establish_truth(item: SuiteSpec, runs: list[Run], levels: int = REFERENCE_LEVELS) -> Truth:
    """The best known design of one spec: the reference search and every run's re-checked answer,
    ranked as the optimiser ranks (MODEL.md 5)."""
    from designer.result import designfile
    from designer.search import reference
    from designer.result.evaluation import evaluate
    from designer.search.optimize import rank

    t0 = time.perf_counter()
    try:
        ref = reference.reference_best(item.spec, levels=levels)
    except (FpdError, ValueError, ArithmeticError):
        ref = None
    ref_seconds = time.perf_counter() - t0
    ref_objective = None if ref is None else float(ref.objective)
    found = []  # (evaluation, who found it)
    if ref is not None and ref.feasible:
        found.append((ref, "reference"))
    for run in runs:
        if run.record is not None and run.feasible:
            spec, design = designfile.rebuild(run.record)
            found.append((evaluate(design, spec), run.method))
    if not found:
        return Truth(item.name, item.kind, item.expected, False, None, None, "", ref_objective, False, ref_seconds,
                     item.spec.objective)
    best = rank([ev for ev, _ in found])[0]
    who = sorted({w for ev, w in found if _same(ev, best)})
    lead = min(float(ev.objective) for ev, _ in found)
    return Truth(item.name, item.kind, item.expected, True, lead, float(best.objective), ", ".join(who),
                 ref_objective, bool(ref is not None and ref.feasible), ref_seconds, item.spec.objective)


def _same(a, b) -> bool:
    return a.design.label() == b.design.label() and abs(a.objective - b.objective) <= 1e-12 * abs(b.objective)


def gap(run: Run, truth: Truth) -> float | None:
    """Objective above the lowest verified objective, as a fraction; 0 inside the tie band
    (MODEL.md 5: designs within 0.1 % tie and rank by deflection, then mass); inf when the
    spec is feasible but the run gave no design that meets every limit; None for an
    infeasible spec."""
    if not truth.feasible:
        return None
    if run.error or not run.feasible or run.status != "optimal":
        return math.inf
    return _tie_gap(run.objective, truth.lead)


def raw_gap(run: Run, truth: Truth) -> float | None:
    """The same for the method's own runs, without the fallback method."""
    if not truth.feasible:
        return None
    if run.raw_objective is None:
        return math.inf
    return _tie_gap(run.raw_objective, truth.lead)


def exact_gap(run: Run, truth: Truth) -> float | None:
    """Objective above the lowest verified objective, without the tie band."""
    if not truth.feasible or run.objective is None or not run.feasible:
        return None
    return max(run.objective / truth.lead - 1, 0.0) if truth.lead > 0 else run.objective - truth.lead


def _tie_gap(objective: float, lead: float) -> float:
    excess = objective / lead - 1 if lead > 0 else objective - lead
    return 0.0 if excess <= TIE_TOLERANCE else excess


FAILURE_KINDS = ("exception", "violating", "missed", "unreadable")


def failures(run: Run, truth: Truth) -> dict:
    """The pipeline's failures on one spec, by kind (each 0 or 1)."""
    reported_optimal = not run.error and run.status == "optimal"
    return {
        "exception": int(bool(run.error)),
        "violating": int(reported_optimal and not run.feasible),        # optimal, yet a limit is broken
        "missed": int(not run.error and truth.feasible and run.status != "optimal"),  # feasible called infeasible
        "unreadable": int(bool(run.unreadable)),                        # design.json its reader refuses
    }


# --------------------------------------------------------------------------- the bench

@dataclass
class BenchResult:
    """Every run of every method on every spec, and what is known of each spec."""

    suite: list
    methods: tuple
    runs: list
    truths: dict                 # spec name -> Truth
    seed: int
    count: int
    levels: int
    skipped: list = field(default_factory=list)   # example files left out (fixed designs)
    seconds: float = 0.0

    def truth(self, run: Run) -> Truth:
        return self.truths[run.spec]

    @property
    def kinds(self) -> list[str]:
        present = {item.kind for item in self.suite}
        return [k for k in ("example",) + KINDS if k in present]


def run_bench(suite: list, methods=METHODS, levels: int = REFERENCE_LEVELS, progress=None, seed: int = DEFAULT_SEED,
              count: int | None = None, skipped=()) -> BenchResult:
    """Run every method on every spec of ``suite``, then the reference search; ``progress(done,
    total, name)`` is called after each spec. The methods' order turns by one from spec to spec,
    so that no method always runs first on a busy machine."""
    methods = tuple(methods)
    for m in methods:
        if m not in METHODS:
            raise InputError(f"--methods: {m!r} is not allowed; must be {describe_allowed(METHODS)}")
    t0 = time.perf_counter()
    if suite:
        _warm_up(suite[0], methods)
    runs, truths = [], {}
    for i, item in enumerate(suite):
        order = methods[i % len(methods):] + methods[:i % len(methods)]
        spec_runs = {m: run_method(item, m) for m in order}
        truths[item.name] = establish_truth(item, list(spec_runs.values()), levels)
        runs += [spec_runs[m] for m in methods]
        if progress is not None:
            progress(i + 1, len(suite), item.name)
    return BenchResult(list(suite), methods, runs, truths, seed,
                       sum(1 for s in suite if s.kind != "example") if count is None else count, levels,
                       list(skipped), time.perf_counter() - t0)


def _warm_up(item: SuiteSpec, methods) -> None:
    """One small untimed search per method: libraries and solver plugins load before the clock runs."""
    from designer.search import optimize

    spec = item.spec
    small = replace(spec, search=replace(spec.search, materials=spec.search.materials[:1],
                                         sections=spec.search.sections[:1]))
    for m in methods:
        try:
            optimize.optimize(small, m)
        except Exception:  # noqa: BLE001 - the timed run records it
            pass


# --------------------------------------------------------------------------- summaries

def _median(values):
    return statistics.median(values) if values else None


def _percentile(values, q):
    """A percentile that is one of the values (inf allowed: a run without a design)."""
    if not values:
        return None
    return float(np.percentile(np.asarray(values, dtype=float), q, method="inverted_cdf"))


def method_summary(result: BenchResult) -> list[dict]:
    """Per method: medians and spreads of time and gap, counts of every failure, and whether its
    (median time, 90th-percentile gap) point is on the speed-accuracy front.

    The gap's median is 0 for every method that finds the best design on most specs, so it
    cannot tell them apart; the 90th percentile says how far off the method's bad answers are.
    ``on_median_front`` records the front of (median time, median gap) as well."""
    rows = []
    for m in result.methods:
        runs = [r for r in result.runs if r.method == m]
        feasible_runs = [r for r in runs if result.truth(r).feasible]
        times = [r.seconds for r in runs]
        gaps = [gap(r, result.truth(r)) for r in feasible_runs]
        raw = [raw_gap(r, result.truth(r)) for r in feasible_runs]
        exact = [g for g in (exact_gap(r, result.truth(r)) for r in feasible_runs) if g is not None]
        fails = [failures(r, result.truth(r)) for r in runs]
        rows.append({
            "method": m, "specs": len(runs), "feasible_specs": len(feasible_runs),
            "median_seconds": _median(times), "seconds_low": _percentile(times, SPREAD[0]),
            "seconds_high": _percentile(times, SPREAD[1]), "total_seconds": sum(times),
            "median_gap": _median_gap(gaps), "gap_low": _percentile(gaps, SPREAD[0]),
            "gap_high": _percentile(gaps, SPREAD[1]), "p90_gap": _percentile(gaps, 90),
            "mean_exact_gap": statistics.fmean(exact) if exact else None,
            "at_best": sum(1 for g in gaps if g == 0), "raw_median_gap": _median_gap(raw),
            "raw_at_best": sum(1 for g in raw if g == 0),
            "exception": sum(f["exception"] for f in fails), "violating": sum(f["violating"] for f in fails),
            "missed": sum(f["missed"] for f in fails), "unreadable": sum(f["unreadable"] for f in fails),
            "solves": sum(r.solves for r in runs), "solver_successes": sum(r.solver_successes for r in runs),
            "false_successes": sum(r.false_successes for r in runs),
            "rounding_breaks": sum(r.rounding_breaks for r in runs),
            "solver_exceptions": sum(r.solver_exceptions for r in runs),
            "fallback_solves": sum(r.fallback_solves for r in runs),
            "fallback_specs": sum(1 for r in runs if r.fallback_solves),
        })
    front = pareto_front([(r["median_seconds"], r["p90_gap"]) for r in rows])
    median_front = pareto_front([(r["median_seconds"], r["median_gap"]) for r in rows])
    for i, r in enumerate(rows):
        r["failures"] = sum(r[k] for k in FAILURE_KINDS)
        r["on_front"] = i in front
        r["on_median_front"] = i in median_front
        r["time_vs_default"] = _paired_time_ratio(result, r["method"])
    return rows


def _paired_time_ratio(result: BenchResult, method: str, default: str = "ipopt") -> float | None:
    """The median over specs of the method's time over the default method's on the same spec:
    on a shared machine a paired ratio is steadier than a ratio of medians."""
    base = {r.spec: r.seconds for r in result.runs if r.method == default}
    ratios = [r.seconds / base[r.spec] for r in result.runs
              if r.method == method and base.get(r.spec, 0) > 0]
    return statistics.median(ratios) if ratios else None


def _median_gap(gaps):
    return _percentile(gaps, 50)


def pareto_front(points) -> set:
    """Indices of the points no other point beats on both (time, gap), lower being better."""
    out = set()
    for i, (t, g) in enumerate(points):
        if t is None or g is None:
            continue
        dominated = any(u is not None and h is not None and u <= t and h <= g and (u < t or h < g)
                        for j, (u, h) in enumerate(points) if j != i)
        if not dominated:
            out.add(i)
    return out


def stability_rows(result: BenchResult) -> list[dict]:
    """Failures per method and kind of spec (long form: one row per method x kind)."""
    rows = []
    for m in result.methods:
        for kind in result.kinds:
            runs = [r for r in result.runs if r.method == m and r.kind == kind]
            fails = [failures(r, result.truth(r)) for r in runs]
            row = {"method": m, "kind": kind, "specs": len(runs),
                   "feasible_specs": sum(1 for r in runs if result.truth(r).feasible)}
            for key in FAILURE_KINDS:
                row[key] = sum(f[key] for f in fails)
            row["pipeline_failures"] = sum(row[k] for k in FAILURE_KINDS)
            row.update(solves=sum(r.solves for r in runs), false_successes=sum(r.false_successes for r in runs),
                       rounding_breaks=sum(r.rounding_breaks for r in runs),
                       solver_exceptions=sum(r.solver_exceptions for r in runs),
                       fallback_solves=sum(r.fallback_solves for r in runs))
            gaps = [gap(r, result.truth(r)) for r in runs if result.truth(r).feasible]
            row["median_gap"] = _median_gap(gaps)
            rows.append(row)
    return rows


def failure_list(result: BenchResult) -> list[dict]:
    """Every failing run, with what went wrong."""
    out = []
    for r in result.runs:
        t = result.truth(r)
        f = failures(r, t)
        if f["exception"]:
            what = f"raised {r.error}"
        elif f["violating"]:
            what = f"reported optimal but breaks {', '.join(r.violated)} (worst {r.worst_violation:.3g})"
        elif f["missed"]:
            what = (f"called infeasible ({', '.join(r.violated[:4]) or 'no design'}); best known "
                    f"{t.best:.6g} by {t.best_by}")
        elif f["unreadable"]:
            what = f"wrote a design.json (status {r.status}) that its reader refuses: {r.unreadable}"
        else:
            continue
        out.append({"method": r.method, "spec": r.spec, "kind": r.kind, "what": what})
    return out


def construction_mismatches(result: BenchResult) -> list[str]:
    """Specs whose verdict differs from the one they were built to have (a model or bench defect)."""
    return [f"{t.spec}: built {t.expected}, found {t.verdict}" for t in result.truths.values()
            if t.expected is not None and t.expected != t.verdict]


# --------------------------------------------------------------------------- tables and files

def _pct(value, digits: int = 3) -> str:
    if value is None:
        return "–"
    if math.isinf(value):
        return "no design"
    if value == 0:
        return "0"
    return f"{value * 100:.{digits}g} %"


def _sec(value) -> str:
    return "–" if value is None else f"{value:.3g}"


def _ratio(value) -> str:
    return "–" if value is None else f"{value:.2f}×"


def _num(value) -> str:
    return "" if value is None else (repr(float(value)) if not math.isinf(value) else "inf")


def _md_table(header: list, rows: list, text_columns: int = 1) -> str:
    """A Markdown table; the first ``text_columns`` columns left-aligned, numbers right-aligned."""
    out = ["| " + " | ".join(header) + " |",
           "|" + "|".join("---" if i < text_columns else "---:" for i in range(len(header))) + "|"]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def summary_tables(result: BenchResult, rows=None) -> tuple[str, str]:
    """The per-method tables as Markdown: speed and accuracy; failures."""
    rows = rows or method_summary(result)
    lo, hi = SPREAD
    speed = _md_table(
        ["method", "median time, s", f"time p{lo}-p{hi}, s", "time / ipopt's", "median gap", f"gap p{lo}-p{hi}",
         "p90 gap", "at best", "raw median gap", "on the front"],
        [[r["method"], _sec(r["median_seconds"]), f"{_sec(r['seconds_low'])}-{_sec(r['seconds_high'])}",
          _ratio(r["time_vs_default"]), _pct(r["median_gap"]), f"{_pct(r['gap_low'])} to {_pct(r['gap_high'])}",
          _pct(r["p90_gap"]), f"{r['at_best']}/{r['feasible_specs']}", _pct(r["raw_median_gap"]),
          "yes" if r["on_front"] else "no"]
         for r in rows])
    fails = _md_table(
        ["method", "exceptions", "violating", "missed", "unreadable", "solves", "false successes",
         "rounding breaks", "solver exceptions", "specs with a fallback"],
        [[r["method"], r["exception"], r["violating"], r["missed"], r["unreadable"], r["solves"],
          r["false_successes"], r["rounding_breaks"], r["solver_exceptions"], r["fallback_specs"]] for r in rows])
    return speed, fails


def stability_markdown(result: BenchResult, rows=None) -> str:
    rows = rows or stability_rows(result)
    kinds = result.kinds
    counts = {k: sum(1 for s in result.suite if s.kind == k) for k in kinds}
    header = ["method"] + [f"{k} ({counts[k]})" for k in kinds] + ["total"]
    cell = {(r["method"], r["kind"]): r for r in rows}

    def matrix(key_fn):
        body = []
        for m in result.methods:
            vals = [key_fn(cell[(m, k)]) for k in kinds]
            body.append([m] + [str(v) for v in vals] + [str(sum(vals))])
        return _md_table(header, body)

    return "\n\n".join([
        "Pipeline failures (what `fpdesign optimize --method M` returns): exceptions + designs reported "
        "optimal that break a limit on re-check + feasible specs called infeasible + design.json records "
        "that `designfile.load_design` refuses. Columns: kind of spec (number of specs).",
        matrix(lambda r: r["pipeline_failures"]),
        "Raw solver failures (from the Solve records, before the pipeline's check and fallback): runs that "
        "said success but whose design breaks a limit (before or only after rounding to 0.01 mm), plus runs "
        "whose solver raised.",
        matrix(lambda r: r["false_successes"] + r["rounding_breaks"] + r["solver_exceptions"]),
    ])


def stability_csv(result: BenchResult, rows=None) -> str:
    rows = rows or stability_rows(result)
    buf = io.StringIO()
    keys = ["method", "kind", "specs", "feasible_specs", *FAILURE_KINDS, "pipeline_failures",
            "solves", "false_successes", "rounding_breaks", "solver_exceptions", "fallback_solves", "median_gap"]
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: (_num(r[k]) if k == "median_gap" else r[k]) for k in keys})
    return buf.getvalue()


def runs_csv(result: BenchResult) -> str:
    buf = io.StringIO()
    keys = ["spec", "kind", "method", "seconds", "status", "objective", "gap", "exact_gap", "raw_objective",
            "raw_gap", "worst_violation", "violated", "design", "deflection", "mass", "candidates", "solves",
            "solver_successes", "false_successes", "rounding_breaks", "solver_exceptions", "fallback_solves",
            "fallbacks",
            "evaluations", *FAILURE_KINDS, "error", "unreadable_reason"]
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for r in result.runs:
        t = result.truth(r)
        f = failures(r, t)
        w.writerow({"spec": r.spec, "kind": r.kind, "method": r.method, "seconds": f"{r.seconds:.4f}",
                    "status": r.status, "objective": _num(r.objective), "gap": _num(gap(r, t)),
                    "exact_gap": _num(exact_gap(r, t)), "raw_objective": _num(r.raw_objective),
                    "raw_gap": _num(raw_gap(r, t)), "worst_violation": _num(r.worst_violation),
                    "violated": " ".join(r.violated), "design": r.design, "deflection": _num(r.deflection),
                    "mass": _num(r.mass), "candidates": r.candidates, "solves": r.solves,
                    "solver_successes": r.solver_successes, "false_successes": r.false_successes,
                    "rounding_breaks": r.rounding_breaks,
                    "solver_exceptions": r.solver_exceptions, "fallback_solves": r.fallback_solves,
                    "fallbacks": r.fallbacks, "evaluations": r.evaluations, **f, "error": r.error,
                    "unreadable_reason": r.unreadable})
    return buf.getvalue()


def specs_csv(result: BenchResult) -> str:
    buf = io.StringIO()
    keys = ["spec", "kind", "objective", "expected", "verdict", "lead_objective", "best_objective", "best_by",
            "reference_objective", "reference_feasible", "reference_seconds"]
    w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
    w.writeheader()
    for item in result.suite:
        t = result.truths[item.name]
        w.writerow({"spec": t.spec, "kind": t.kind, "objective": t.objective, "expected": t.expected or "",
                    "verdict": t.verdict, "lead_objective": _num(t.lead), "best_objective": _num(t.best),
                    "best_by": t.best_by, "reference_objective": _num(t.reference),
                    "reference_feasible": t.reference_feasible, "reference_seconds": f"{t.reference_seconds:.4f}"})
    return buf.getvalue()


def markdown(result: BenchResult, chart_file: str = "bench.png") -> str:
    """bench.md: settings, the per-method table, the chart, the stability tables and every failure."""
    import platform

    summary = method_summary(result)
    speed_table, failure_table = summary_tables(result, summary)
    n_ex = sum(1 for s in result.suite if s.kind == "example")
    n_gen = len(result.suite) - n_ex
    truths = list(result.truths.values())
    n_feasible = sum(1 for t in truths if t.feasible)
    default = next((r for r in summary if r["method"] == "ipopt"), None)
    lines = [
        "# Search methods compared: speed, accuracy and stability",
        "",
        f"`fpdesign bench` ran {len(result.methods)} methods ({', '.join(result.methods)}) on {len(result.suite)} "
        f"specs: {n_ex} optimiser examples and {n_gen} generated from seed {result.seed} "
        f"({n_feasible} feasible, {len(truths) - n_feasible} infeasible). Reference search: "
        f"`reference.reference_best` at {result.levels} levels. Total {result.seconds / 60:.1f} min on "
        f"{os_cpu()} ({platform.python_implementation()} {platform.python_version()}); the machine was shared, "
        "so times are medians of single runs and only their ratios mean much.",
        "",
        "- **time**: wall time of one `optimize` call (every material x section family, with the method's "
        "start points, checks and fallback), after a warm-up.",
        "- **gap**: reported objective over the lowest verified objective any method or the reference "
        f"found for that spec, minus one. Within the {TIE_TOLERANCE:.1%} tie band it counts as 0: "
        "there MODEL.md section 5 ranks designs by deflection, then mass, not by objective. *no design*: "
        "the spec is feasible but the method returned no design that meets every limit. Medians are over "
        "the feasible specs; spreads are the "
        f"{SPREAD[0]}th-{SPREAD[1]}th percentiles.",
        "- **raw median gap**: the same for the method's own runs alone, without the fallback method "
        "(`optimize` falls back to IPOPT, and IPOPT to SLSQP, when no start gives a verified design; IPOPT "
        "does not when every start ended in a verdict: locally infeasible, or the targets out of reach).",
        "- **violating**: reported optimal, but the design rebuilt from its design.json record "
        "(`designfile.rebuild` + `evaluation.evaluate`) breaks a limit. **missed**: called infeasible though "
        "a design that meets every limit is known. **exceptions**: `optimize` raised. **unreadable**: the "
        "design.json record is refused by the product's own reader (`designfile.validate`), so `plot`, "
        "`export` or `simulate` cannot use it.",
        "- **solves**: runs of the method itself. **false successes**: runs that reported success though "
        f"their own answer breaks a limit they were given by more than {SOLVER_TOLERANCE:g} (normalised; "
        "with the error objective the targets are the objective, not limits); **rounding breaks**: runs "
        "that reported success and met every limit, but no design rounded to 0.01 mm near the answer does; "
        "**solver exceptions**: runs whose solver raised (caught by the adapter). The pipeline checks every "
        "run, so these cost time, not correctness.",
        "- **time / ipopt's**: the median over specs of the method's time over IPOPT's on the same spec "
        "(paired, so steadier than a ratio of medians on a shared machine).",
        "- **front**: no other method has both a lower (or equal) median time and a lower (or equal) "
        "90th-percentile gap. The median gap is 0 for every method that finds the best design on most "
        "specs and cannot tell them apart; the 90th percentile says how far off a method's bad answers are.",
        "",
        "## Per method",
        "",
        speed_table,
        "",
        f"![Solve time against objective gap]({chart_file})",
        "",
        failure_table,
        "",
    ]
    if default is not None:
        lines += [_default_verdict(default, summary), ""]
    lines += ["## Stability", "", stability_markdown(result), ""]
    fails = failure_list(result)
    lines += ["## Every pipeline failure", ""]
    if fails:
        lines += [_md_table(["method", "spec", "kind", "what happened"],
                            [[f["method"], f["spec"], f["kind"], f["what"].replace("|", "/")] for f in fails],
                            text_columns=4)]
    else:
        lines += ["None."]
    lines += [""]
    mism = construction_mismatches(result)
    lines += ["## Verdicts", "",
              "Specs built to be infeasible carry a proof (a lower bound on the force error, the room the "
              "stations need, or the deflection of the stiffest beam allowed); nearly infeasible ones carry "
              "a design that meets every limit with 1-5 % to spare on the targets.", ""]
    kind_rows = []
    for k in result.kinds:
        ts = [t for t in truths if t.kind == k]
        kind_rows.append([k, KIND_NOTES[k], len(ts), sum(t.feasible for t in ts), sum(not t.feasible for t in ts)])
    lines += [_md_table(["kind", "what it is", "specs", "feasible", "infeasible"], kind_rows, text_columns=2), ""]
    lines += ["Built verdicts contradicted: " + ("; ".join(mism) if mism else "none.")]
    if result.skipped:
        lines += ["", "Example files left out (fixed designs, `design:` block): " + ", ".join(result.skipped) + "."]
    lines += ["", "Files: `runs.csv` (every run), `specs.csv` (every spec's verdict and best known design), "
              "`stability.csv`, `suite/*.yaml` (the generated specs).", ""]
    return "\n".join(lines)


def _default_verdict(default: dict, summary: list) -> str:
    """What the bench says of the default method, in words."""
    clean = not (default["violating"] or default["missed"] or default["exception"])
    out = "On this suite the default method's pipeline " + (
        "never returned a design that breaks a limit and never called a feasible spec infeasible; "
        if clean else f"returned {default['violating']} designs that break a limit, called {default['missed']} "
                      f"feasible specs infeasible and raised {default['exception']} times (listed below); ")
    out += ("IPOPT is on the speed-accuracy front (median time, 90th-percentile gap). " if default["on_front"]
            else "IPOPT is NOT on the speed-accuracy front (median time, 90th-percentile gap). ")
    if default["on_median_front"]:
        return out + "It is also on the front of medians (median time, median gap)."
    better = [r for r in summary if r is not default and r["median_seconds"] is not None
              and r["median_gap"] is not None and r["median_seconds"] <= default["median_seconds"]
              and r["median_gap"] <= default["median_gap"]]
    parts = [f"{r['method']} (median {_sec(r['median_seconds'])} s against {_sec(default['median_seconds'])} s, "
             f"{_ratio(r['time_vs_default'])} of IPOPT's time on the median spec; median gap "
             f"{_pct(r['median_gap'])} against {_pct(default['median_gap'])}; 90th percentile "
             f"{_pct(r['p90_gap'])} against {_pct(default['p90_gap'])}; best known design found on "
             f"{r['at_best']} specs against {default['at_best']})" for r in better]
    return out + "On medians alone it is dominated by " + "; ".join(parts) + "."


def os_cpu() -> str:
    import os

    n = os.cpu_count() or 0
    return f"{n} CPU core{'s' if n != 1 else ''}"


def terminal_table(result: BenchResult, rows=None):
    """The per-method table as a rich Table (the command prints it)."""
    from rich.table import Table

    rows = rows or method_summary(result)
    table = Table(title=f"fpdesign bench: {len(result.suite)} specs, "
                        f"{sum(t.feasible for t in result.truths.values())} feasible")
    for name in ("method", "median s", "median gap", "p90 gap", "at best", "exc/viol/\nmiss/unread",
                 "raw false/\nround/exc", "front"):
        table.add_column(name, justify="left" if name == "method" else "right")
    for r in rows:
        table.add_row(r["method"], _sec(r["median_seconds"]), _pct(r["median_gap"]), _pct(r["p90_gap"]),
                      f"{r['at_best']}/{r['feasible_specs']}",
                      f"{r['exception']}/{r['violating']}/{r['missed']}/{r['unreadable']}",
                      f"{r['false_successes']}/{r['rounding_breaks']}/{r['solver_exceptions']}",
                      "yes" if r["on_front"] else "no")
    return table


def write_bench(result: BenchResult, out_dir) -> list[Path]:
    """bench.md, bench.png, stability.md, stability.csv, runs.csv, specs.csv and suite/*.yaml, all
    or nothing."""
    from designer.outputs.files import atomic_write_bytes, atomic_write_text, staged_directory

    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"-o: {out_dir} is a file, not a folder; give a folder for the bench's files")
    names = []
    with staged_directory(out_dir) as scratch:
        fig = chart(chart_data(result))
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=150)
        atomic_write_bytes(scratch / "bench.png", buf.getvalue())
        files = {"bench.md": markdown(result, "bench.png"),
                 "stability.md": "# Stability: failures per method and kind of spec\n\n" + stability_markdown(result)
                 + "\n", "stability.csv": stability_csv(result), "runs.csv": runs_csv(result),
                 "specs.csv": specs_csv(result)}
        for name, text in files.items():
            atomic_write_text(scratch / name, text)
        for item in result.suite:
            if item.kind != "example":
                atomic_write_text(scratch / "suite" / f"{item.name}.yaml", item.text)
        names = sorted(p.relative_to(scratch) for p in scratch.rglob("*") if p.is_file())
    return [out_dir / n for n in names]


# --------------------------------------------------------------------------- the chart

def chart_data(result: BenchResult) -> dict:
    """What ``chart`` draws: per method its medians and spreads; per run its time and gap."""
    summary = method_summary(result)
    points = [{"method": r.method, "seconds": r.seconds, "gap": gap(r, result.truth(r))}
              for r in result.runs if result.truth(r).feasible]
    return {"methods": summary, "points": points, "specs": len(result.suite),
            "feasible_specs": sum(t.feasible for t in result.truths.values()), "tie": TIE_TOLERANCE}


def chart(data: dict, ax=None):
    """Solve time (log) against objective gap (symlog %), one point per method (median time with
    its spread, 90th-percentile gap with a bar down to the median gap) over faint per-spec points;
    the speed-accuracy front dashed. Returns the figure."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.ticker import NullFormatter

    if ax is None:
        fig = Figure(figsize=(9.5, 6.0), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    methods = data["methods"]
    finite = [p["gap"] * 100 for p in data["points"] if p["gap"] is not None and math.isfinite(p["gap"])]
    top = 10 ** math.ceil(math.log10(max(finite + [10.0]))) * 3   # the "no design" row, % above every gap
    colours = {m: f"C{i}" for i, m in enumerate(METHODS)}

    def y(g):
        return top if g is None or math.isinf(g) else g * 100

    for p in data["points"]:
        missing = p["gap"] is not None and math.isinf(p["gap"])
        ax.scatter(p["seconds"], y(p["gap"]), s=22 if missing else 12, color=colours[p["method"]],
                   alpha=0.6 if missing else 0.28, linewidths=1.2 if missing else 0,
                   marker="x" if missing else "o", zorder=1)
    offsets = _label_offsets([(r["median_seconds"], y(r["p90_gap"])) for r in methods])
    for r, offset in zip(methods, offsets):
        t, g = r["median_seconds"], r["p90_gap"]
        if t is None or g is None:
            continue
        xerr = [[t - r["seconds_low"]], [r["seconds_high"] - t]]
        yerr = [[y(g) - y(r["median_gap"])], [0.0]]  # down to the median gap
        c = colours[r["method"]]
        default = r["method"] == "ipopt"  # a diamond on top: no other point hides it
        ax.errorbar(t, y(g), xerr=xerr, yerr=yerr, fmt="D" if default else "o", ms=8 if default else 9, color=c,
                    mec="black", mew=1.4 if default else 0.8, elinewidth=1.4, capsize=3, zorder=5 if default else 3)
        label = r["method"] + (" (default)" if r["method"] == "ipopt" else "")
        ax.annotate(label, (t, y(g)), xytext=offset, textcoords="offset points", fontsize=9,
                    fontweight="bold" if r["method"] == "ipopt" else "normal", color=c, zorder=4)
    front = sorted((r["median_seconds"], y(r["p90_gap"])) for r in methods if r["on_front"])
    if front:
        xs, ys = zip(*front)
        ax.plot(xs, ys, ls="--", color="0.3", lw=1.2, zorder=2, drawstyle="steps-post")
    linthresh = data["tie"] * 100
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide when times span under a decade
    ax.set_yscale("symlog", linthresh=linthresh, linscale=0.6)
    ax.set_ylim(-linthresh * 0.3, top * 2.5)
    ax.axhline(top / 1.8, color="0.75", lw=0.8)
    ticks = [0] + [10.0 ** k for k in range(int(round(math.log10(linthresh))), int(math.log10(top)))]
    ax.set_yticks(ticks + [top])
    ax.set_yticklabels([_tick(v) for v in ticks] + ["no design"])
    ax.set_xlabel("wall time of one optimize call, s (log scale)")
    ax.set_ylabel(f"objective gap to the best known design, %\n(symlog; 0 = within the {data['tie']:.1%} tie band)")
    ax.set_title(f"Speed against accuracy: {len(methods)} methods on {data['feasible_specs']} feasible specs "
                 f"(of {data['specs']})", fontsize=11)
    ax.grid(True, which="major", alpha=0.3)
    handles = [Line2D([], [], marker="D" if r["method"] == "ipopt" else "o", ls="", color=colours[r["method"]],
                      mec="black", ms=7 if r["method"] == "ipopt" else 8, label=r["method"])
               for r in methods]
    handles += [Line2D([], [], marker="o", ls="", color="0.5", alpha=0.3, ms=5, label="one spec"),
                Line2D([], [], marker="x", ls="", color="0.5", ms=5, label="one spec, no design"),
                Line2D([], [], color="black", lw=1.2, label=f"median time (p{SPREAD[0]}-p{SPREAD[1]} bar),\n"
                                                             "p90 gap (bar down to the median gap)"),
                Line2D([], [], ls="--", color="0.3", label="speed-accuracy front")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8.5, frameon=False)
    return fig


def _label_offsets(points) -> list:
    """Text offsets (points) that keep the labels of nearby method points apart: labels of
    points less than a factor 4 apart in time and at about the same gap (equal, or within a
    factor 1.6) are stacked."""
    out = [(7, 7)] * len(points)
    order = sorted(range(len(points)), key=lambda i: (points[i][1] or 0, points[i][0] or 0))
    stack = []
    for i in order:
        t, g = points[i]
        if t is None or g is None:
            continue
        stack = [j for j in stack if _about(points[j][1], g) and t / points[j][0] < 4]
        used = {out[j] for j in stack}
        out[i] = next(o for o in ((7, 7 + 12 * k) for k in range(len(points) + 1)) if o not in used)
        stack.append(i)
    return out


def _about(a: float, b: float) -> bool:
    return a == b or (a > 0 and b > 0 and max(a, b) / min(a, b) < 1.6)


def _tick(v: float) -> str:
    return "0" if v == 0 else f"{v:g}"
