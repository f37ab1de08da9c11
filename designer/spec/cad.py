"""A spec's CAD details (``cad``, docs/spec.md 2.8): the end mill's corner radius, the searched
depth's step, the wire channels and load grooves, read and checked against the spec's limits and
a fixed design's pocket."""

from __future__ import annotations

from dataclasses import dataclass

from designer.errors import SpecError, brief
from designer.spec import catalogue, units
from designer.spec.keys import boolean, machinable, mapping

# The corner radius of the end mill that cuts pockets and flats (cad.corner_radius), m, by
# default: R0.2 is the radius the tool catalogue (materials/tools.yaml) lists on every metric
# end mill of 1-12 mm, so a shop has one for any pocket this tool designs. It is also below half
# the smallest end mill there (1 mm) and the default limits.min_pocket_depth (0.5 mm).
DEFAULT_CORNER_RADIUS = 0.0002
# The grid of a searched pocket's depth (cad.depth_step), m: what a shop sets on a depth stop
DEFAULT_DEPTH_STEP = 5e-5
DEPTH_STEPS = (1, 100)  # the least and the greatest step allowed, in hundredths of a millimetre
# ... and at most this share of the shallowest pocket the spec allows, so that a pocket keeps a
# straight wall above its floor radius (and a wire channel half the pocket deep stays above it).
CORNER_RADIUS_SHARE = 0.4


@dataclass(frozen=True)
class CadOptions:
    """CAD details; ``None`` lets the CAD module pick a default for the beam's size."""

    clamp_length: float | None = None
    bolt_diameter: float | None = None
    end_mill_diameter: float | None = None
    corner_radius: float = DEFAULT_CORNER_RADIUS    # the end mill's: pocket and flat floors meet walls in it
    depth_step: float = DEFAULT_DEPTH_STEP          # the grid of the searched pocket or flat depth
    wire_channels: bool = True
    channel_width: float | None = None
    channel_depth: float | None = None
    load_grooves: bool = False
    groove_positions: tuple[float, ...] | None = None
    groove_depth: float | None = None


def default_corner_radius(shallowest: float, system: str | None = None, mill: float | None = None) -> float:
    """The default cad.corner_radius for pockets at least ``shallowest`` deep (m): the largest
    corner radius of the tool catalogue's end mills (``system``'s, metric unless the spec's stock
    is imperial; of the end mill ``mill`` when one is given and listed) up to R0.2 and
    CORNER_RADIUS_SHARE of the depth (and of ``mill``); another system's where ``system`` has none
    that small, the smallest listed where none has."""
    from designer.spec.tools import SAME

    cap = min(DEFAULT_CORNER_RADIUS, CORNER_RADIUS_SHARE * shallowest)
    if mill is not None:
        cap = min(cap, CORNER_RADIUS_SHARE * mill)
    tools = catalogue.end_mills()
    radii = tools.radii(system if system in ("metric", "imperial") else "metric", mill)
    fitting = [r for r in radii if r <= cap + SAME] or [r for r in tools.radii(None, mill) if r <= cap + SAME]
    return fitting[-1] if fitting else radii[0]


def parse_cad(raw, limits, design, system: str = "none") -> CadOptions:
    """The spec's ``cad`` (docs/spec.md 2.8) under its ``limits`` and fixed ``design`` (None for a search)."""
    lengths = ("clamp_length", "bolt_diameter", "end_mill_diameter", "corner_radius", "channel_width",
               "channel_depth", "groove_depth", "depth_step")
    raw = mapping(raw, "cad", lengths + ("wire_channels", "load_grooves", "groove_positions"))
    values = {k: units.parse_positive(raw[k], "length", f"cad.{k}") for k in lengths if raw.get(k) is not None}
    for k, v in values.items():
        if k != "depth_step":   # (its own rule below)
            machinable(v, f"cad.{k}", repr(raw[k]))
    for k in ("wire_channels", "load_grooves"):
        if k in raw:
            values[k] = boolean(raw[k], f"cad.{k}")
    if raw.get("groove_positions") is not None:
        positions = raw["groove_positions"]
        if not isinstance(positions, (list, tuple)) or not positions:
            raise SpecError(f"cad.groove_positions: {brief(positions)} must be a list of positions")
        values["groove_positions"] = tuple(
            units.parse_positive(p, "length", f"cad.groove_positions[{i}]") for i, p in enumerate(positions))
    if not values.get("load_grooves") and (stray := [k for k in ("groove_positions", "groove_depth") if k in values]):
        raise SpecError(f"cad.{stray[0]}: given without cad.load_grooves: true, so no groove is cut; set "
                        "cad.load_grooves: true or leave it out")
    if (step := values.get("depth_step")) is not None:
        if abs(step / 1e-5 - (k := round(step / 1e-5))) > 1e-6 or not DEPTH_STEPS[0] <= k <= DEPTH_STEPS[1]:
            raise SpecError(f"cad.depth_step: {step * 1e3:g} mm is not allowed; must be a multiple of 0.01 mm from "
                            f"{DEPTH_STEPS[0] / 100:g} mm to {DEPTH_STEPS[1] / 100:g} mm")
        values["depth_step"] = k * 1e-5
    pocket = design.feature if design is not None and design.feature.kind == "pocket" else None
    if "corner_radius" not in values:
        # recorded in design.json's spec.cad, so that the file describes the part on its own
        shallowest = min(limits.min_pocket_depth, pocket.depth) if pocket else limits.min_pocket_depth
        values["corner_radius"] = default_corner_radius(shallowest, system, values.get("end_mill_diameter"))
    radius = values["corner_radius"]
    mill = values.get("end_mill_diameter")
    if mill is not None and not radius < mill / 2:
        raise SpecError(f"cad.corner_radius: {radius * 1e3:g} mm must be less than half the end mill, "
                        f"cad.end_mill_diameter / 2 = {mill * 1e3 / 2:g} mm")
    if pocket is not None and not radius < pocket.depth:
        raise SpecError(f"cad.corner_radius: {radius * 1e3:g} mm must be less than the pocket depth "
                        f"design.feature.depth = {pocket.depth * 1e3:g} mm")
    if pocket is not None and (c_depth := values.get("channel_depth")) is not None and not c_depth < pocket.depth:
        raise SpecError(f"cad.channel_depth: {c_depth * 1e3:g} mm must be less than the pocket depth "
                        f"design.feature.depth = {pocket.depth * 1e3:g} mm")
    return CadOptions(**values)
