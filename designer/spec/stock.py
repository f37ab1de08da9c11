"""The stock catalogue: bar and tube sizes a shop can buy (``materials/stock.yaml``).

A table lists one shape (round bar, square bar, flat bar, round tube) of one material family
in one system of units; its sizes are read into SI once, exactly (25.4 mm per inch). The
search (``search.stock``) takes a section's sizes from the rows of the material's family.
Every problem with the file is a ``CatalogueError`` naming the file, the entry and the key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

from designer.errors import CatalogueError, brief, describe_allowed
from designer.spec.keys import machinable, plain_name

FILE = "stock.yaml"
#: search.stock: none keeps the sizes continuous; the others choose rows from these systems.
STOCK_CHOICES = ("none", "metric", "imperial", "any")
SYSTEMS = ("metric", "imperial")
UNITS = {"mm": Fraction(1, 1000), "in": Fraction(254, 10000)}   # m per unit; the inch is 25.4 mm exactly
SYSTEM_UNITS = {"metric": "mm", "imperial": "in"}   # a table's sizes are in its system's unit
#: Each shape's sizes, in the order a row gives them.
SHAPES = {"round bar": ("diameter",), "square bar": ("side",), "flat bar": ("width", "thickness"),
          "round tube": ("diameter", "wall")}
#: The shapes that can make each section kind.
SECTION_SHAPES = {"round": ("round bar",), "tube": ("round tube",), "rectangle": ("flat bar", "square bar")}
TABLE_KEYS = ("name", "family", "shape", "system", "unit", "standard", "source", "sizes")
FAMILY_KEYS = ("description", "materials")
LARGEST_SIZE = 0.5   # m: no sensor beam is cut from stock thicker than this


@dataclass(frozen=True)
class StockItem:
    """One row of a table: a bar or tube size, in SI."""

    shape: str
    sizes: tuple            # m, in the order SHAPES names
    table: str
    system: str
    unit: str
    standard: str

    @property
    def designation(self) -> str:
        """The size as a supplier writes it: ``Ø10 mm``, ``25 × 6 mm``, ``Ø3/8 × 0.049 in``."""
        shown = [_number(float(Fraction(s) / UNITS[self.unit]), self.unit) for s in self.sizes]
        prefix = "Ø" if self.shape in ("round bar", "round tube") else ""
        return f"{prefix}{' × '.join(shown)} {self.unit}"

    @property
    def label(self) -> str:
        """``round bar Ø10 mm (EN 754-3 / EN 755-3)``."""
        return f"{self.shape} {self.designation} ({self.standard})"

    def sections(self, section: str, axes: int) -> list[dict]:
        """The NLP's section variables (m) this row gives a ``section`` family: a flat bar either
        way round, a square bar as a square rectangle (``side`` when biaxial); [] when it cannot."""
        if self.shape not in SECTION_SHAPES[section]:
            return []
        if self.shape == "round bar":
            return [{"diameter": self.sizes[0]}]
        if self.shape == "round tube":
            return [{"diameter": self.sizes[0], "wall": self.sizes[1]}]
        if self.shape == "square bar":
            side = self.sizes[0]
            return [{"side": side}] if axes == 2 else [{"width": side, "height": side}]
        if axes == 2:
            return []  # a biaxial rectangle is square
        width, thickness = self.sizes
        return [{"width": width, "height": thickness}, {"width": thickness, "height": width}]

    def as_dict(self) -> dict:
        return {"label": self.label, "shape": self.shape, "designation": self.designation,
                "sizes": list(self.sizes), "table": self.table, "system": self.system, "standard": self.standard}


def _number(value: float, unit: str) -> str:
    """A size as written in its table: millimetres as decimals, inches as fractions where exact."""
    if unit == "in":
        frac = Fraction(value).limit_denominator(64)
        if abs(float(frac) - value) < 1e-12 and frac.denominator > 1 and frac.denominator in (2, 4, 8, 16, 32, 64):
            whole, rest = divmod(frac.numerator, frac.denominator)
            return f"{whole} {rest}/{frac.denominator}" if whole else f"{rest}/{frac.denominator}"
    return f"{value:g}"


@dataclass(frozen=True)
class StockTable:
    name: str
    family: str
    shape: str
    system: str
    unit: str
    standard: str
    source: str
    items: tuple


@dataclass(frozen=True)
class StockCatalogue:
    """Every table, and which material belongs to which family."""

    families: dict          # family -> tuple of material names
    tables: tuple

    def family_of(self, material: str) -> str | None:
        return next((f for f, names in self.families.items() if material in names), None)

    def rows(self, material: str, section: str, system: str, axes: int = 1) -> list[tuple]:
        """``(StockItem, section variables)`` for every row of ``material``'s family that can make
        ``section`` in ``system`` (``metric``, ``imperial`` or ``any``)."""
        family = self.family_of(material)
        systems = SYSTEMS if system == "any" else (system,)
        return [(item, values) for t in self.tables if t.family == family and t.system in systems
                for item in t.items for values in item.sections(section, axes)]


def parse(raw, materials, where: str = FILE) -> StockCatalogue:
    """The catalogue from the loaded YAML; ``materials``: the material names of materials.yaml."""
    if not isinstance(raw, dict) or set(raw) != {"families", "tables"}:
        raise CatalogueError(f"{where}: must be a mapping with the keys 'families' and 'tables'")
    families = _families(raw["families"], materials, where)
    tables = _with_tables((), raw["tables"], families, where)
    for family in families:
        if not any(t.family == family for t in tables):
            raise CatalogueError(f"{where} families.{family}: no table lists this family; add one or remove it")
    return StockCatalogue(families, tables)


def extend(base: StockCatalogue, raw, materials, where: str) -> StockCatalogue:
    """``base`` with a user catalogue's stock (``raw``: ``tables`` and, optionally, new
    ``families``): a table may list a shipped family or a new one; a family's name, a table's
    name and a material's family are each given once. ``materials``: every material name."""
    if not isinstance(raw, dict) or "tables" not in raw or not set(raw) <= {"families", "tables"}:
        raise CatalogueError(f"{where}: must be a mapping with the key 'tables' (and 'families' for new families)")
    families = dict(base.families)
    if raw.get("families") is not None:
        taken = {m: f for f, names in base.families.items() for m in names}
        for family, names in _families(raw["families"], materials, where, taken).items():
            if family in families:
                raise CatalogueError(f"{where} families.{family}: the family is already in {FILE}; give yours a "
                                     "name of its own")
            families[family] = names
    return StockCatalogue(families, _with_tables(base.tables, raw["tables"], families, where))


def _with_tables(tables: tuple, raw, families: dict, where: str) -> tuple:
    """``tables`` and the tables of the list ``raw``, each name used once."""
    if not isinstance(raw, list) or not raw:
        raise CatalogueError(f"{where} tables: must be a list of tables")
    out, names = list(tables), {t.name for t in tables}
    for i, entry in enumerate(raw):
        table = _table(entry, i, families, where)
        if table.name in names:
            raise CatalogueError(f"{where} tables[{i}].name: {table.name!r} is used twice; each table needs a name "
                                 "of its own")
        names.add(table.name)
        out.append(table)
    return tuple(out)


def _families(raw, materials, where: str, taken: dict | None = None) -> dict:
    """Family name -> its material names. ``taken``: materials already in a family (of the shipped
    file, for a user's families), which need not be in one of these; without it every material
    must be."""
    if not isinstance(raw, dict) or not raw:
        raise CatalogueError(f"{where} families: must be a mapping of family names to their materials")
    out, owner = {}, dict(taken or {})
    for family, entry in raw.items():
        key = f"{where} families.{family}"
        if not isinstance(entry, dict):
            raise CatalogueError(f"{key}: must be a mapping with keys {describe_allowed(FAMILY_KEYS)}")
        known_keys(entry, FAMILY_KEYS, key)
        names = required(entry, "materials", key)
        if not isinstance(names, list) or not names:
            raise CatalogueError(f"{key}.materials: {brief(names)} must be a list of materials.yaml names")
        for name in names:
            if name not in materials:
                raise CatalogueError(f"{key}.materials: {name!r} is not in the catalogue; must be "
                                     f"{describe_allowed(materials)}")
            if name in owner:
                raise CatalogueError(f"{key}.materials: {name!r} is already in the family {owner[name]!r}; a "
                                     "material belongs to one family")
            owner[name] = family
        out[family] = tuple(names)
    missing = [m for m in materials if m not in owner]
    if missing and taken is None:
        raise CatalogueError(f"{where} families: the material {missing[0]!r} of materials.yaml is in no family; "
                             "add it to the family whose stock it is sold as")
    return out


def table_fields(entry, at: str, keys, text, allowed: dict, key_of) -> tuple[str, str, dict]:
    """A catalogue table's name, the prefix its messages name it by (``key_of(name)``) and its
    values: every one of ``keys`` required, ``text`` keys text, ``allowed`` keys among their
    choices. ``at``: where the table is (``stock.yaml tables[3]``), for a table without a name."""
    if not isinstance(entry, dict):
        raise CatalogueError(f"{at}: must be a mapping with keys {describe_allowed(keys)}")
    name = plain_name(entry.get("name"), f"{at}.name", CatalogueError)
    key = key_of(name)
    known_keys(entry, keys, key)
    values = {k: required(entry, k, key) for k in keys}
    for k in text:
        if not isinstance(values[k], str) or not values[k].strip():
            raise CatalogueError(f"{key}.{k}: {brief(values[k])} must be text")
    for k, choices in allowed.items():
        if values[k] not in choices:
            raise CatalogueError(f"{key}.{k}: {brief(values[k])} is not allowed; must be {describe_allowed(choices)}")
    if "system" in values and "unit" in values and values["unit"] != SYSTEM_UNITS[values["system"]]:
        raise CatalogueError(f"{key}.unit: {values['unit']!r} is not the unit of a {values['system']} table; must be "
                             f"{SYSTEM_UNITS[values['system']]}")
    return name, key, values


def _table(entry, i: int, families: dict, where: str) -> StockTable:
    allowed = {"family": tuple(families), "shape": tuple(SHAPES), "system": SYSTEMS, "unit": tuple(UNITS)}
    name, key, values = table_fields(entry, f"{where} tables[{i}]", TABLE_KEYS,
                                     ("family", "shape", "system", "unit", "standard", "source"), allowed,
                                     lambda n: f"{where} {n}")
    shape, unit = values["shape"], values["unit"]
    rows = _rows(values["sizes"], shape, f"{key}.sizes")
    seen, items = set(), []
    for where_row, sizes in rows:
        if sizes in seen:
            raise CatalogueError(f"{key}.{where_row}: the size {list(sizes)} is listed twice")
        seen.add(sizes)
        for s in sizes:
            machinable(_si(s, unit), f"{key}.{where_row}", f"{s:g} {unit}", CatalogueError)
            if _si(s, unit) > LARGEST_SIZE:
                raise CatalogueError(f"{key}.{where_row}: {s:g} {unit} is larger than a sensor beam is cut from "
                                     f"(at most {LARGEST_SIZE:g} m)")
        if shape == "round tube" and not sizes[1] < sizes[0] / 2:
            raise CatalogueError(f"{key}.{where_row}: the wall {sizes[1]:g} {unit} is not less than the radius "
                                 f"{sizes[0] / 2:g} {unit}")
        items.append(StockItem(shape, tuple(_si(s, unit) for s in sizes), name, values["system"], unit,
                               values["standard"]))
    return StockTable(name, values["family"], shape, values["system"], unit, values["standard"], values["source"],
                      tuple(items))


def _si(size: float, unit: str) -> float:
    """A size as written (decimal) in metres: the double nearest the exact product, so that
    3/8 in is 0.009525 m, not 0.375 x 0.0254 rounded twice."""
    return float(Fraction(repr(size)) * UNITS[unit])


def _rows(raw, shape: str, key: str) -> list[tuple]:
    """``(where, sizes)`` per row, in the table's unit: a list of sizes for a one-size shape, a
    mapping of the first size to a list of the second for a two-size shape."""
    out = []
    if len(SHAPES[shape]) == 1:
        if not isinstance(raw, list) or not raw:
            raise CatalogueError(f"{key}: must be a list of {SHAPES[shape][0]}s, numbers in the table's unit")
        for j, v in enumerate(raw):
            out.append((f"sizes[{j}]", (_size(v, f"{key}[{j}]"),)))
        return out
    first, second = SHAPES[shape]
    if not isinstance(raw, dict) or not raw:
        raise CatalogueError(f"{key}: must be a mapping of each {first} to a list of {second}s, numbers in the "
                             "table's unit")
    for outer, inner in raw.items():
        a = _key_size(outer, f"{key} ({first} {outer!r})")
        if not isinstance(inner, list) or not inner:
            raise CatalogueError(f"{key}.{outer}: {brief(inner)} must be a list of {second}s")
        for j, v in enumerate(inner):
            out.append((f"sizes.{outer}[{j}]", (a, _size(v, f"{key}.{outer}[{j}]"))))
    return out


def _key_size(value, key: str) -> float:
    """A size that is a mapping's key: a number, or its text (JSON's keys are text: a user
    catalogue comes back from design.json so)."""
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            pass
    return _size(value, key)


def _size(value, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CatalogueError(f"{key}: {value!r} must be a number in the table's unit (give the unit once, as "
                             "'unit: mm' or 'unit: in')")
    if not math.isfinite(value) or value <= 0:
        raise CatalogueError(f"{key}: {value!r} must be a positive size")
    return float(value)


def required(entry: dict, k: str, key: str):
    if entry.get(k) is None:
        raise CatalogueError(f"{key}.{k}: missing; it is required")
    return entry[k]


def known_keys(entry: dict, allowed, key: str) -> None:
    unknown = [k for k in entry if k not in allowed]
    if unknown:
        raise CatalogueError(f"{key}.{unknown[0]}: unknown key; allowed keys are {describe_allowed(allowed)}")
