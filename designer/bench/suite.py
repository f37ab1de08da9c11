"""The bench's suite: the optimiser examples and specs generated from a fixed seed.

Each generated spec is of one *kind*: forces from millinewtons to kilonewtons, beams from a few
millimetres to a metre, tight and loose limits, imperial units, nearly infeasible specs and three
kinds that are infeasible by construction (a lower bound proves it: see ``_infeasible_noise``,
``_infeasible_room`` and ``_infeasible_deflection``). Generated specs are written as spec.yaml
text and read by the real spec reader.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import yaml

from designer import model
from designer.errors import FpdError, InputError, SpecError, describe_allowed
from designer.spec import catalogue

DEFAULT_COUNT = 50
DEFAULT_SEED = 0
CALIBRATION_LEVELS = 5         # grid points per variable of the reference search calibrating a nearly infeasible spec

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
            spec = _parse(text, name)
            if _has_sizes(spec):
                return SuiteSpec(name, kind, text, spec, expected)
    raise FpdError(f"could not generate a {kind} spec from seed {seed}")  # pragma: no cover


def _has_sizes(spec) -> bool:
    """Whether some family of the spec has a size to try: a tube only comes from stock, and a
    draw's section limits may leave none of its materials' tubes (the product refuses such a spec,
    ``search.sections: tube leaves no size to try``). The product's own rule (``stock_rows``)."""
    from designer.search.problem import FamilyProblem, families
    from designer.search.stock import stock_system, stock_rows

    try:
        every = families(spec)
    except SpecError:
        return False
    for fam in every:
        if stock_system(spec, fam) == "none":
            return True
        problem = FamilyProblem(spec, fam)
        if any(stock_rows(problem, catalogue.material(m))[0] for m in spec.search.materials):
            return True
    return False


def _parse(text: str, name: str, folder: Path | None = None):
    from designer.spec.reader import parse_spec_text

    return parse_spec_text(text, source=name, default_name=name, folder=folder)


def _is_catalogue(text: str) -> bool:
    """Whether a YAML file of a specs folder is a user catalogue (docs/spec.md 2.9), not a spec:
    a mapping of catalogue keys alone."""
    from designer.spec import catalogue, strict_yaml

    try:
        raw = strict_yaml.load(text)
    except Exception:  # noqa: BLE001 - not YAML: the spec reader says what is wrong
        return False
    return isinstance(raw, dict) and bool(raw) and set(raw) <= set(catalogue.USER_KEYS)


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
    end_mill: float | None = None        # cad.end_mill_diameter: a micro end mill for a miniature gauge's slot


def _draw_common(rng, f_range, x_range, materials=(2, 3), sections=(1, 2)) -> _Draft:
    names = list(catalogue.materials())
    n_mat = int(rng.integers(materials[0], materials[1] + 1))
    mats = [names[i] for i in sorted(rng.choice(len(names), size=n_mat, replace=False))]
    n_sec = int(rng.integers(sections[0], sections[1] + 1))
    secs = [SECTION_KINDS[i] for i in sorted(rng.choice(3, size=n_sec, replace=False))]
    feature = str(rng.choice(["pocket", "pocket", "pocket", "pocket", "none", "hole"]))
    if feature == "hole":
        secs = ["rectangle"]
    if secs == ["tube"] and not any(catalogue.stock().rows(m, "tube", "any") for m in mats):
        secs = ["round", "tube"]  # a tube is only bought (docs/model.md §5): a family these materials can make
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


def _feature_length(d: _Draft, hole: float | None = None) -> float:
    """``model.feature_length`` of the draft's numbers: a pocket the gauge plus its margins long,
    a hole of ``hole`` (by default twice the smallest wall, a typical hole), or the gauge."""
    min_wall = d.limits.get("min_wall", 1e-3)
    pocket_length = d.gauge_length + 2 * d.limits.get("pocket_margin", 1e-3)
    return model.feature_length(d.feature, pocket_length, 2 * min_wall if hole is None else hole, d.gauge_length)


def _room(d: _Draft) -> float:
    """The smallest x_min with room for the stations, ``model.minimum_room`` and the load clearance (a hole
    no narrower than the smallest wall) from the draft's numbers: the draft is not a Spec yet."""
    lim = d.limits
    lf = _feature_length(d, hole=lim.get("min_wall", 1e-3))
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
        **({"cad": {"end_mill_diameter": length(d.end_mill)}} if d.end_mill is not None else {}),
        # the suite measures the search at nominal sizes: a general class (ISO 2768-m's ±0.1 mm)
        # leaves its millimetre beams no design, and their drawings would give their own deviations
        "tolerances": {"class": "none"},
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
    d.end_mill = 0.8e-3   # the 1.6 mm slot is too narrow for the CAD's standard end mills (from 1 mm)
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
    d.end_mill = 0.5e-3   # likewise for its 1.0 mm slot
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
    scale = rng.uniform(0.95, 0.99) / best.error_ratio
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
        raise InputError(f"specs folder: {folder} is not a folder; give a folder of spec.yaml files")
    suite, skipped = [], []
    for path in sorted(folder.glob("*.yaml")) + sorted(folder.glob("*.yml")):
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise InputError(f"specs folder: {path} cannot be read ({exc})") from exc
        if _is_catalogue(text):   # (a catalogue the specs beside it name)
            skipped.append(f"{path.name} (a catalogue)")
            continue
        try:
            spec = _parse(text, path.stem, path.parent)
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

