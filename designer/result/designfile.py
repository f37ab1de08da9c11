"""Reading design.json back: the one reader and validator of the record, with clear messages.

``read_design(path)`` (or ``parse_design(record)`` for a record in memory) returns a
``DesignRecord``: the validated dictionary (SI) with the ``Spec`` and ``Design`` it describes,
so that every consumer (CAD, plots, calibration, the 3-D check, the elastica, simulate) judges a
design from the file alone without checking it again. ``load_design`` returns the validated
dictionary only; ``validate`` and ``rebuild`` are the two halves.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from designer import model
from designer.spec.units import RANGES
from designer.result.record import VERSION
from designer.errors import DesignFileError, SpecError, brief, describe_allowed, metres, read_text
from designer.spec.keys import plain_name

SECTION_KEYS = {"rectangle": ("width", "height"), "round": ("diameter",), "tube": ("diameter", "wall")}
FEATURE_KEYS = {"pocket": ("depth", "length", "width"), "hole": ("diameter",), "none": ()}


def read_json(path: str | Path, error: type = DesignFileError, what: str = ""):
    """The JSON in ``path``; a missing, unreadable or malformed file raises ``error`` (an InputError)."""
    where = f"{what} {path}".strip()
    # (a byte-order mark, which some Windows editors write, is read past as in spec.yaml and CSV)
    text = read_text(path, error, where, encoding="utf-8-sig")
    if len(text) > MAX_JSON_CHARS:
        raise error(f"{where}: the file is {len(text) / 1e6:.0f} MB; fpdesign's JSON files are at most "
                    f"{MAX_JSON_CHARS / 1e6:.0f} MB")
    try:
        data = json.loads(text, parse_constant=_NotANumber)
    except json.JSONDecodeError as exc:
        raise error(f"{where}: not valid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}") from exc
    except RecursionError as exc:
        raise error(f"{where}: nested too deeply to be an fpdesign file") from exc
    found = _first_constant(data)
    if found is not None:  # NaN or Infinity, which JSON does not have
        key, value = found
        raise error(f"{where}: {key or 'the file'}: {value.name} is not a JSON number; give a finite number")
    return data


MAX_JSON_CHARS = 50_000_000   # design.json with its fronts is about 100 kB


class _NotANumber:
    """NaN, Infinity or -Infinity where a JSON file has one (Python's json reads them)."""

    def __init__(self, name: str):
        self.name = name


def _first_constant(data, key: str = ""):
    """``(key path, _NotANumber)`` of the first NaN or Infinity in ``data``, None if there is none."""
    stack = [(key, data)]
    while stack:
        key, value = stack.pop()
        if isinstance(value, _NotANumber):
            return key, value
        if isinstance(value, dict):
            stack.extend((f"{key}.{k}" if key else str(k), v) for k, v in reversed(value.items()))
        elif isinstance(value, list):
            stack.extend((f"{key}[{i}]", v) for i, v in reversed(list(enumerate(value))))
    return None


@dataclass(frozen=True)
class DesignRecord:
    """A design.json record, read and checked once (docs/spec.md §4)."""

    data: dict          # the record as read (SI)
    spec: object        # spec.reader.Spec
    design: object      # result.evaluation.Design
    source: str = "design.json"

    @property
    def status(self) -> str:
        return self.data.get("status", "")

    @property
    def predicted(self) -> dict:
        return self.data.get("predicted") or {}


def parse_design(record, source: str = "design.json") -> DesignRecord:
    """Validate a record in memory and rebuild what it describes (a DesignRecord passes through)."""
    if isinstance(record, DesignRecord):
        return record
    validate(record, source=source)
    spec, design = rebuild(record)
    return DesignRecord(record, spec, design, source)


def read_design(path: str | Path) -> DesignRecord:
    """design.json at ``path``, read, validated and rebuilt."""
    return parse_design(read_json(path), source=str(path))


def load_design(path: str | Path) -> dict:
    """design.json at ``path`` as its dictionary, checked as ``read_design`` checks it (its spec
    included): every command that reads a design.json refuses the same files."""
    return read_design(path).data


def _get(obj, key: str, where: str):
    if not isinstance(obj, dict):
        raise DesignFileError(f"{where}: {brief(obj)} must be an object")
    if key not in obj or obj[key] is None:
        raise DesignFileError(f"{where}.{key}: missing; it is required" if where else f"{key}: missing; it is required")
    return obj[key]


def _positive(obj, key: str, where: str, largest: float = math.inf) -> float:
    value = _get(obj, key, where)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DesignFileError(f"{where}.{key}: {value!r} must be a number (SI units)")
    if value <= 0:
        raise DesignFileError(f"{where}.{key}: {value!r} must be positive")
    if value > largest:
        raise DesignFileError(f"{where}.{key}: {value!r} must be at most {largest:g}")
    return float(value)


# Material properties a design.json may carry beyond E, yield and density, with their bounds (SI).
OPTIONAL_PROPERTIES = {"poisson": (-0.99, 0.4999), "ultimate": RANGES["pressure"], "fatigue": RANGES["pressure"],
                       "fatigue_cycles": (1.0, 1e12), "notch_length": (0.0, 0.1), "modulus_tc": (-0.01, 0.01),
                       "expansion": (0.0, 1e-3), "creep": (0.0, 0.1)}
# A section or feature size beyond this is not a sensor beam (and overflows the model).
LARGEST_SIZE = RANGES["length"][1]   # m


def validate(record, source: str = "design.json") -> None:
    """Raise DesignFileError naming the first key that is missing or impossible."""
    if not isinstance(record, dict):
        raise DesignFileError(f"{source}: must be a JSON object with keys 'spec' and 'design'")
    version = record.get("version", VERSION)
    if version != VERSION or isinstance(version, bool):
        raise DesignFileError(f"version: {version!r} is not a design.json this fpdesign reads; it reads version "
                              f"{VERSION}")
    if not isinstance(record.get("predicted", {}), dict):
        raise DesignFileError(f"predicted: {brief(record['predicted'])} must be an object of the predicted figures")
    spec = _get(record, "spec", "")
    if not isinstance(spec, dict):
        raise DesignFileError(f"spec: {brief(spec)} must be an object (the normalised spec of SPEC.md)")
    design = _get(record, "design", "")
    plain_name(_get(design, "material", "design"), "design.material", DesignFileError)
    props = _get(design, "material_properties", "design")
    for key in ("E", "yield", "density"):
        _positive(props, key, "design.material_properties")
    for key, (low, high) in OPTIONAL_PROPERTIES.items():
        if props.get(key) is not None:
            value = props[key]
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not low <= value <= high:
                raise DesignFileError(f"design.material_properties.{key}: {value!r} must be a number from "
                                      f"{low:g} to {high:g}")
    section = _get(design, "section", "design")
    kind = _get(section, "kind", "design.section")
    if not isinstance(kind, str) or kind not in SECTION_KEYS:
        raise DesignFileError(f"design.section.kind: {kind!r} is not allowed; must be {describe_allowed(SECTION_KEYS)}")
    dims = {k: _positive(section, k, "design.section", LARGEST_SIZE) for k in SECTION_KEYS[kind]}
    feature = _get(design, "feature", "design")
    fkind = _get(feature, "kind", "design.feature")
    if not isinstance(fkind, str) or fkind not in FEATURE_KEYS:
        raise DesignFileError(f"design.feature.kind: {fkind!r} is not allowed; must be {describe_allowed(FEATURE_KEYS)}")
    fdims = {k: _positive(feature, k, "design.feature", LARGEST_SIZE) for k in FEATURE_KEYS[fkind]}
    length = _positive(design, "length", "design", LARGEST_SIZE)
    stations = _get(design, "stations", "design")
    if not isinstance(stations, list) or len(stations) < 2:
        raise DesignFileError(f"design.stations: {brief(stations)} must be a list of at least 2 positions")
    for i, s in enumerate(stations):
        if isinstance(s, bool) or not isinstance(s, (int, float)) or not math.isfinite(s):
            raise DesignFileError(f"design.stations[{i}]: {s!r} must be a number (m)")
    geometry = model.Geometry(section=kind, feature=fkind, stations=tuple(float(s) for s in stations), length=length,
                              width=dims.get("width"), height=dims.get("height"), diameter=dims.get("diameter"),
                              wall=dims.get("wall"), depth=fdims.get("depth", 0.0),
                              hole=fdims.get("diameter", 0.0) if fkind == "hole" else 0.0,
                              pocket_width=fdims.get("width", 0.0))
    problem = model.unbuildable(geometry)
    if problem is not None:
        key, reason = problem
        raise DesignFileError(f"design.{key}: {reason}")
    axes = design.get("axes", 1)
    if axes not in (1, 2):
        raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
    _repeats_the_spec(design, spec)
    adjustment = _adjustment(design)
    if adjustment is not None and len(adjustment.gauge_strain) != len(stations):
        raise DesignFileError(f"design.adjustment.gauge_strain: {len(adjustment.gauge_strain)} factors for "
                              f"{len(stations)} stations; it needs one per station")


def _repeats_the_spec(design: dict, spec: dict) -> None:
    """The design block's ``bridge``, ``axes`` and ``gauge`` repeat the spec's, and commands read one
    copy or the other (the 3-D check the design's gauge, the model the spec's): a value the spec
    does not hold (a hand edit of one copy) is refused, naming it, rather than read by some
    commands and passed over by others."""
    for key in ("bridge", "axes"):
        if design.get(key) is not None and key in spec and design[key] != spec[key]:
            raise DesignFileError(f"design.{key}: {design[key]!r} differs from spec.{key} ({spec[key]!r}); the "
                                  f"design block repeats the spec's {key}: give both the same")
    gauge, given = design.get("gauge"), spec.get("gauge")
    if gauge is None or given is None:
        return
    if not isinstance(gauge, dict):
        raise DesignFileError(f"design.gauge: {brief(gauge)} must be an object (the spec's gauge, repeated)")
    for key, value in gauge.items():
        theirs = given.get(key) if isinstance(given, dict) else (given if key == "name" else value)
        if value != theirs:
            raise DesignFileError(f"design.gauge.{key}: {value!r} differs from spec.gauge.{key} ({theirs!r}); the "
                                  "design block repeats the spec's gauge: give both the same")


def _adjustment(design: dict):
    """The design's 3-D/model factors (``design.adjustment``), or None when it has none."""
    data = design.get("adjustment")
    if data is None:
        return None
    try:
        return model.Adjustment.from_dict(data)
    except ValueError as exc:
        raise DesignFileError(f"design.{exc}") from exc


def rebuild(record: dict):
    """``(Spec, Design)`` from a validated design.json record."""
    from designer.spec.catalogue import Material
    from designer.result.evaluation import Design, geometry_for
    from designer.spec.reader import Feature, Section, parse_design_block, parse_spec

    raw_spec = dict(record["spec"])
    if isinstance(raw_spec.get("electronics"), dict):  # anything else: parse_spec says what is wrong
        raw_spec["electronics"] = {k: v for k, v in raw_spec["electronics"].items()
                                   if k != "noise_output" and v is not None}
    raw_design = raw_spec.pop("design", None)   # (a fixed design's block: the record's design is the one judged)
    d = record["design"]
    try:
        spec = parse_spec(raw_spec)
        if raw_design is not None:
            parse_design_block(raw_design, spec, material=d["material"])
    except SpecError as exc:
        raise DesignFileError(f"spec.{str(exc).removeprefix('spec.')}") from exc   # (a top-level key: spec.x)
    props = d["material_properties"]
    material = Material(name=d["material"], description="from design.json", E=props["E"],
                        poisson=props.get("poisson", 0.3), yield_strength=props["yield"],
                        ultimate=props.get("ultimate", props["yield"]), fatigue=props.get("fatigue", props["yield"]),
                        fatigue_cycles=props.get("fatigue_cycles", 1e7), density=props["density"], source="design.json",
                        notch_length=props.get("notch_length", 0.0), modulus_tc=props.get("modulus_tc"),
                        expansion=props.get("expansion"), creep=props.get("creep"))
    section = Section(kind=d["section"]["kind"], **{k: d["section"][k] for k in SECTION_KEYS[d["section"]["kind"]]})
    f = d["feature"]
    feature = Feature(kind=f["kind"], **{k: f[k] for k in FEATURE_KEYS[f["kind"]]})
    if d["length"] < spec.load.position_max:   # as a spec's design block (spec.reader)
        raise DesignFileError(f"design.length: {metres(d['length'])} is shorter than the "
                              f"largest load position spec.load.position[1] = {spec.load.position_max * 1e3:g} mm")
    geometry = geometry_for(spec, section, feature, d["stations"], d["length"], axes=d.get("axes", 1))
    return spec, Design(material, geometry, _adjustment(d))
