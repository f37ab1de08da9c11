"""The tool catalogue: the corner-radius end mills a shop has (``materials/tools.yaml``).

A table lists the end mills of one system of units (metric or imperial) as a mapping of each
diameter to the corner radii ground on it, read into SI once, exactly (25.4 mm per inch). A
pocket's or flat's corner radius (``cad.corner_radius``) is by default one of them, and the CAD
cuts slots and flats with one of them. Every problem with the file is a ``CatalogueError``
naming the file, the table and the key.
"""

from __future__ import annotations

from dataclasses import dataclass

from designer.errors import CatalogueError, brief
from designer.spec.keys import machinable
from designer.spec.stock import SYSTEMS, UNITS, _key_size, _number, _si, _size, table_fields

FILE = "tools.yaml"
TABLE_KEYS = ("name", "system", "unit", "source", "tools")
LARGEST_TOOL = 0.05     # m: no end mill for a sensor's pocket is wider than this
# Two radii or diameters within this (m) are the same tool's: a size read from inches and one
# given in millimetres by a spec differ in the last bits.
SAME = 1e-9


@dataclass(frozen=True)
class EndMill:
    """One end mill: its diameter and corner radius, in SI."""

    diameter: float
    corner_radius: float
    table: str
    system: str
    unit: str

    @property
    def designation(self) -> str:
        """``Ø3 R0.2 mm``, ``Ø1/8 R0.010 in``, as a tool supplier writes it."""
        scale = float(UNITS[self.unit])
        radius = self.corner_radius / scale
        shown = f"{radius:.3f}" if self.unit == "in" else f"{radius:g}"
        return f"Ø{_number(self.diameter / scale, self.unit)} R{shown} {self.unit}"

    @property
    def label(self) -> str:
        """``end mill Ø3 R0.2 mm``."""
        return f"end mill {self.designation}"

    def as_dict(self) -> dict:
        return {"label": self.label, "diameter": self.diameter, "corner_radius": self.corner_radius,
                "table": self.table, "system": self.system}


@dataclass(frozen=True)
class ToolCatalogue:
    """Every end mill of every table, in the tables' order."""

    end_mills: tuple

    def of(self, system: str | None = None) -> tuple:
        """The end mills of ``system`` (``metric``, ``imperial``), then the others'."""
        if system not in SYSTEMS:
            return self.end_mills
        return (tuple(t for t in self.end_mills if t.system == system)
                + tuple(t for t in self.end_mills if t.system != system))

    def radii(self, system: str | None = None, diameter: float | None = None) -> tuple:
        """The corner radii, ascending, of ``system``'s end mills (every system's if it has none)
        and, with ``diameter``, of the end mills of that diameter only (all if none has it)."""
        tools = [t for t in self.end_mills if system not in SYSTEMS or t.system == system] or list(self.end_mills)
        if diameter is not None:
            tools = [t for t in tools if abs(t.diameter - diameter) <= SAME] or tools
        return tuple(sorted({t.corner_radius for t in tools}))

    def diameters(self, corner_radius: float, system: str | None = None) -> tuple:
        """The diameters, ascending, of the end mills with ``corner_radius`` (of ``system`` where it
        has one); every end mill's where none has that radius (a radius the spec gives)."""
        tools = [t for t in self.of(system) if abs(t.corner_radius - corner_radius) <= SAME]
        if system in SYSTEMS and any(t.system == system for t in tools):
            tools = [t for t in tools if t.system == system]
        tools = tools or list(self.end_mills)
        return tuple(sorted({t.diameter for t in tools}))

    def tool(self, diameter: float, corner_radius: float, system: str | None = None) -> EndMill | None:
        """The catalogue's end mill of that diameter and corner radius (``system``'s first), or None."""
        return next((t for t in self.of(system) if abs(t.diameter - diameter) <= SAME
                     and abs(t.corner_radius - corner_radius) <= SAME), None)


def parse(raw, where: str = FILE) -> ToolCatalogue:
    """The catalogue from the loaded YAML: a mapping with ``end_mills``, a list of tables."""
    if not isinstance(raw, dict) or set(raw) != {"end_mills"}:
        raise CatalogueError(f"{where}: must be a mapping with the key 'end_mills'")
    return extend(ToolCatalogue(()), raw["end_mills"], f"{where} end_mills")


def extend(base: ToolCatalogue, raw, where: str) -> ToolCatalogue:
    """``base`` and the tables of the list ``raw`` after its end mills (a user catalogue's
    ``end_mills``), each table's name used once."""
    if not isinstance(raw, list) or not raw:
        raise CatalogueError(f"{where}: must be a list of tables")
    out = list(base.end_mills)
    names = {t.table for t in out}
    for i, entry in enumerate(raw):
        tools = _table(entry, i, where)
        if tools[0].table in names:
            raise CatalogueError(f"{where}[{i}].name: {tools[0].table!r} is used twice; each table needs a name "
                                 "of its own")
        names.add(tools[0].table)
        out += tools
    return ToolCatalogue(tuple(out))


def _table(entry, i: int, where: str) -> list[EndMill]:
    name, key, values = table_fields(entry, f"{where}[{i}]", TABLE_KEYS, ("system", "unit", "source"),
                                     {"system": SYSTEMS, "unit": tuple(UNITS)}, lambda n: f"{where}.{n}")
    unit, raw = values["unit"], values["tools"]
    if not isinstance(raw, dict) or not raw:
        raise CatalogueError(f"{key}.tools: must be a mapping of each diameter to a list of its corner radii, "
                             "numbers in the table's unit")
    out, seen = [], set()
    for outer, radii in raw.items():
        d = _key_size(outer, f"{key}.tools (diameter {outer!r})")
        if _si(d, unit) > LARGEST_TOOL:
            raise CatalogueError(f"{key}.tools.{outer}: {d:g} {unit} is wider than an end mill for a sensor's "
                                 f"pocket (at most {LARGEST_TOOL:g} m)")
        if not isinstance(radii, list) or not radii:
            raise CatalogueError(f"{key}.tools.{outer}: {brief(radii)} must be a list of corner radii")
        for j, v in enumerate(radii):
            r = _size(v, f"{key}.tools.{outer}[{j}]")
            machinable(_si(r, unit), f"{key}.tools.{outer}[{j}]", f"the corner radius {r:g} {unit}", CatalogueError)
            if not r < d / 2:
                raise CatalogueError(f"{key}.tools.{outer}[{j}]: the corner radius {r:g} {unit} is not less than "
                                     f"the end mill's radius {d / 2:g} {unit}")
            if (d, r) in seen:
                raise CatalogueError(f"{key}.tools.{outer}[{j}]: the end mill Ø{d:g} R{r:g} {unit} is listed twice")
            seen.add((d, r))
            out.append(EndMill(_si(d, unit), _si(r, unit), name, values["system"], unit))
    return out
