"""Reading spec.yaml (SPEC.md) into frozen dataclasses, SI throughout.

Every problem is reported as a SpecError that names the key, the value and what is
allowed; the command line turns it into exit code 2.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from designer.spec import catalogue
from designer.spec import strict_yaml, units
from designer.spec.catalogue import Gauge
from designer.spec.stock import STOCK_CHOICES
from designer.errors import SpecError, brief, describe_allowed, read_text
from designer.model.electronics import BRIDGE_FACTORS, output_noise
from designer.spec.cad import CadOptions, parse_cad
from designer.spec.electronics import Electronics, parse_electronics
from designer.spec.environment import CalibrationSetup, Environment, check_thermal, parse_calibration, parse_environment
from designer.spec.tolerances import Tolerances, parse_tolerances
from designer.spec.keys import boolean, mapping as _mapping, plain_name, required as _required

SECTION_KINDS = ("rectangle", "round", "tube")
FEATURE_KINDS = ("pocket", "hole", "none")
BRIDGES = BRIDGE_FACTORS
OBJECTIVES = ("error", "deflection", "mass")
DEFAULT_GAUGE = "BF120-3AA"


@dataclass(frozen=True)
class Load:
    force_min: float       # N
    force_max: float
    position_min: float    # m from the clamp face
    position_max: float


@dataclass(frozen=True)
class Limits:
    safety_factor: float = 2.0
    fatigue: bool = True
    max_deflection: float | None = None
    min_frequency: float | None = None
    width: tuple[float, float] = (0.002, 0.050)
    height: tuple[float, float] = (0.002, 0.050)
    min_wall: float = 0.001
    clamp_clearance: float = 0.005
    load_clearance: float = 0.005
    tip_margin: float = 0.005
    pocket_margin: float = 0.001
    gauge_gap: float = 0.002
    min_pocket_depth: float = 0.0005
    max_pocket_fraction: float = 0.3
    min_snr: float = 5.0


@dataclass(frozen=True)
class Targets:
    force_error: float = 0.01      # sigma_F / F_min
    position_error: float = 0.001  # sigma_x at (F_min, x_max), m


@dataclass(frozen=True)
class Search:
    materials: tuple[str, ...]
    sections: tuple[str, ...] = SECTION_KINDS
    feature: str = "pocket"
    stock: str = "none"    # none: continuous sizes; metric | imperial | any: rows of materials/stock.yaml


@dataclass(frozen=True)
class Section:
    kind: str
    width: float | None = None      # rectangle
    height: float | None = None     # rectangle
    diameter: float | None = None   # round, tube
    wall: float | None = None       # tube

    @property
    def across(self) -> float:
        """Bounding-box size across the beam (Y)."""
        return self.width if self.kind == "rectangle" else self.diameter

    @property
    def depth(self) -> float:
        """Bounding-box size in the load direction (Z)."""
        return self.height if self.kind == "rectangle" else self.diameter

    def as_dict(self) -> dict:
        keys = {"rectangle": ("width", "height"), "round": ("diameter",), "tube": ("diameter", "wall")}
        return {"kind": self.kind, **{k: getattr(self, k) for k in keys[self.kind]}}


@dataclass(frozen=True)
class Feature:
    kind: str
    depth: float = 0.0        # pocket depth p, m
    diameter: float = 0.0     # hole diameter d_h, m
    length: float = 0.0       # pocket length along the beam, m
    width: float = 0.0        # pocket width across the beam, m

    def as_dict(self) -> dict:
        if self.kind == "pocket":
            return {"kind": "pocket", "depth": self.depth, "length": self.length, "width": self.width}
        if self.kind == "hole":
            return {"kind": "hole", "diameter": self.diameter}
        return {"kind": "none"}


@dataclass(frozen=True)
class FixedDesign:
    material: str
    section: Section
    stations: tuple[float, ...]
    feature: Feature
    length: float | None = None


@dataclass(frozen=True)
class Spec:
    name: str
    load: Load
    electronics: Electronics
    gauge: Gauge
    bridge: str = "half"
    stations: int = 2
    axes: int = 1
    limits: Limits = field(default_factory=Limits)
    targets: Targets = field(default_factory=Targets)
    search: Search = field(default_factory=lambda: Search(materials=()))
    objective: str = "error"
    cad: CadOptions = field(default_factory=CadOptions)
    design: FixedDesign | None = None
    catalogue: tuple = ()     # the user catalogues: (file, content) pairs (spec.catalogue.use)
    environment: Environment | None = None   # the error budget's temperatures (docs/model.md §13)
    calibration: CalibrationSetup = field(default_factory=CalibrationSetup)
    tolerances: Tolerances = field(default_factory=Tolerances)   # the built sizes' deviations (docs/model.md §14)

    @property
    def bridge_factor(self) -> int:
        """n = 1, 2, 4 active arms for quarter, half and full bridges."""
        return BRIDGES[self.bridge]

    @property
    def sigma_v(self) -> float:
        """Noise per channel at the amplifier output, V (docs/model.md §3)."""
        e = self.electronics
        if e.adc is not None:
            return e.gain * self.front_end_noise.total
        return output_noise(e.excitation, e.gain, self.gauge.factor, self.bridge_factor, e.noise, e.noise_rti,
                            e.noise_strain)

    @property
    def front_end_noise(self):
        """The catalogue front-end's noise and range (``model.FrontEndNoise``), None without one."""
        e = self.electronics
        if e.adc is None:
            return None
        from designer.model.electronics import front_end_noise

        return front_end_noise(e.front_end, e.gain, e.rate, e.excitation, self.gauge.resistance, e.bits, e.reference)

    @property
    def free_length(self) -> float:
        if self.design is not None and self.design.length is not None:
            return self.design.length
        return self.load.position_max + self.limits.tip_margin

    def pocket_size(self) -> tuple[float, float]:
        """Pocket length along and width across the beam (MODEL.md section 1): the gauge backing
        with ``limits.pocket_margin`` all round, and at least ``cad.corner_radius``, so that the
        backing lies on the flat floor, inside the radius the end mill leaves where the floor
        meets the walls."""
        margin = max(self.limits.pocket_margin, self.cad.corner_radius)
        return self.gauge.length + 2 * margin, self.gauge.width + 2 * margin

    def to_dict(self) -> dict:
        """The normalised spec, SI, as written into design.json."""
        out = {
            "name": self.name,
            "load": {"force": [self.load.force_min, self.load.force_max],
                     "position": [self.load.position_min, self.load.position_max]},
            "electronics": asdict(self.electronics) | {"noise_output": self.sigma_v},
            "gauge": self.gauge.as_dict(),
            "bridge": self.bridge, "stations": self.stations, "axes": self.axes,
            "limits": {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self.limits).items()},
            "targets": asdict(self.targets),
            "search": {"materials": list(self.search.materials), "sections": list(self.search.sections),
                       "feature": self.search.feature, "stock": self.search.stock},
            "objective": self.objective,
            "cad": {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self.cad).items()},
        }
        if self.environment is not None:
            env = self.environment
            out["environment"] = {"temperature": list(env.temperature), "calibrated_at": env.calibrated_at,
                                  "hold": env.hold, "tare": env.tare}
            # (a spec without an environment has no calibration block: design.json's spec reads as a spec)
            out["calibration"] = asdict(self.calibration)
        out["tolerances"] = self.tolerances.as_dict()
        if self.catalogue:
            # the content itself, so that design.json is read again without the files
            out["catalogue"] = [{"file": f, **content} for f, content in self.catalogue]
        if self.design is not None:
            out["design"] = {"material": self.design.material, "section": self.design.section.as_dict(),
                             "stations": list(self.design.stations), "feature": self.design.feature.as_dict(),
                             "length": self.design.length}
        return out


# --------------------------------------------------------------------------- reading

_TOP_KEYS = ("name", "load", "electronics", "gauge", "bridge", "stations", "axes", "limits",
             "targets", "search", "objective", "design", "cad", "catalogue", "environment", "calibration",
             "tolerances")


def load_spec(path: str | Path, catalogues=()) -> Spec:
    """The spec file at ``path``; its ``catalogue`` files are read from its folder, and the user
    catalogues ``catalogues`` (``catalogue.read_user`` pairs, from the command line) join them."""
    path = Path(path)
    text = read_text(path, SpecError)
    return parse_spec_text(text, source=str(path), default_name=path.stem, folder=path.parent,
                           catalogues=catalogues)


def parse_spec_text(text: str, source: str = "spec", default_name: str = "sensor", folder: Path | None = None,
                    catalogues=()) -> Spec:
    raw = strict_yaml.load_as(text, source, SpecError)
    if raw is None:
        raise SpecError(f"{source}: the file is empty; a spec needs at least 'load' and 'electronics'")
    if not isinstance(raw, dict):
        raise SpecError(f"{source}: a spec must be a mapping of keys such as 'load' and 'electronics', "
                        f"not {type(raw).__name__}")
    if raw.get("calibration") is not None and raw.get("environment") is None:
        raise SpecError("calibration: its weights and placement are terms of the error budget, which only a spec "
                        "with environment has (docs/spec.md 2.10); give environment.temperature or leave "
                        "calibration out")
    return parse_spec(raw, default_name=default_name, folder=folder, catalogues=catalogues)


def _catalogue_name(value, key: str, lookup):
    """A catalogue entry by name; a name that is not text is refused before the look-up."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        raise SpecError(f"{key}: {value!r} was read as a number; quote a name that looks like one "
                        f"(\"{value}\"), as `fpdesign materials` lists them")
    if not isinstance(value, str):
        raise SpecError(f"{key}: {value!r} is not a catalogue name; give one name as text, "
                        "as `fpdesign materials` lists them")
    return lookup(value, key)


def _choice(value, choices, key: str):
    if value not in choices:
        raise SpecError(f"{key}: {value!r} is not allowed; must be {describe_allowed(choices)}")
    return value


def _integer(value, key: str, minimum: int, maximum: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not float(value).is_integer():
        raise SpecError(f"{key}: {value!r} must be a whole number")
    value = int(value)
    if value < minimum or (maximum is not None and value > maximum):
        allowed = f"from {minimum} to {maximum}" if maximum is not None else f"at least {minimum}"
        raise SpecError(f"{key}: {value} is out of range; must be {allowed}")
    return value


def parse_spec(raw: dict, default_name: str = "sensor", folder: Path | None = None, catalogues=()) -> Spec:
    """The spec of a loaded mapping. ``folder``: where its ``catalogue`` files are (the spec
    file's folder; None: the working folder); ``catalogues``: user catalogues given besides
    (``catalogue.read_user`` pairs). The spec's user catalogues are put in force first
    (``catalogue.use``; none: the shipped catalogue alone)."""
    raw = _mapping(raw, "spec", _TOP_KEYS)
    user = _parse_catalogue(raw.get("catalogue"), folder) + tuple(catalogues)
    catalogue.use(user)
    name = plain_name(raw.get("name", default_name), "name")

    load_raw = _mapping(_required(raw, "load", ""), "load", ("force", "position"))
    f_min, f_max = units.parse_range(_required(load_raw, "force", "load"), "force", "load.force")
    x_min, x_max = units.parse_range(_required(load_raw, "position", "load"), "length", "load.position")
    load = Load(f_min, f_max, x_min, x_max)

    electronics = parse_electronics(_required(raw, "electronics", ""))
    gauge = _parse_gauge(raw.get("gauge"))
    bridge = _choice(raw.get("bridge", "half"), tuple(BRIDGES), "bridge")
    stations = _integer(raw.get("stations", 2), "stations", 2, 10)
    axes = _integer(raw.get("axes", 1), "axes", 1, 2)
    limits = _parse_limits(raw.get("limits"))
    targets = _parse_targets(raw.get("targets"), x_max)
    search = _parse_search(raw.get("search"))
    objective = _choice(raw.get("objective", "error"), OBJECTIVES, "objective")
    design = _parse_design(raw["design"], limits, gauge) if raw.get("design") is not None else None
    cad = parse_cad(raw.get("cad"), limits, design, search.stock)

    if axes == 2:
        if search.feature == "hole":
            raise SpecError("search.feature: 'hole' is not allowed with axes: 2; a biaxial sensor "
                            "needs a feature on all four faces: use pocket or none")
        if design is not None and design.feature.kind == "hole":
            raise SpecError("design.feature.kind: 'hole' is not allowed with axes: 2; use pocket or none")
        if design is not None and design.section.kind == "rectangle" and \
                not math.isclose(design.section.width, design.section.height, rel_tol=1e-9):
            raise SpecError("design.section: a biaxial (axes: 2) rectangle must be square; "
                            f"width {design.section.width * 1e3:g} mm differs from height "
                            f"{design.section.height * 1e3:g} mm")
    if search.feature == "hole" and search.sections != ("rectangle",):
        bad = [s for s in search.sections if s != "rectangle"]
        raise SpecError(f"search.sections: {bad[0]!r} cannot carry a hole; with feature: hole use "
                        "sections: [rectangle]")
    spec = Spec(name=name.strip(), load=load, electronics=electronics, gauge=gauge, bridge=bridge,
                stations=len(design.stations) if design else stations, axes=axes, limits=limits,
                targets=targets, search=search, objective=objective, cad=cad, design=design, catalogue=user,
                environment=parse_environment(raw.get("environment")),
                calibration=parse_calibration(raw.get("calibration")),
                tolerances=parse_tolerances(raw.get("tolerances")))
    if spec.environment is not None:
        check_thermal(spec)
    if design is not None and spec.free_length < x_max:
        raise SpecError(f"design.length: {spec.free_length * 1e3:g} mm is shorter than the largest load "
                        f"position load.position[1] = {x_max * 1e3:g} mm")
    if spec.cad.load_grooves:
        _check_grooves(spec)
    return spec


def _check_grooves(spec) -> None:
    """The load grooves on the beam, half a groove's width inside its free end, and apart (the
    CAD's rules, checked before a search that would end in them)."""
    from designer.model import grooves

    given, t = spec.cad.groove_positions, spec.cad.groove_depth
    lim = spec.limits
    largest = min(lim.width[1], lim.height[1])
    if t is not None and spec.design is None and t > grooves.DEPTH_FRACTION * largest + 1e-12:
        raise SpecError(f"cad.groove_depth: {t * 1e3:g} mm is too deep for any section limits.width and limits.height "
                        f"allow: a groove is at most {grooves.DEPTH_FRACTION:.0%} of the section's smaller side, "
                        f"{grooves.DEPTH_FRACTION * largest * 1e3:.4g} mm on the largest ({largest * 1e3:g} mm)")
    at = sorted(grooves.positions(spec))
    end = spec.free_length - grooves.WIDTH / 2
    if at[-1] > end + 1e-12:
        where = ("design.length" if spec.design is not None and spec.design.length is not None
                 else "load.position[1] + limits.tip_margin")
        key = (f"cad.groove_positions[{given.index(at[-1])}]: {at[-1] * 1e3:g} mm" if given else
               f"cad.load_grooves: the default groove at load.position[1] = {at[-1] * 1e3:g} mm")
        hint = ("" if given else "; give cad.groove_positions, or a longer design.length" if where == "design.length"
                else "; give limits.tip_margin or cad.groove_positions")
        raise SpecError(f"{key} is past the free end less half a groove's width ({where} = "
                        f"{spec.free_length * 1e3:g} mm, less {grooves.WIDTH / 2 * 1e3:g} mm); must be at most "
                        f"{end * 1e3:g} mm{hint}")
    if (pair := grooves.overlapping(at)) is not None:
        a, b = pair
        raise SpecError(f"cad.groove_positions: grooves at {a * 1e3:g} mm and {b * 1e3:g} mm overlap; they must "
                        f"be more than {grooves.WIDTH * 1e3:g} mm apart")


def _parse_catalogue(raw, folder: Path | None) -> tuple:
    """``catalogue``: a user catalogue file (a path, relative to the spec's folder), a catalogue
    written out (a mapping, as design.json records it), or a list of either; ``(file, content)``
    pairs."""
    if raw is None:
        return ()
    items = raw if isinstance(raw, list) else [raw]
    if not items:
        raise SpecError("catalogue: [] must name at least one catalogue file")
    out = []
    for i, item in enumerate(items):
        key = "catalogue" if not isinstance(raw, list) else f"catalogue[{i}]"
        if isinstance(item, str) and item.strip():
            out.append(catalogue.read_user(catalogue.user_file(item, folder), item))
        elif isinstance(item, dict):
            shown = item.get("file", key)
            if not isinstance(shown, str) or not shown.strip():
                raise SpecError(f"{key}.file: {shown!r} must be the catalogue's file name (text)")
            out.append((shown, catalogue.user_content(item, shown)))
        else:
            raise SpecError(f"{key}: {item!r} must be the path of a catalogue file (text), or a list of them")
    return tuple(out)


def _parse_gauge(raw) -> Gauge:
    if raw is None:
        return catalogue.gauge(DEFAULT_GAUGE)
    if isinstance(raw, str):
        return catalogue.gauge(raw, "gauge")
    keys = ("name",) + tuple(catalogue.GAUGE_FIELDS) + tuple(catalogue.GAUGE_THERMAL)
    raw = _mapping(raw, "gauge", keys)
    fields = catalogue.plausible({k: units.parse_positive(v, catalogue.GAUGE_FIELDS[k], f"gauge.{k}")
                                  for k, v in raw.items() if k in catalogue.GAUGE_FIELDS}, "gauge", SpecError)
    fields |= catalogue.gauge_thermal(raw, "gauge", in_spec=True)
    name = raw.get("name")
    if name is not None and not isinstance(name, str):
        _catalogue_name(name, "gauge.name", catalogue.gauge)
    if name is not None and (base := catalogue.modified_from(name)) is not None:
        name = base   # a modified catalogue gauge as design.json records it: the same gauge again
    if name is not None and name in catalogue.gauges():
        return catalogue.grid_on_backing(catalogue.customised(catalogue.gauge(name), **fields), "gauge", SpecError)
    missing = [k for k in ("factor", "length", "width", "max_strain") if k not in fields]
    if missing and name is not None:
        catalogue.gauge(name)  # an unknown name with incomplete fields: say which names exist
    if missing:
        raise SpecError(f"gauge.{missing[0]}: missing; a gauge without a catalogue name needs "
                        "factor, length, width and max_strain")
    fields.setdefault("resistance", 120.0)
    fields.setdefault("grid_length", fields["length"] / 2)
    fields.setdefault("grid_width", fields["width"] / 2)
    return catalogue.grid_on_backing(Gauge(name=name or "custom", **fields), "gauge", SpecError)


_LIMIT_KINDS = {
    "safety_factor": "ratio", "max_deflection": "length", "min_frequency": "frequency",
    "min_wall": "length", "clamp_clearance": "length", "load_clearance": "length",
    "tip_margin": "length", "pocket_margin": "length", "gauge_gap": "length",
    "min_pocket_depth": "length", "max_pocket_fraction": "ratio", "min_snr": "ratio",
}
LARGEST_SAFETY_FACTOR = 100.0
_ZERO_ALLOWED = {"clamp_clearance", "load_clearance", "tip_margin", "pocket_margin", "gauge_gap"}


def _parse_limits(raw) -> Limits:
    raw = _mapping(raw, "limits", tuple(_LIMIT_KINDS) + ("fatigue", "width", "height"))
    values = {}
    for key, kind in _LIMIT_KINDS.items():
        if raw.get(key) is not None:
            values[key] = units.parse_positive(raw[key], kind, f"limits.{key}", allow_zero=key in _ZERO_ALLOWED)
    for key in ("width", "height"):
        if raw.get(key) is not None:
            values[key] = units.parse_range(raw[key], "length", f"limits.{key}")
    if "fatigue" in raw:
        values["fatigue"] = boolean(raw["fatigue"], "limits.fatigue")
    if not 1 <= values.get("safety_factor", 2.0) <= LARGEST_SAFETY_FACTOR:
        # (a factor of 1e9 left every design's stress limit broken, and the diagnosis reasoned from
        # a least-violating design that was no sensor)
        raise SpecError(f"limits.safety_factor: {raw['safety_factor']!r} must be from 1 to {LARGEST_SAFETY_FACTOR:g}")
    if not values.get("max_pocket_fraction", 0.3) < 0.5:
        raise SpecError(f"limits.max_pocket_fraction: {raw['max_pocket_fraction']!r} must be below 0.5 "
                        "(pockets on both faces would meet)")
    return Limits(**values)


def _parse_targets(raw, x_max: float) -> Targets:
    raw = _mapping(raw, "targets", ("force_error", "position_error"))
    values = {}
    if raw.get("force_error") is not None:
        values["force_error"] = units.parse_positive(raw["force_error"], "ratio", "targets.force_error")
    if raw.get("position_error") is not None:
        value = raw["position_error"]
        if isinstance(value, str) and "%" in value:
            values["position_error"] = units.parse_positive(value, "ratio", "targets.position_error") * x_max
        else:
            values["position_error"] = units.parse_positive(value, "length", "targets.position_error")
    return Targets(**values)


def _parse_search(raw) -> Search:
    raw = _mapping(raw, "search", ("materials", "sections", "feature", "stock"))
    names = tuple(catalogue.materials())
    chosen = raw.get("materials", "all")
    if chosen == "all":
        chosen = names
    elif isinstance(chosen, str):
        chosen = (chosen,)
    if not isinstance(chosen, (list, tuple)) or not chosen:
        raise SpecError(f"search.materials: {chosen!r} must be 'all' or a list of catalogue names")
    for i, m in enumerate(chosen):
        if m == "all":
            raise SpecError(f"search.materials[{i}]: 'all' stands for the whole list (search.materials: all), not "
                            f"for a name in one; a list names materials of the catalogue, {describe_allowed(names)}")
        _catalogue_name(m, f"search.materials[{i}]", catalogue.material)
    sections = raw.get("sections", list(SECTION_KINDS))
    if isinstance(sections, str):
        sections = [sections]
    if not isinstance(sections, (list, tuple)) or not sections:
        raise SpecError(f"search.sections: {brief(sections)} must be a list from {describe_allowed(SECTION_KINDS)}")
    for i, s in enumerate(sections):
        _choice(s, SECTION_KINDS, f"search.sections[{i}]")
    feature = _choice(raw.get("feature", "pocket"), FEATURE_KINDS, "search.feature")
    stock = _choice(raw.get("stock", "none"), STOCK_CHOICES, "search.stock")
    if stock != "none":
        catalogue.stock()  # a bad stock.yaml is refused before any work
    return Search(materials=tuple(dict.fromkeys(chosen)), sections=tuple(dict.fromkeys(sections)),
                  feature=feature, stock=stock)


def parse_design_block(raw, spec: "Spec", material: str | None = None) -> FixedDesign:
    """A ``design:`` block checked as a spec.yaml's is, under ``spec``'s limits and gauge; its
    material may also be ``material`` (a design.json's own, whose properties it carries, where
    the catalogue read may not list it)."""
    return _parse_design(raw, spec.limits, spec.gauge, material)


def _parse_design(raw, limits: Limits, gauge: Gauge, known: str | None = None) -> FixedDesign:
    raw = _mapping(raw, "design", ("material", "section", "stations", "feature", "length"))
    material = _required(raw, "material", "design")
    if not (known is not None and isinstance(material, str) and material == known):
        _catalogue_name(material, "design.material", catalogue.material)
    section = _parse_section(_required(raw, "section", "design"))
    stations = _required(raw, "stations", "design")
    if not isinstance(stations, (list, tuple)) or len(stations) < 2:
        raise SpecError(f"design.stations: {brief(stations)} must be a list of at least 2 positions")
    stations = tuple(units.parse_positive(s, "length", f"design.stations[{i}]") for i, s in enumerate(stations))
    if any(b <= a for a, b in zip(stations, stations[1:])):
        raise SpecError(f"design.stations: {[round(s * 1e3, 3) for s in stations]} mm must increase "
                        "from the clamp outwards")
    feature = _parse_feature(raw.get("feature", {"kind": "pocket", "depth": limits.min_pocket_depth}),
                             limits, gauge, section)
    length = units.parse_positive(raw["length"], "length", "design.length") if raw.get("length") is not None else None
    return FixedDesign(material=material, section=section, stations=stations, feature=feature, length=length)


def _parse_section(raw) -> Section:
    if not isinstance(raw, dict):
        raise SpecError(f"design.section: {brief(raw)} must be a mapping such as "
                        "{kind: rectangle, width: 12 mm, height: 6 mm}")
    kind = _choice(_required(raw, "kind", "design.section"), SECTION_KINDS, "design.section.kind")
    keys = {"rectangle": ("width", "height"), "round": ("diameter",), "tube": ("diameter", "wall")}[kind]
    raw = _mapping(raw, "design.section", ("kind",) + keys)
    dims = {k: units.parse_positive(_required(raw, k, "design.section"), "length", f"design.section.{k}")
            for k in keys}
    if kind == "tube" and not dims["wall"] < dims["diameter"] / 2:
        raise SpecError(f"design.section.wall: {dims['wall'] * 1e3:g} mm must be less than half the "
                        f"diameter ({dims['diameter'] * 1e3 / 2:g} mm)")
    return Section(kind=kind, **dims)


def _parse_feature(raw, limits: Limits, gauge: Gauge, section: Section) -> Feature:
    if not isinstance(raw, dict):
        raise SpecError(f"design.feature: {brief(raw)} must be a mapping such as {{kind: pocket, depth: 1 mm}}")
    kind = _choice(_required(raw, "kind", "design.feature"), FEATURE_KINDS, "design.feature.kind")
    keys = {"pocket": ("depth", "length", "width"), "hole": ("diameter",), "none": ()}[kind]
    raw = _mapping(raw, "design.feature", ("kind",) + keys)
    if kind == "none":
        return Feature("none", length=gauge.length, width=gauge.width)
    if kind == "hole":
        if section.kind != "rectangle":
            raise SpecError(f"design.feature.kind: 'hole' needs a rectangle section, not {section.kind!r}")
        d = units.parse_positive(_required(raw, "diameter", "design.feature"), "length", "design.feature.diameter")
        if not d < section.height:
            raise SpecError(f"design.feature.diameter: {d * 1e3:g} mm must be less than the section height "
                            f"{section.height * 1e3:g} mm")
        return Feature("hole", diameter=d)
    depth = units.parse_positive(_required(raw, "depth", "design.feature"), "length", "design.feature.depth")
    margin = limits.pocket_margin
    longest = units.RANGES["length"][1]
    if raw.get("length") is None and not gauge.length + 2 * margin <= longest:  # the default pocket, by the margin
        raise SpecError(f"limits.pocket_margin: {margin:g} m makes the pocket longer than the {longest:g} m "
                        f"fpdesign handles; must be at most {(longest - gauge.length) / 2:g} m")
    length = units.parse_positive(raw.get("length", gauge.length + 2 * margin), "length", "design.feature.length")
    width = units.parse_positive(raw.get("width", gauge.width + 2 * margin), "length", "design.feature.width")
    if not depth < section.depth / 2:
        raise SpecError(f"design.feature.depth: {depth * 1e3:g} mm must be less than half the section "
                        f"height ({section.depth * 1e3 / 2:g} mm)")
    if section.kind == "tube" and not depth < section.wall:
        raise SpecError(f"design.feature.depth: {depth * 1e3:g} mm must be less than the tube wall "
                        f"({section.wall * 1e3:g} mm)")
    return Feature("pocket", depth=depth, length=length, width=width)
