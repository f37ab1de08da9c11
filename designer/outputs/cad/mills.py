"""The end mills that cut a beam's pockets and flats, from the tool catalogue
(``materials/tools.yaml`` and the user's, ``catalogue.end_mills``).

A slot on a rectangle is cut with the largest end mill whose radius (the slot's corner radius
in plan) leaves the gauge backing on the flat floor and which is at most END_MILL_FRACTION of the
slot's width; a flat on a round bar or tube across the bar with the largest no wider than the
flat is long; either with the spec's cad.end_mill_diameter where it gives one. Both carry the
spec's corner radius (``cad.corner_radius``), where the floor meets the walls. design.json
records the end mill (``design.feature.tool``).
"""

from __future__ import annotations

import math

from designer.errors import DesignFileError, metres
from designer.outputs.part import fmt_mm
from designer.spec import catalogue
from designer.spec.tools import EndMill

# Default end mill: at most 60 % of the slot width, so that the slot keeps straight side walls.
END_MILL_FRACTION = 0.6
# Lengths closer than this are equal (m): below the 0.01 mm resolution of design.json.
LENGTH_EPS = 1e-9


def spec_system(spec) -> str:
    """The system of units whose end mills go first: the spec's stock's (``search.stock``),
    metric unless it is imperial."""
    return spec.search.stock if spec.search.stock in ("metric", "imperial") else "metric"


def tool_label(diameter: float, corner: float, system: str = "metric") -> str:
    """``end mill Ø3 R0.2 mm``: the catalogue's designation, or in mm for a tool it does not list."""
    listed = catalogue.end_mills().tool(diameter, corner, system)
    return listed.label if listed is not None else f"end mill Ø{fmt_mm(diameter)} R{fmt_mm(corner)} mm"


def flat_end_mill(p_len: float, corner: float, system: str = "metric") -> float:
    """The end mill that cuts a flat on a round bar or tube: moved across the bar, it is no wider
    than the flat is long, so the largest catalogue end mill with the corner radius that is (the
    smallest there is where none is)."""
    diameters = catalogue.end_mills().diameters(corner, system)
    fitting = [d for d in diameters if d <= p_len + LENGTH_EPS]
    return fitting[-1] if fitting else diameters[0]


def check_flat_end_mill(given: float | None, p_len: float) -> None:
    """A given end mill (cad.end_mill_diameter, m) for a flat on a round bar or tube: moved across
    the bar, it cuts a flat as long as itself, so it must be no wider than the flat is long."""
    if given is not None and given > p_len + LENGTH_EPS:
        raise DesignFileError(f"spec.cad.end_mill_diameter: {metres(given)} is wider than the flat is long "
                              f"({fmt_mm(p_len)} mm); moved across the bar it would cut a longer flat: it must be "
                              "at most the flat's length")


def pocket_tool(spec, geometry) -> EndMill | None:
    """The end mill that cuts ``geometry``'s pockets or flats under ``spec`` (a Spec), as the
    CAD picks it; None without pockets. design.json records it (``design.feature.tool``)."""
    if geometry.feature != "pocket":
        return None
    system = spec_system(spec)
    corner = spec.cad.corner_radius
    if geometry.section == "rectangle":
        # chosen as for the gauge's own pocket (``spec.pocket_size``): a slot made longer than that
        # (``search.problem.pocket_as_needed``) is cut with the same end mill, whose radius the
        # search's model took (``slot_end_mill``), not a larger one its length would allow
        length = min(geometry.pocket_length, spec.pocket_size()[0])
        d = end_mill(spec.cad.end_mill_diameter, length, geometry.pocket_width, spec.gauge.length,
                     spec.gauge.width, corner, system)
    else:
        d = spec.cad.end_mill_diameter or flat_end_mill(geometry.pocket_length, corner, system)
        check_flat_end_mill(spec.cad.end_mill_diameter, geometry.pocket_length)
    listed = catalogue.end_mills().tool(d, corner, system)
    return listed if listed is not None else EndMill(d, corner, "spec", system, "mm")


def slot_end_mill(spec) -> float:
    """The end mill that cuts a spec's slots (rectangle pockets), which depends on the spec alone:
    the pocket's size from the gauge and its margin, the corner radius and any given end mill.
    Raises DesignFileError when no tool can."""
    lp, wp = spec.pocket_size()
    system = spec_system(spec)
    if spec.cad.end_mill_diameter is not None:
        return end_mill(spec.cad.end_mill_diameter, lp, wp, spec.gauge.length, spec.gauge.width,
                        spec.cad.corner_radius, system)
    try:
        return end_mill(None, lp, wp, spec.gauge.length, spec.gauge.width, spec.cad.corner_radius, system)
    except DesignFileError:
        smallest = min(t.diameter for t in catalogue.end_mills().end_mills)
        raise DesignFileError(
            f"a slot {fmt_mm(wp)} mm wide (the gauge's {fmt_mm(spec.gauge.width)} mm and twice "
            f"limits.pocket_margin, or cad.corner_radius where larger) leaves no catalogue end mill (from "
            f"{fmt_mm(smallest)} mm) that cuts it with the {fmt_mm(spec.cad.corner_radius)} mm cad.corner_radius "
            "and keeps the gauge on its flat floor; "
            "give cad.end_mill_diameter, a smaller cad.corner_radius or a larger limits.pocket_margin") from None


def slot_plan_radius(spec) -> float:
    """A spec's slots' corner radius in plan: the radius of the end mill that cuts them
    (``slot_end_mill``), which the model's K_t at the rim reads (docs/model.md §7). Where no end mill
    can, the largest the rule allows (END_MILL_FRACTION of the slot's width): no such design is
    reported (``search.run``'s unmachinable families), but its model stays defined."""
    try:
        return slot_end_mill(spec) / 2
    except DesignFileError:
        return END_MILL_FRACTION * spec.pocket_size()[1] / 2


def end_mill(given: float | None, p_len: float, p_wid: float, g_len: float, g_wid: float, corner: float,
             system: str = "metric") -> float:
    """The end mill of a slot: its radius is the slot's plan corner radius; ``corner`` (its own
    corner radius) rounds the floor's edge, and the gauge backing must sit on the flat floor;
    ``given``: the spec's cad.end_mill_diameter (m), checked, or None for the largest catalogue
    end mill with the corner radius that fits. Raises DesignFileError when none does."""

    def gauge_fits(tool: float) -> bool:
        r = tool / 2
        cx, cy = p_len / 2 - r, p_wid / 2 - r  # centre of the corner arc
        gx, gy = g_len / 2, g_wid / 2          # corner of the gauge backing
        # the flat floor: the slot's outline less the floor radius all round
        if gx > p_len / 2 - corner + LENGTH_EPS or gy > p_wid / 2 - corner + LENGTH_EPS:
            return False
        return gx <= cx or gy <= cy or math.hypot(gx - cx, gy - cy) <= r - corner + LENGTH_EPS

    if given is None:
        fitting = [t for t in catalogue.end_mills().diameters(corner, system)
                   if t <= END_MILL_FRACTION * p_wid + LENGTH_EPS and t / 2 > corner + LENGTH_EPS
                   and gauge_fits(t)]
        if not fitting:
            raise DesignFileError(f"design.feature.width: {metres(p_wid)} leaves no catalogue end mill "
                                  f"that cuts the slot with a {fmt_mm(corner)} mm corner radius and keeps the "
                                  f"{fmt_mm(g_len)} x {fmt_mm(g_wid)} mm gauge on its flat floor; give "
                                  f"spec.cad.end_mill_diameter or a smaller spec.cad.corner_radius")
        return fitting[-1]
    if given > p_wid + LENGTH_EPS:
        raise DesignFileError(f"spec.cad.end_mill_diameter: {metres(given)} is wider than the {fmt_mm(p_wid)} mm "
                              "pocket; it must be at most the pocket width")
    if not corner < given / 2 - LENGTH_EPS:
        raise DesignFileError(f"spec.cad.corner_radius: {metres(corner)} must be less than half the end mill "
                              f"(Ø{fmt_mm(given)} mm: {fmt_mm(given / 2)} mm)")
    if not gauge_fits(given):
        raise DesignFileError(f"spec.cad.end_mill_diameter: {metres(given)} leaves corner radii that cut into the "
                              f"{fmt_mm(g_len)} x {fmt_mm(g_wid)} mm gauge backing in its "
                              f"{fmt_mm(p_len)} x {fmt_mm(p_wid)} mm pocket (its floor radius "
                              f"{fmt_mm(corner)} mm included); use a smaller end mill")
    return given
