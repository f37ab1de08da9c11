"""The beam to build: a design.json record resolved into a ``BeamCad`` (SI, every default picked).

``resolve(record)`` checks that the design can be machined and picks what the record leaves
open from the spec's ``cad`` keys or the documented defaults:

- the clamp block ``-clamp_length <= X < 0``: the section's bounding box (widened when the
  bolts need it) with two bolt clearance holes along ``Z`` on the axis;
- the end mill of slot pockets on a rectangle (corner radii equal to its radius) and of flats,
  from the tool catalogue (``materials/tools.yaml``) unless the record names it;
- the corner radius of the end mill that cuts pockets and flats (``spec.cad.corner_radius``,
  recorded by the spec reader; older files get the reader's default): a slot's floor meets its
  walls all round in it, a flat's floor meets its two end walls in it;
- a shallow wire channel on each pocketed face, from the farthest pocket to the clamp face;
- optionally shallow load-position grooves all around the beam at the calibration positions.

Every problem raises DesignFileError naming the key, its value and what is allowed.
"""

from __future__ import annotations

import math
from typing import Any

from designer import model
from designer.errors import DesignFileError, brief, metres
from designer.model import grooves
from designer.model.sections import LEAST_CUT, flat_depth, flat_half_chord, round_down
from designer.outputs.part import BeamCad, Channels, Clamp, Grooves, fmt_mm
from designer.result.designfile import validate
from designer.outputs.cad import mills
from designer.spec.cad import default_corner_radius

# ISO 273 medium-series clearance holes for ISO metric coarse bolts: nominal -> hole, m.
ISO_273_MEDIUM = {0.0016: 0.0018, 0.002: 0.0024, 0.0025: 0.0029, 0.003: 0.0034, 0.004: 0.0045,
                  0.005: 0.0055, 0.006: 0.0066, 0.008: 0.0090, 0.010: 0.0110, 0.012: 0.0135,
                  0.016: 0.0175, 0.020: 0.0220}
# Other sizes: ISO 273 medium holes run about 10-14 % over the nominal diameter.
CLEARANCE_RATIO = 1.12
# Bolts picked by default for the clamp: M2 ... M8 (a sensor clamp does not need more).
DEFAULT_BOLTS = (0.002, 0.0025, 0.003, 0.004, 0.005, 0.006, 0.008)
# Bolt centre to the edge of the block, in bolt diameters: the usual 1.5 d of bolted joints.
BOLT_EDGE = 1.5
# Default clamp length: 1.5 times the section's larger side, rounded up to 5 mm.
CLAMP_LENGTH_PER_SIZE = 1.5
CLAMP_LENGTH_STEP = 0.005
# Load grooves: their sizes and defaults are the model's (model.grooves, whose stress it checks):
# 0.5 mm wide holds the "very thin string" the paper hung its masses from (Noh et al. 2025,
# section 4.2.1); 0.3 mm deep, at most 5 % of the section's smaller side.
# Defaults are rounded down to this step (0.01 mm, as designs are reported, MODEL.md 5).
ROUND_STEP = 1e-5
# Lengths closer than this are equal (m): below the 0.01 mm resolution of design.json.
LENGTH_EPS = 1e-9


def _mapping(obj: Any, where: str) -> dict:
    if not isinstance(obj, dict):
        raise DesignFileError(f"{where}: {brief(obj)} must be an object")
    return obj


def _length(obj: dict, key: str, where: str, required: bool = True) -> float | None:
    """A positive finite number (a length in metres) at ``obj[key]``."""
    value = obj.get(key)
    if value is None:
        if required:
            raise DesignFileError(f"{where}.{key}: missing; it is required (a length in metres)")
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DesignFileError(f"{where}.{key}: {value!r} must be a number (a length in metres)")
    if value <= 0:
        raise DesignFileError(f"{where}.{key}: {value!r} must be positive (a length in metres)")
    return float(value)


def _flag(obj: dict, key: str, where: str, default: bool) -> bool:
    value = obj.get(key)
    if value is None:
        return default
    if not isinstance(value, bool):
        raise DesignFileError(f"{where}.{key}: {value!r} must be true or false")
    return value


def resolve(record: dict) -> BeamCad:
    """The validated, fully specified beam of a design.json record (SI).

    The record must first pass ``designer.result.designfile.validate`` (the rules every reader
    of design.json applies: known kinds, positive sizes, pockets shallower than half the section
    or the wall, holes in rectangles only, stations on the beam). Then raises DesignFileError
    naming the key, its value and what is allowed when the part cannot be machined: flats too
    narrow for the gauge, features on four faces that meet, stations whose features run off the
    beam or into each other, CAD options that do not fit.
    """
    validate(record)
    d = record["design"]
    spec = record["spec"]
    cad = _mapping(spec.get("cad") or {}, "spec.cad")
    limits = _mapping(spec.get("limits") or {}, "spec.limits")

    name = spec.get("name") or "design"
    if not isinstance(name, str):
        raise DesignFileError(f"spec.name: {name!r} must be text")
    material = d["material"]
    if not material.strip():
        raise DesignFileError(f"design.material: {material!r} must be a material name")

    section = d["section"]
    kind = section["kind"]
    wall = None
    if kind == "rectangle":
        width, height = float(section["width"]), float(section["height"])
    else:
        width = height = float(section["diameter"])
        if kind == "tube":
            wall = float(section["wall"])

    axes = d.get("axes", 1)
    if isinstance(axes, bool):
        raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
    if axes == 2 and kind == "rectangle" and abs(width - height) > LENGTH_EPS:
        raise DesignFileError(f"design.axes: 2 needs a square, round or tube section; the rectangle is "
                              f"{fmt_mm(width)} x {fmt_mm(height)} mm")

    gauge = d.get("gauge") or spec.get("gauge")
    gauge = _mapping(gauge, "design.gauge")
    gauge_length = _length(gauge, "length", "design.gauge")
    gauge_width = _length(gauge, "width", "design.gauge")
    gauge_name = str(gauge.get("name") or "strain gauge")

    feature = d["feature"]
    fkind = feature["kind"]
    depth = p_len = p_wid = hole = 0.0
    if fkind == "pocket":
        depth, p_len, p_wid = float(feature["depth"]), float(feature["length"]), float(feature["width"])
        _check_pocket(kind, width, wall, depth, p_wid, axes)
    elif fkind == "hole":
        hole = float(feature["diameter"])
        if axes != 1:
            raise DesignFileError("design.feature.kind: 'hole' is not allowed with axes: 2; use pocket or none")

    length = float(d["length"])
    l_f = model.feature_length(fkind, p_len, hole, gauge_length)
    stations = _check_stations(d["stations"], length, l_f, fkind)

    end_mill = given = None
    corner = 0.0
    tool = ""
    system = _system(spec)
    if fkind == "pocket":
        corner = _corner_radius(cad, limits, depth, p_len, gauge_length, kind, system)
        recorded = _recorded_tool(feature)
        given = _length(cad, "end_mill_diameter", "spec.cad", required=False)
        if kind == "rectangle":
            end_mill = mills.end_mill(recorded if given is None else given, p_len, p_wid, gauge_length, gauge_width,
                                      corner, system)
            tool = mills.tool_label(end_mill, corner, system)
        else:
            mills.check_flat_end_mill(given, p_len)
            tool = mills.tool_label(given or recorded or mills.flat_end_mill(p_len, corner, system), corner, system)
    clamp = _clamp(cad, width, height)
    channels = None
    if fkind == "pocket" and _flag(cad, "wire_channels", "spec.cad", True):
        channels = _channels(cad, kind, depth, p_wid, end_mill, given)
    grooves = None
    if _flag(cad, "load_grooves", "spec.cad", False):
        grooves = _grooves(cad, spec, kind, width, height, wall, length, stations, l_f, limits)

    status = record.get("status") or "unknown"
    return BeamCad(name=name.strip(), material=material.strip(), status=str(status), section=kind,
                   width=width, height=height, wall=wall, length=length, stations=stations, axes=axes,
                   feature=fkind, pocket_depth=depth, pocket_length=p_len, pocket_width=p_wid,
                   hole_diameter=hole, end_mill=end_mill, floor_radius=corner, tool=tool, gauge_name=gauge_name,
                   gauge_length=gauge_length, gauge_width=gauge_width, clamp=clamp, channels=channels, grooves=grooves,
                   stock=_stock_label(d.get("stock")), tolerances=_tolerance_label(record.get("tolerances")),
                   tolerances_hold=_tolerances_hold(record.get("tolerances")))


def _tolerance_label(block) -> str:
    """The tolerances design.json's ``tolerances`` says the design was checked at ("" without them)."""
    label = block.get("label") if isinstance(block, dict) else None
    return label if isinstance(label, str) else ""


def _tolerances_hold(block) -> bool:
    """Whether design.json's ``tolerances`` gives every limit as met at its worst corner."""
    rows = block.get("constraints") if isinstance(block, dict) else None
    return isinstance(rows, list) and all(isinstance(c, dict) and c.get("satisfied") is True for c in rows)


def _stock_label(stock) -> str:
    """The stock item's label of a design.json ``design.stock`` ("" when the section is not from stock)."""
    if stock is None:
        return ""
    label = stock.get("label") if isinstance(stock, dict) else None
    if not isinstance(label, str) or not label.strip():
        raise DesignFileError(f"design.stock: {stock!r} must be a stock item with its label, as optimize writes it")
    return label.strip()


def _check_pocket(kind, width, wall, depth, p_wid, axes) -> None:
    """What machining needs beyond designfile.validate (which keeps pockets and flats shallower
    than half the section or the wall, and slots narrower than the section)."""
    where = "design.feature"
    if kind == "rectangle":
        if axes == 2 and not depth + p_wid / 2 < width / 2:
            raise DesignFileError(f"{where}.depth: {metres(depth)} with a {fmt_mm(p_wid)} mm wide pocket on all four "
                                  f"faces makes neighbouring pockets meet; depth + width/2 must be less than "
                                  f"{fmt_mm(width / 2)} mm")
        return
    R = width / 2
    half_chord = flat_half_chord(R, depth)
    if 2 * half_chord < p_wid - LENGTH_EPS:
        need = (f"the depth must be at least {fmt_mm(flat_depth(R, p_wid))} mm" if p_wid < width
                else f"no flat on a Ø{fmt_mm(width)} mm bar is that wide")
        raise DesignFileError(f"{where}.depth: {metres(depth)} gives a flat {fmt_mm(2 * half_chord)} mm wide, narrower "
                              f"than the pocket width {fmt_mm(p_wid)} mm the gauge needs; {need}")
    if axes == 2 and not half_chord < R - depth:
        raise DesignFileError(f"{where}.depth: {metres(depth)} is too deep for flats on four faces: neighbouring flats "
                              f"would meet; the depth must be less than {fmt_mm(R - R / math.sqrt(2))} mm")


def _check_stations(stations, length: float, l_f: float, fkind: str) -> tuple:
    out = tuple(float(s) for s in stations)
    problem = model.features_apart(out, length, l_f, fkind)
    if problem is not None:
        raise DesignFileError(f"design.{problem[0]}: {problem[1]}")
    return out


def bolt_clearance(bolt: float) -> float:
    """The clearance hole for a bolt: ISO 273 medium series, else 1.12 d rounded up to 0.1 mm."""
    for nominal, hole in ISO_273_MEDIUM.items():
        if abs(nominal - bolt) < LENGTH_EPS:
            return hole
    return math.ceil(CLEARANCE_RATIO * bolt / 1e-4 - 1e-6) * 1e-4


def _clamp(cad: dict, width: float, height: float) -> Clamp:
    bolt = _length(cad, "bolt_diameter", "spec.cad", required=False)
    if bolt is None:
        fitting = [b for b in DEFAULT_BOLTS if 2 * BOLT_EDGE * b <= width + LENGTH_EPS]
        bolt = fitting[-1] if fitting else DEFAULT_BOLTS[0]
    clearance = bolt_clearance(bolt)
    block_width = max(width, 2 * BOLT_EDGE * bolt)
    minimum = 4 * BOLT_EDGE * bolt  # two holes at L/4 and 3L/4, each 1.5 d from an end
    length = _length(cad, "clamp_length", "spec.cad", required=False)
    if length is None:
        length = max(CLAMP_LENGTH_PER_SIZE * max(width, height), minimum)
        length = math.ceil(length / CLAMP_LENGTH_STEP - 1e-6) * CLAMP_LENGTH_STEP
    elif length < minimum - LENGTH_EPS:
        largest = length / (4 * BOLT_EDGE)   # the bolt the block's length holds
        smaller = (f"; or give a spec.cad.bolt_diameter of at most {fmt_mm(round_down(largest, ROUND_STEP))} mm"
                   if largest >= LEAST_CUT else "")
        raise DesignFileError(f"spec.cad.clamp_length: {metres(length)} is too short for two {fmt_mm(bolt)} mm bolts; "
                              f"it must be at least {fmt_mm(minimum)} mm (holes {BOLT_EDGE:g} bolt diameters from "
                              f"the block's ends){smaller}")
    return Clamp(length=length, width=block_width, height=height, bolt_diameter=bolt, bolt_clearance=clearance,
                 bolt_positions=(-length / 4, -3 * length / 4))


def _system(spec: dict) -> str:
    """The system of units the spec's stock is in (``search.stock``): its end mills' first."""
    search = spec.get("search")
    stock = search.get("stock") if isinstance(search, dict) else None
    return stock if stock in ("metric", "imperial") else "metric"


def _recorded_tool(feature: dict) -> float | None:
    """The end mill's diameter design.json's ``design.feature.tool`` names (optimize and evaluate
    write it from the catalogue they read, which may hold a user's tools), or None."""
    tool = feature.get("tool")
    if tool is None:
        return None
    d = tool.get("diameter") if isinstance(tool, dict) else None
    if isinstance(d, bool) or not isinstance(d, (int, float)) or not 0 < d < 1:
        raise DesignFileError(f"design.feature.tool: {tool!r} must be the end mill optimize writes, with its "
                              "diameter in m")
    return float(d)


def _corner_radius(cad: dict, limits: dict, depth: float, p_len: float, g_len: float, kind: str,
                   system: str = "metric") -> float:
    """The end mill's corner radius, where a pocket's or flat's floor meets its walls."""
    given = _length(cad, "corner_radius", "spec.cad", required=False)
    if given is None:  # a design.json written before the key existed: the spec reader's default
        shallowest = limits.get("min_pocket_depth")
        if isinstance(shallowest, bool) or not isinstance(shallowest, (int, float)) or not shallowest > 0:
            shallowest = depth
        mill = _length(cad, "end_mill_diameter", "spec.cad", required=False)
        return default_corner_radius(min(float(shallowest), depth), system, mill)
    if not given < depth - LENGTH_EPS:
        raise DesignFileError(f"spec.cad.corner_radius: {metres(given)} must be less than the pocket depth "
                              f"({fmt_mm(depth)} mm), so that the pocket keeps a wall above its floor radius")
    floor = p_len - 2 * given
    if kind != "rectangle" and floor < g_len - LENGTH_EPS:  # slots: checked with the end mill
        room = (p_len - g_len) / 2
        allowed = (f"it must be at most {fmt_mm(room)} mm" if room > LENGTH_EPS else
                   f"a flat no longer than the backing has no room for one: make it at least "
                   f"{fmt_mm(g_len + 2 * given)} mm long (design.feature.length)")
        raise DesignFileError(f"spec.cad.corner_radius: {metres(given)} leaves a flat floor {fmt_mm(floor)} mm long, "
                              f"shorter than the {fmt_mm(g_len)} mm gauge backing; {allowed}")
    return given


def _channels(cad: dict, kind: str, depth: float, p_wid: float, end_mill: float | None,
              given_mill: float | None) -> Channels:
    # The default size is the beam model's (model.default_channel, from the spec's end mill if it
    # gives one), whose stiffness counts it. On a slot the channel must enter through the straight
    # part of the pocket's end wall.
    room = p_wid - end_mill if kind == "rectangle" else p_wid
    default_width, default_depth = model.default_channel(kind, depth, p_wid, given_mill)
    width = _length(cad, "channel_width", "spec.cad", required=False)
    if width is None:
        width = default_width
    if not 0 < width <= room + LENGTH_EPS:
        what = ("the pocket width less the end mill diameter, so that the channel enters the pocket's straight "
                "end wall" if kind == "rectangle" else "the pocket width")
        raise DesignFileError(f"spec.cad.channel_width: {metres(width)} is too wide; it must be at most "
                              f"{fmt_mm(room)} mm ({what}); or set spec.cad.wire_channels: false")
    c_depth = _length(cad, "channel_depth", "spec.cad", required=False)
    if c_depth is None:
        c_depth = default_depth
    if not 0 < c_depth < depth:
        raise DesignFileError(f"spec.cad.channel_depth: {metres(c_depth)} must be less than the pocket depth "
                              f"({fmt_mm(depth)} mm)")
    return Channels(width=width, depth=c_depth)


def _grooves(cad, spec, kind, width, height, wall, length, stations, l_f, limits) -> Grooves:
    positions = cad.get("groove_positions")
    key = "spec.cad.groove_positions"
    if positions is None:
        key = "spec.cad.load_grooves"
        load = _mapping(spec.get("load") or {}, "spec.load")
        rng = load.get("position")
        if (not isinstance(rng, list) or len(rng) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in rng)):
            raise DesignFileError(f"spec.load.position: {rng!r} must be [x_min, x_max] in metres to place the "
                                  f"default load grooves; or give spec.cad.groove_positions")
        x_min, x_max = float(rng[0]), float(rng[1])
        positions = list(grooves.default_positions(x_min, x_max))
    if not isinstance(positions, list) or not positions:
        raise DesignFileError(f"spec.cad.groove_positions: {brief(positions)} must be a list of positions (m)")
    g_depth = _length(cad, "groove_depth", "spec.cad", required=False)
    if g_depth is None:
        g_depth = grooves.cut_depth(min(width, height))
    # kept to the default's share of the section, which the beam model's groove stress (Roark's
    # K_t, docs/model.md §4) takes as a notch on the bar; a 3 mm groove had cut an 8 mm bar nearly through
    shallow = grooves.DEPTH_FRACTION * min(width, height)
    deepest, what = shallow, f"{grooves.DEPTH_FRACTION:.0%} of the section's smaller side"
    if kind == "tube":
        min_wall = float(limits.get("min_wall") or 0.0)
        if wall - min_wall < shallow:
            deepest, what = wall - min_wall, f"the tube wall less spec.limits.min_wall ({fmt_mm(min_wall)} mm)"
    if not 0 < g_depth <= deepest + LENGTH_EPS:
        raise DesignFileError(f"spec.cad.groove_depth: {metres(g_depth)} is too deep; it must be at most "
                              f"{deepest * 1e3:.4g} mm ({what})")
    half = grooves.WIDTH / 2
    lo, hi = stations[-1] + l_f / 2 + half, length - half
    out = []
    for i, x in enumerate(positions):
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise DesignFileError(f"spec.cad.groove_positions[{i}]: {x!r} must be a number (m from the clamp face)")
        if not lo - LENGTH_EPS <= x <= hi + LENGTH_EPS:
            which = f"{key}" if key.endswith("positions") else f"{key} (default groove at {fmt_mm(x)} mm)"
            move = "move it" if key.endswith("positions") else "give spec.cad.groove_positions"
            raise DesignFileError(f"{which}: a groove at {metres(x)} does not fit: grooves must lie between the last "
                                  f"gauge feature and the free end, from {fmt_mm(lo)} mm to {fmt_mm(hi)} mm; "
                                  f"{move} or set spec.cad.load_grooves: false")
        out.append(float(x))
    out.sort()
    if (pair := grooves.overlapping(out)) is not None:
        raise DesignFileError(f"{key}: grooves at {fmt_mm(pair[0])} mm and {fmt_mm(pair[1])} mm overlap; they must be "
                              f"more than {fmt_mm(grooves.WIDTH)} mm apart")
    return Grooves(positions=tuple(out), width=grooves.WIDTH, depth=g_depth)

