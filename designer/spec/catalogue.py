"""The material and strain-gauge catalogue, shipped as YAML in ``designer.materials``."""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path

import yaml

from designer.spec import units
from designer.errors import CatalogueError, FpdError, SpecError, describe_allowed


@dataclass(frozen=True)
class Material:
    name: str
    description: str
    E: float                 # Young's modulus, Pa
    poisson: float
    yield_strength: float    # Pa
    ultimate: float          # Pa
    fatigue: float           # fatigue strength at fatigue_cycles, Pa
    fatigue_cycles: float
    density: float           # kg/m^3
    source: str
    notch_length: float = 0.0  # Peterson's characteristic length a, m; 0: fully notch sensitive (q = 1)

    def allowable_stress(self, safety_factor: float, use_fatigue: bool) -> float:
        """``min(yield, fatigue if used) / safety_factor`` (MODEL.md section 4)."""
        strength = min(self.yield_strength, self.fatigue) if use_fatigue else self.yield_strength
        return strength / safety_factor

    def properties(self) -> dict:
        return {"E": self.E, "poisson": self.poisson, "yield": self.yield_strength,
                "ultimate": self.ultimate, "fatigue": self.fatigue, "density": self.density,
                "notch_length": self.notch_length}


@dataclass(frozen=True)
class Gauge:
    name: str
    factor: float            # gauge factor G
    resistance: float        # ohm
    length: float            # backing length along the beam, m
    width: float             # backing width, m
    grid_length: float       # active grid, m
    grid_width: float
    max_strain: float        # fatigue-rated strain
    description: str = ""
    source: str = ""

    def as_dict(self) -> dict:
        return {"name": self.name, "factor": self.factor, "resistance": self.resistance,
                "length": self.length, "width": self.width, "grid_length": self.grid_length,
                "grid_width": self.grid_width, "max_strain": self.max_strain}


_MATERIAL_FIELDS = {  # yaml key -> (dataclass field, kind of quantity)
    "E": ("E", "pressure"), "poisson": ("poisson", "ratio"), "yield": ("yield_strength", "pressure"),
    "ultimate": ("ultimate", "pressure"), "fatigue": ("fatigue", "pressure"),
    "fatigue_cycles": ("fatigue_cycles", "ratio"), "density": ("density", "density"),
    "notch_length": ("notch_length", "length"),
}
GAUGE_FIELDS = {
    "factor": "ratio", "resistance": "resistance", "length": "length", "width": "length",
    "grid_length": "length", "grid_width": "length", "max_strain": "strain",
}


def data_folder() -> Path:
    """The folder of the catalogue files (package data of ``designer.materials``)."""
    try:
        return Path(str(resources.files("designer.materials")))
    except ModuleNotFoundError:  # running from a source checkout that is not installed
        return Path(__file__).resolve().parents[2] / "materials"


def _read(name: str) -> list[dict]:
    path = data_folder() / name
    try:
        entries = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise FpdError(f"the catalogue file {path} cannot be read: {exc}") from exc
    return entries


@functools.lru_cache(maxsize=1)
def materials() -> dict[str, Material]:
    out = {}
    for entry in _read("materials.yaml"):
        values = {field: units.parse(entry[key], kind, f"materials.yaml {entry['name']}.{key}")
                  for key, (field, kind) in _MATERIAL_FIELDS.items()}
        out[entry["name"]] = Material(name=entry["name"], description=entry.get("description", ""),
                                      source=entry.get("source", ""), **values)
    return out


@functools.lru_cache(maxsize=1)
def gauges() -> dict[str, Gauge]:
    out = {}
    for entry in _read("gauges.yaml"):
        values = {key: units.parse(entry[key], kind, f"gauges.yaml {entry['name']}.{key}")
                  for key, kind in GAUGE_FIELDS.items()}
        out[entry["name"]] = Gauge(name=entry["name"], description=entry.get("description", ""),
                                   source=entry.get("source", ""), **values)
    return out


@functools.lru_cache(maxsize=1)
def stock():
    """The stock catalogue (``materials/stock.yaml``, ``spec.stock``), read and checked once."""
    from designer.spec import stock as stock_file, strict_yaml

    path = data_folder() / stock_file.FILE
    try:
        raw = strict_yaml.load(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError, strict_yaml.StrictYamlError) as exc:
        raise CatalogueError(f"{stock_file.FILE}: cannot be read ({path}): {exc}") from exc
    return stock_file.parse(raw, tuple(materials()))


def material(name: str, key: str = "material") -> Material:
    table = materials()
    if name not in table:
        raise SpecError(f"{key}: {name!r} is not in the catalogue; must be {describe_allowed(table)}")
    return table[name]


def gauge(name: str, key: str = "gauge.name") -> Gauge:
    table = gauges()
    if name not in table:
        raise SpecError(f"{key}: {name!r} is not in the catalogue; must be {describe_allowed(table)}")
    return table[name]


def customised(base: Gauge, **fields) -> Gauge:
    """``base`` with ``fields`` replaced; a gauge that differs from its catalogue entry says so in
    its name (reports and the drawing's title block), ``"BF120-3AA (modified max_strain)"``."""
    changed = [k for k, v in fields.items() if getattr(base, k) != v]
    name = f"{base.name} (modified {', '.join(changed)})" if changed else base.name
    return replace(base, name=name, **fields)


def modified_from(name: str) -> str | None:
    """The catalogue gauge that ``name`` says it modifies (``customised``), else None."""
    match = re.fullmatch(r"(.+) \(modified [a-z_, ]+\)", name)
    return match.group(1) if match and match.group(1) in gauges() else None
