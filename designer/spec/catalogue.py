"""The material, strain-gauge and stock catalogue, shipped as YAML in ``designer.materials``,
and the users' own catalogues beside it.

A user catalogue (``catalogue:`` in a spec, ``--catalogue FILE`` on the command line) is a
mapping with any of ``materials`` and ``gauges`` (lists of entries written as in the shipped
files) and ``stock`` (``families`` and ``tables`` as in stock.yaml). Its entries join the
shipped ones under names of their own; ``use`` puts the catalogues a spec names in force for the
process (a spec that names none puts the shipped catalogue alone back). Every problem with a
file is a CatalogueError naming the file, the entry and the key.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path

import yaml

from designer.spec import stock as stock_file, units
from designer.errors import CatalogueError, FpdError, SpecError, brief, describe_allowed
from designer.spec.keys import plain_name


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
    modulus_tc: float | None = None  # (1/E) dE/dT, 1/K; None: not known (the error budget needs it)
    expansion: float | None = None   # thermal expansion coefficient, 1/K
    creep: float | None = None       # the output's creep under constant load over 30 min, fraction

    def allowable_stress(self, safety_factor: float, use_fatigue: bool) -> float:
        """``min(yield, fatigue if used) / safety_factor`` (MODEL.md section 4)."""
        strength = min(self.yield_strength, self.fatigue) if use_fatigue else self.yield_strength
        return strength / safety_factor

    def properties(self) -> dict:
        return {"E": self.E, "poisson": self.poisson, "yield": self.yield_strength,
                "ultimate": self.ultimate, "fatigue": self.fatigue, "density": self.density,
                "notch_length": self.notch_length, "modulus_tc": self.modulus_tc, "expansion": self.expansion,
                "creep": self.creep}

    def thermal_missing(self) -> list[str]:
        """The figures the error budget needs that this material does not give."""
        return [k for k in THERMAL_MATERIAL_FIELDS if getattr(self, k) is None]


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
    # the error budget's figures (None: not known): the gauge factor's temperature coefficient,
    # 1/K; the expansion coefficient its self-temperature compensation matches, 1/K; the
    # residual thermal output on a matched material and the scatter between gauges of a lot,
    # each a bound in strain per K
    factor_tc: float | None = None
    compensated_for: float | None = None
    thermal_output: float | None = None
    thermal_match: float | None = None

    def as_dict(self) -> dict:
        out = {"name": self.name, "factor": self.factor, "resistance": self.resistance,
               "length": self.length, "width": self.width, "grid_length": self.grid_length,
               "grid_width": self.grid_width, "max_strain": self.max_strain}
        return out | {k: getattr(self, k) for k in GAUGE_THERMAL if getattr(self, k) is not None}

    def thermal_missing(self) -> list[str]:
        """The figures the error budget needs that this gauge does not give."""
        return [k for k in GAUGE_THERMAL if getattr(self, k) is None]


_MATERIAL_FIELDS = {  # yaml key -> (dataclass field, kind of quantity)
    "E": ("E", "pressure"), "poisson": ("poisson", "ratio"), "yield": ("yield_strength", "pressure"),
    "ultimate": ("ultimate", "pressure"), "fatigue": ("fatigue", "pressure"),
    "fatigue_cycles": ("fatigue_cycles", "ratio"), "density": ("density", "density"),
    "notch_length": ("notch_length", "length"), "modulus_tc": ("modulus_tc", "drift"),
    "expansion": ("expansion", "drift"), "creep": ("creep", "ratio"),
}
THERMAL_MATERIAL_FIELDS = ("modulus_tc", "expansion", "creep")
GAUGE_FIELDS = {
    "factor": "ratio", "resistance": "resistance", "length": "length", "width": "length",
    "grid_length": "length", "grid_width": "length", "max_strain": "strain",
}
# The figures a material or gauge of any catalogue may have (SI): wide of every engineering solid
# and foil or semiconductor gauge (a plastic's 0.1 GPa to a carbide's 700, osmium's 22.6 t/m^3,
# a 0.2 mm grid on a 0.5 m carrier, a post-yield gauge's 20 %), so that a slip of a unit or a
# digit is refused rather than designed with (a gauge factor of 1e10 read as a flawless sensor).
PLAUSIBLE = {
    "E": (1e8, 1.5e12, "Pa"), "yield": (1e5, 1e10, "Pa"), "ultimate": (1e5, 1e10, "Pa"),
    "fatigue": (1e5, 1e10, "Pa"), "fatigue_cycles": (1e3, 1e12, ""), "density": (100.0, 25e3, "kg/m^3"),
    "notch_length": (0.0, 0.01, "m"),
    "factor": (0.5, 500.0, ""), "resistance": (10.0, 1e6, "ohm"), "length": (1e-4, 0.5, "m"),
    "width": (1e-4, 0.5, "m"), "grid_length": (5e-5, 0.5, "m"), "grid_width": (5e-5, 0.5, "m"),
    "max_strain": (1e-5, 0.2, ""),
}


def plausible(values: dict, key: str, error: type) -> dict:
    """``values`` (yaml key -> SI figure); ``error`` naming ``key.k`` for a figure outside PLAUSIBLE."""
    for k, v in values.items():
        if k in PLAUSIBLE and v is not None:
            lo, hi, unit = PLAUSIBLE[k]
            if not lo <= v <= hi:
                of = "gauge" if k in GAUGE_FIELDS else "material"
                unit = f" {unit}" if unit else ""
                raise error(f"{key}.{k}: {v:g}{unit} is not a figure a {of} has; must lie between {lo:g} and "
                            f"{hi:g}{unit}")
    return values


# The optional thermal figures of a gauge (per K) and the sign each may have.
GAUGE_THERMAL = {"factor_tc": "any", "compensated_for": "positive", "thermal_output": "zero or positive",
                 "thermal_match": "zero or positive"}


def gauge_thermal(entry: dict, key: str, in_spec: bool = False) -> dict:
    """The thermal figures an entry gives, in 1/K (``"1.8 ue/K"``, ``"11 ppm/K"``); a bad one is a
    CatalogueError, or in a spec (``in_spec``) a SpecError."""
    read = signed if in_spec else quantity
    return {k: read(entry[k], "drift", f"{key}.{k}", sign) for k, sign in GAUGE_THERMAL.items()
            if entry.get(k) is not None}


def data_folder() -> Path:
    """The folder of the catalogue files (package data of ``designer.materials``)."""
    try:
        return Path(str(resources.files("designer.materials")))
    except ModuleNotFoundError:  # running from a source checkout that is not installed
        return Path(__file__).resolve().parents[2] / "materials"


USER_KEYS = ("file", "materials", "gauges", "stock", "end_mills")
MATERIAL_KEYS = ("name", "description", "source", *_MATERIAL_FIELDS)
# 0: fully notch sensitive (K_f = K_t); the thermal figures: None, not known (only the error budget needs them)
OPTIONAL_MATERIAL_FIELDS = {"notch_length": 0.0, "modulus_tc": None, "expansion": None, "creep": None}
MATERIAL_SIGNS = {"poisson": "any", "notch_length": "zero or positive", "modulus_tc": "any",
                  "creep": "zero or positive"}   # the others: positive
GAUGE_KEYS = ("name", "description", "source", *GAUGE_FIELDS, *GAUGE_THERMAL)

# The user catalogues in force: ``(file, content)`` pairs (``use``).
_user: tuple = ()


@functools.lru_cache(maxsize=None)
def read_shipped(name: str) -> list[dict]:
    """A shipped catalogue file's entries (materials, gauges, front-ends), read once (never
    changed by their readers)."""
    from designer.spec import strict_yaml

    path = data_folder() / name
    try:
        entries = strict_yaml.load_shipped(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError, strict_yaml.StrictYamlError) as exc:
        raise FpdError(f"the catalogue file {path} cannot be read: {exc}") from exc
    return entries


def use(catalogues) -> None:
    """Put the user catalogues ``catalogues`` (``(file, content)`` pairs, as ``read_user`` gives
    them) in force, beside the shipped one; ``()`` leaves the shipped catalogue alone. Each is
    checked at once: CatalogueError names the file, the entry and the key."""
    global _user
    catalogues = tuple((str(f), c) for f, c in catalogues)
    if catalogues == _user:
        return
    previous, _user = _user, catalogues
    for table in (materials, gauges, stock, end_mills):
        table.cache_clear()
    try:
        materials(), gauges(), end_mills()
        if any(c.get("stock") is not None for _, c in catalogues):
            stock()
    except BaseException:
        use(previous)
        raise


def user_file(name: str, folder: Path | None) -> Path:
    """The path of the catalogue file a spec names: ``name`` relative to the spec's ``folder``
    (None: the working folder), ``~`` expanded."""
    path = Path(name).expanduser()
    return path if path.is_absolute() or folder is None else folder / path


def read_user(path: str | Path, shown: str | None = None) -> tuple[str, dict]:
    """A user catalogue file as ``(file, content)``: ``file`` is how messages name it (``shown``,
    else the path as given). CatalogueError for a file that cannot be read or is not a mapping
    of USER_KEYS; its entries are checked by ``use``."""
    from designer.errors import read_text
    from designer.spec import strict_yaml

    shown = shown or str(path)
    text = read_text(Path(path), CatalogueError)
    raw = strict_yaml.load_as(text, shown, CatalogueError)
    return shown, user_content(raw, shown)


def user_content(raw, shown: str) -> dict:
    """A user catalogue's content checked for its shape: a mapping of materials, gauges and stock."""
    if not isinstance(raw, dict) or not raw:
        raise CatalogueError(f"{shown}: a catalogue must be a mapping with any of the keys "
                             f"{describe_allowed(USER_KEYS[1:])}")
    unknown = [k for k in raw if k not in USER_KEYS]
    if unknown:
        raise CatalogueError(f"{shown}.{unknown[0]}: unknown key; allowed keys are "
                             f"{describe_allowed(USER_KEYS[1:])}")
    for key in ("materials", "gauges"):
        if raw.get(key) is not None and (not isinstance(raw[key], list) or not raw[key]):
            raise CatalogueError(f"{shown}.{key}: must be a list of entries, each a mapping with a name")
    if all(raw.get(k) is None for k in USER_KEYS[1:]):
        raise CatalogueError(f"{shown}: the catalogue is empty; give at least {describe_allowed(USER_KEYS[1:])}")
    return {k: v for k, v in raw.items() if k != "file"}


def _entries(entries, where: str, keys, required) -> list[tuple[str, str, dict]]:
    """``(name, key prefix, entry)`` for each entry of a list, its keys checked."""
    out = []
    for i, entry in enumerate(entries):
        if not isinstance(entry, dict):
            raise CatalogueError(f"{where}[{i}]: {brief(entry)} must be a mapping with keys {describe_allowed(keys)}")
        name = plain_name(entry.get("name"), f"{where}[{i}].name", CatalogueError)
        key = f"{where}[{i}] ({name})"
        stock_file.known_keys(entry, keys, key)
        for k in required:
            stock_file.required(entry, k, key)
        out.append((name.strip(), key, entry))
    return out


def quantity(value, kind: str, key: str, sign: str = "positive") -> float:
    """A catalogue figure with its unit, in SI (``signed``); CatalogueError names the key."""
    try:
        return signed(value, kind, key, sign)
    except SpecError as exc:
        raise CatalogueError(str(exc)) from exc


def signed(value, kind: str, key: str, sign: str = "positive") -> float:
    """A figure with its unit, in SI; ``sign``: ``positive``, ``zero or positive`` (a notch length:
    0 is fully notch sensitive) or ``any`` (Poisson's ratio, whose range its caller checks)."""
    if sign == "any":
        return units.parse(value, kind, key)
    return units.parse_positive(value, kind, key, allow_zero=sign == "zero or positive")


def _text(entry: dict, key: str, where: str, required: bool) -> str:
    value = entry.get(key, "")
    if not isinstance(value, str) or (required and not value.strip()):
        raise CatalogueError(f"{where}.{key}: {value!r} must be " + ("a text saying where the figures come from"
                                                                     if key == "source" else "text"))
    return value


def _materials_from(entries, where: str, user: bool) -> list[Material]:
    required = [k for k in MATERIAL_KEYS if k not in ("description", *OPTIONAL_MATERIAL_FIELDS)]
    required = required if user else [k for k in required if k != "source"]
    out = []
    for name, key, entry in _entries(entries, f"{where} materials" if user else where, MATERIAL_KEYS, required):
        values = {field: (quantity(entry[k], kind, f"{key}.{k}", MATERIAL_SIGNS.get(k, "positive"))
                          if entry.get(k) is not None else OPTIONAL_MATERIAL_FIELDS[k])
                  for k, (field, kind) in _MATERIAL_FIELDS.items()}
        plausible({k: values[field] for k, (field, _) in _MATERIAL_FIELDS.items()}, key, CatalogueError)
        if user and name == "all":
            raise CatalogueError(f"{key}.name: 'all' is search.materials' word for every material; give the "
                                 "material a name of its own")
        if not 0 <= values["poisson"] < 0.5:
            raise CatalogueError(f"{key}.poisson: {values['poisson']!r} must be at least 0 and less than 0.5")
        for k in ("yield", "fatigue"):   # no metal yields or tires above its breaking stress
            if values[_MATERIAL_FIELDS[k][0]] > values["ultimate"]:
                raise CatalogueError(f"{key}.{k}: {entry[k]!r} is above the ultimate strength ({entry['ultimate']!r}); "
                                     "must be at most it")
        out.append(Material(name=name, description=_text(entry, "description", key, False),
                            source=_text(entry, "source", key, user), **values))
    return out


def _gauges_from(entries, where: str, user: bool) -> list[Gauge]:
    required = ["name", *GAUGE_FIELDS] + (["source"] if user else [])
    out = []
    for name, key, entry in _entries(entries, f"{where} gauges" if user else where, GAUGE_KEYS, required):
        values = plausible({k: quantity(entry[k], kind, f"{key}.{k}") for k, kind in GAUGE_FIELDS.items()}, key,
                           CatalogueError)
        out.append(Gauge(name=name, description=_text(entry, "description", key, False),
                         source=_text(entry, "source", key, user), **values, **gauge_thermal(entry, key)))
        grid_on_backing(out[-1], key, CatalogueError)
    return out


def grid_on_backing(gauge: Gauge, key: str, error: type) -> Gauge:
    """``gauge``; ``error`` naming ``key``'s grid size when its grid is longer or wider than its backing."""
    for grid, backing in (("grid_length", "length"), ("grid_width", "width")):
        if getattr(gauge, grid) > getattr(gauge, backing) * (1 + 1e-12):
            raise error(f"{key}.{grid}: {getattr(gauge, grid) * 1e3:g} mm is more than the backing's {backing}, "
                        f"{getattr(gauge, backing) * 1e3:g} mm; the grid lies on the backing")
    return gauge


def _joined(shipped: list, file: str, kind: str, user_entries) -> dict:
    """The shipped entries and every user catalogue's, by name; a name given twice is refused."""
    out = {x.name: x for x in shipped}
    owner = {x.name: file for x in shipped}
    for where, entries in user_entries:
        for i, x in enumerate(entries):
            if x.name in out:
                raise CatalogueError(f"{where} {kind}[{i}] ({x.name}).name: {x.name!r} is already in "
                                     f"{owner[x.name]}; give the entry a name of its own")
            out[x.name], owner[x.name] = x, where
    return out


@functools.lru_cache(maxsize=1)
def materials() -> dict[str, Material]:
    """Every material: the shipped ones, then the user catalogues' in force."""
    shipped = _materials_from(read_shipped("materials.yaml"), "materials.yaml", False)
    return _joined(shipped, "materials.yaml", "materials",
                   [(f, _materials_from(c["materials"], f, True)) for f, c in _user if c.get("materials")])


@functools.lru_cache(maxsize=1)
def gauges() -> dict[str, Gauge]:
    """Every strain gauge: the shipped ones, then the user catalogues' in force."""
    return _joined(_gauges_from(read_shipped("gauges.yaml"), "gauges.yaml", False), "gauges.yaml", "gauges",
                   [(f, _gauges_from(c["gauges"], f, True)) for f, c in _user if c.get("gauges")])


def shipped_material_names() -> tuple:
    """The names of the materials that ship with the package (materials.yaml)."""
    return tuple(entry["name"] for entry in read_shipped("materials.yaml"))


@functools.lru_cache(maxsize=1)
def stock():
    """The stock catalogue (``materials/stock.yaml``, ``spec.stock``) with the user catalogues'
    families and tables, read and checked once."""
    from designer.spec import strict_yaml

    path = data_folder() / stock_file.FILE
    try:
        raw = strict_yaml.load_shipped(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError, strict_yaml.StrictYamlError) as exc:
        raise CatalogueError(f"{stock_file.FILE}: cannot be read ({path}): {exc}") from exc
    table = stock_file.parse(raw, shipped_material_names())
    for file, content in _user:
        if content.get("stock") is not None:
            table = stock_file.extend(table, content["stock"], tuple(materials()), f"{file} stock")
    return table


@functools.lru_cache(maxsize=1)
def end_mills():
    """The tool catalogue (``materials/tools.yaml``) with the user catalogues' ``end_mills``
    tables, read and checked once."""
    from designer.spec import strict_yaml
    from designer.spec import tools

    path = data_folder() / tools.FILE
    try:
        raw = strict_yaml.load_shipped(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError, strict_yaml.StrictYamlError) as exc:
        raise CatalogueError(f"{tools.FILE}: cannot be read ({path}): {exc}") from exc
    table = tools.parse(raw)
    for file, content in _user:
        if content.get("end_mills") is not None:
            table = tools.extend(table, content["end_mills"], f"{file} end_mills")
    return table


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
