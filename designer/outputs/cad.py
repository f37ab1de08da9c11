"""The CAD model of a designed beam: a machinable CadQuery solid, STEP and STL files.

The solid is built in the CAD frame of SPEC.md, in millimetres: origin on the beam's axis at
the clamp face, ``+X`` along the beam to the free end (``0 <= X <= length``), the clamp block at
``X < 0``, ``Z`` the load direction (gauge faces at ``Z = +-h/2`` or ``+-D/2``), ``Y`` across.

It carries, besides the section of the design:

- the clamp block ``-clamp_length <= X < 0``: the section's bounding box (widened when the
  bolts need it) with two bolt clearance holes along ``Z`` on the axis;
- at every station the feature of MODEL.md section 1 on both bending faces (all four faces
  when biaxial): a slot pocket with corner radii equal to the end mill's radius on a
  rectangle, a flat on a round or tube, a through-hole along ``Y`` for ``hole``;
- a shallow wire channel on each pocketed face, along its centre line from the farthest
  pocket to the clamp face (it runs through the nearer pockets and ends in a half circle of
  its own width centred on the clamp face, as its cutter leaves it);
- optionally shallow load-position grooves all around the beam at the calibration positions.

``resolve(record)`` turns a design.json record into a validated ``BeamCad`` (SI, every
default picked); ``build_solid(beam)`` makes the solid; ``export(...)`` and
``write_cad_outputs(...)`` write STEP, STL and the pictures so that nothing half-written is
left behind. cadquery is imported only inside the functions that need it.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import tempfile
import unicodedata
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from designer.errors import DesignFileError, FpdError, describe_allowed

MM = 1e-3  # metres per millimetre; CAD files are in millimetres (SPEC.md, the CAD frame)

SECTION_KINDS = ("rectangle", "round", "tube")
FEATURE_KINDS = ("pocket", "hole", "none")
FACES = ("+z", "-z", "+y", "-y")

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
# Standard metric end mill diameters, m.
END_MILLS = (0.001, 0.0015, 0.002, 0.0025, 0.003, 0.004, 0.005, 0.006, 0.008, 0.010, 0.012)
# Default end mill: at most 60 % of the slot width, so that the slot keeps straight side walls.
END_MILL_FRACTION = 0.6
# Wire channel: 1.5 mm takes four 0.3 mm lead wires side by side; 0.5 mm deep covers one.
CHANNEL_WIDTH = 0.0015
CHANNEL_DEPTH = 0.0005
# Load grooves: 0.5 mm wide holds the "very thin string" the paper hung its masses from
# (Noh et al. 2025, section 4.2.1); 0.3 mm deep, at most 5 % of the section's smaller side.
GROOVE_WIDTH = 0.0005
GROOVE_DEPTH = 0.0003
GROOVE_DEPTH_FRACTION = 0.05
# Defaults are rounded down to this step (0.01 mm, as designs are reported, MODEL.md 5).
ROUND_STEP = 1e-5
# Cutting tools run this far past the surfaces they break, so that no faces coincide (mm).
TOOL_OVERRUN_MM = 1.0
# STL tessellation: 0.01 mm chordal deviation, 0.1 rad angular deviation.
STL_TOLERANCE_MM = 0.01
STL_ANGULAR_TOLERANCE = 0.1
# Lengths closer than this are equal (m): below the 0.01 mm resolution of design.json.
LENGTH_EPS = 1e-9


# ----------------------------------------------------------------- the resolved geometry

@dataclass(frozen=True)
class Clamp:
    """The clamp block behind the clamp face (``-length <= X <= 0``), SI."""

    length: float
    width: float               # across (Y)
    height: float              # in the load direction (Z)
    bolt_diameter: float       # nominal bolt size
    bolt_clearance: float      # the drilled hole
    bolt_positions: tuple      # X of the hole centres, negative


@dataclass(frozen=True)
class Channels:
    """Wire channels: ``width`` across, ``depth`` into the face, along each pocketed face."""

    width: float
    depth: float


@dataclass(frozen=True)
class Grooves:
    """Load-position grooves all around the beam, centred at ``positions`` (X)."""

    positions: tuple
    width: float
    depth: float


@dataclass(frozen=True)
class BeamCad:
    """Everything needed to build and draw one beam, SI, every default already picked."""

    name: str
    material: str
    status: str
    section: str               # rectangle | round | tube
    width: float               # Y extent: b or D
    height: float              # Z extent: h or D
    wall: float | None         # tube wall t
    length: float              # free length
    stations: tuple            # d_i, gauge centres from the clamp face
    axes: int
    feature: str               # pocket | hole | none
    pocket_depth: float        # p (pocket or flat)
    pocket_length: float       # l_p
    pocket_width: float        # w_p
    hole_diameter: float       # d_h
    end_mill: float | None     # slot pockets on rectangles: corner radius = end_mill / 2
    gauge_name: str
    gauge_length: float
    gauge_width: float
    clamp: Clamp
    channels: Channels | None
    grooves: Grooves | None

    @property
    def radius(self) -> float:
        """R = D/2 of a round or tube."""
        return self.width / 2

    @property
    def corner_radius(self) -> float:
        return self.end_mill / 2 if self.end_mill else 0.0

    @property
    def feature_length(self) -> float:
        """l_f of MODEL.md section 1: pocket length, hole diameter, or the gauge's length."""
        return {"pocket": self.pocket_length, "hole": self.hole_diameter, "none": self.gauge_length}[self.feature]

    @property
    def faces(self) -> tuple:
        """The faces that carry a feature (and gauges): ``+z, -z`` and, biaxial, ``+y, -y``."""
        return FACES if self.axes == 2 else FACES[:2]

    @property
    def cut_faces(self) -> tuple:
        """Faces with a pocket or flat machined into them."""
        return self.faces if self.feature == "pocket" else ()

    @property
    def flat_half_chord(self) -> float:
        """Half the chord of a flat's floor on a round or tube."""
        R, p = self.radius, self.pocket_depth
        return math.sqrt(max(R * R - (R - p) ** 2, 0.0))

    @property
    def overall_length(self) -> float:
        return self.clamp.length + self.length

    @property
    def file_stem(self) -> str:
        """The name made safe for file names."""
        stem = re.sub(r"[^A-Za-z0-9._-]+", "-", _ascii(self.name)).strip("-.")
        return stem or "design"

    def bounding_box(self) -> tuple:
        """((xmin, xmax), (ymin, ymax), (zmin, zmax)) of the solid, m."""
        c = self.clamp
        return ((-c.length, self.length), (-c.width / 2, c.width / 2), (-c.height / 2, c.height / 2))

    def section_label(self) -> str:
        """The section in millimetres, as a machinist reads it."""
        if self.section == "rectangle":
            return f"{fmt_mm(self.width)} x {fmt_mm(self.height)} rectangle"
        if self.section == "round":
            return f"Ø{fmt_mm(self.width)} round"
        return f"Ø{fmt_mm(self.width)} x {fmt_mm(self.wall)} wall tube"


def fmt_mm(value_m: float) -> str:
    """A length in millimetres to 0.01 mm without trailing zeros: 0.0127 -> '12.7'."""
    text = f"{value_m / MM:.2f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _ascii(text: str) -> str:
    return unicodedata.normalize("NFKD", str(text)).encode("ascii", "ignore").decode("ascii")


def _mm(value_m: float) -> str:
    return f"{value_m!r} m ({fmt_mm(value_m)} mm)"


# ----------------------------------------------------------------- reading and checking

def _mapping(obj: Any, where: str) -> dict:
    if not isinstance(obj, dict):
        raise DesignFileError(f"{where}: {obj!r} must be an object")
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


def _round_down(value: float, step: float = ROUND_STEP) -> float:
    return math.floor(value / step + 1e-9) * step


def resolve(record: dict) -> BeamCad:
    """The validated, fully specified beam of a design.json record (SI).

    Raises DesignFileError naming the key, its value and what is allowed when the design
    cannot be built: missing or non-positive sizes, pockets or flats as deep as the wall,
    stations whose features run off the beam or into each other, CAD options that do not fit.
    """
    record = _mapping(record, "design.json")
    if "design" not in record:
        raise DesignFileError("design: missing; a design.json record needs its 'design' object "
                              "(written by fpdesign optimize or evaluate)")
    d = _mapping(record["design"], "design")
    spec = _mapping(record.get("spec") or {}, "spec")
    cad = _mapping(spec.get("cad") or {}, "spec.cad")
    limits = _mapping(spec.get("limits") or {}, "spec.limits")

    name = spec.get("name") or "design"
    if not isinstance(name, str):
        raise DesignFileError(f"spec.name: {name!r} must be text")
    material = d.get("material")
    if not isinstance(material, str) or not material.strip():
        raise DesignFileError(f"design.material: {material!r} must be a material name")

    section = _mapping(d.get("section"), "design.section")
    kind = section.get("kind")
    if kind not in SECTION_KINDS:
        raise DesignFileError(f"design.section.kind: {kind!r} is not allowed; "
                              f"must be {describe_allowed(SECTION_KINDS)}")
    wall = None
    if kind == "rectangle":
        width = _length(section, "width", "design.section")
        height = _length(section, "height", "design.section")
    else:
        width = height = _length(section, "diameter", "design.section")
        if kind == "tube":
            wall = _length(section, "wall", "design.section")
            if not wall < width / 2:
                raise DesignFileError(f"design.section.wall: {_mm(wall)} must be less than half the diameter "
                                      f"({fmt_mm(width / 2)} mm)")

    axes = d.get("axes", 1)
    if axes not in (1, 2) or isinstance(axes, bool):
        raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
    if axes == 2 and kind == "rectangle" and abs(width - height) > LENGTH_EPS:
        raise DesignFileError(f"design.axes: 2 needs a square, round or tube section; the rectangle is "
                              f"{fmt_mm(width)} x {fmt_mm(height)} mm")

    gauge = d.get("gauge") or spec.get("gauge")
    gauge = _mapping(gauge, "design.gauge")
    gauge_length = _length(gauge, "length", "design.gauge")
    gauge_width = _length(gauge, "width", "design.gauge")
    gauge_name = str(gauge.get("name") or "strain gauge")

    feature = _mapping(d.get("feature"), "design.feature")
    fkind = feature.get("kind")
    if fkind not in FEATURE_KINDS:
        raise DesignFileError(f"design.feature.kind: {fkind!r} is not allowed; "
                              f"must be {describe_allowed(FEATURE_KINDS)}")
    depth = p_len = p_wid = hole = 0.0
    if fkind == "pocket":
        depth = _length(feature, "depth", "design.feature")
        p_len = _length(feature, "length", "design.feature")
        p_wid = _length(feature, "width", "design.feature")
        _check_pocket(kind, width, height, wall, depth, p_wid, axes)
    elif fkind == "hole":
        hole = _length(feature, "diameter", "design.feature")
        if kind != "rectangle":
            raise DesignFileError(f"design.feature.kind: 'hole' needs a rectangle section, not {kind!r}")
        if axes != 1:
            raise DesignFileError("design.feature.kind: 'hole' is not allowed with axes: 2; use pocket or none")
        if not hole < height:
            raise DesignFileError(f"design.feature.diameter: {_mm(hole)} must be less than the section height "
                                  f"({fmt_mm(height)} mm)")

    length = _length(d, "length", "design")
    l_f = {"pocket": p_len, "hole": hole, "none": gauge_length}[fkind]
    stations = _check_stations(d.get("stations"), length, l_f, fkind)

    end_mill = None
    if fkind == "pocket" and kind == "rectangle":
        end_mill = _end_mill(cad, p_len, p_wid, gauge_length, gauge_width)
    clamp = _clamp(cad, width, height)
    channels = None
    if fkind == "pocket" and _flag(cad, "wire_channels", "spec.cad", True):
        channels = _channels(cad, kind, depth, p_wid, end_mill)
    grooves = None
    if _flag(cad, "load_grooves", "spec.cad", False):
        grooves = _grooves(cad, spec, kind, width, height, wall, length, stations, l_f, limits)

    status = record.get("status") or "unknown"
    return BeamCad(name=name.strip(), material=material.strip(), status=str(status), section=kind,
                   width=width, height=height, wall=wall, length=length, stations=stations, axes=axes,
                   feature=fkind, pocket_depth=depth, pocket_length=p_len, pocket_width=p_wid,
                   hole_diameter=hole, end_mill=end_mill, gauge_name=gauge_name, gauge_length=gauge_length,
                   gauge_width=gauge_width, clamp=clamp, channels=channels, grooves=grooves)


def _check_pocket(kind, width, height, wall, depth, p_wid, axes) -> None:
    where = "design.feature"
    if kind == "rectangle":
        if not depth < height / 2:
            raise DesignFileError(f"{where}.depth: {_mm(depth)} is too deep; the pockets on both faces must "
                                  f"leave material between them: less than half the height ({fmt_mm(height / 2)} mm)")
        if not p_wid < width:
            raise DesignFileError(f"{where}.width: {_mm(p_wid)} must be less than the section width "
                                  f"({fmt_mm(width)} mm) so that the slot keeps its side walls")
        if axes == 2 and not depth + p_wid / 2 < width / 2:
            raise DesignFileError(f"{where}.depth: {_mm(depth)} with a {fmt_mm(p_wid)} mm wide pocket on all four "
                                  f"faces makes neighbouring pockets meet; depth + width/2 must be less than "
                                  f"{fmt_mm(width / 2)} mm")
        return
    R = width / 2
    limit, what = (wall, "the tube wall") if kind == "tube" else (R, "the radius")
    if not depth < limit:
        raise DesignFileError(f"{where}.depth: {_mm(depth)} is too deep; a flat must be shallower than {what} "
                              f"({fmt_mm(limit)} mm)")
    half_chord = math.sqrt(R * R - (R - depth) ** 2)
    if 2 * half_chord < p_wid - LENGTH_EPS:
        raise DesignFileError(f"{where}.depth: {_mm(depth)} gives a flat {fmt_mm(2 * half_chord)} mm wide, narrower "
                              f"than the pocket width {fmt_mm(p_wid)} mm the gauge needs; the depth must be at least "
                              f"{fmt_mm(R - math.sqrt(max(R * R - p_wid * p_wid / 4, 0.0)))} mm")
    if axes == 2 and not half_chord < R - depth:
        raise DesignFileError(f"{where}.depth: {_mm(depth)} is too deep for flats on four faces: neighbouring flats "
                              f"would meet; the depth must be less than {fmt_mm(R - R / math.sqrt(2))} mm")


def _check_stations(stations, length: float, l_f: float, fkind: str) -> tuple:
    what = {"pocket": "pocket", "hole": "hole", "none": "gauge"}[fkind]
    if not isinstance(stations, list) or not stations:
        raise DesignFileError(f"design.stations: {stations!r} must be a list of gauge positions (m)")
    out = []
    for i, s in enumerate(stations):
        if isinstance(s, bool) or not isinstance(s, (int, float)) or not math.isfinite(s):
            raise DesignFileError(f"design.stations[{i}]: {s!r} must be a number (m from the clamp face)")
        lo, hi = l_f / 2, length - l_f / 2
        if not lo < s < hi:
            raise DesignFileError(f"design.stations[{i}]: {_mm(s)} is off the beam: with its {fmt_mm(l_f)} mm "
                                  f"{what} it must lie between {fmt_mm(lo)} mm and {fmt_mm(hi)} mm from the clamp "
                                  f"face (free length {fmt_mm(length)} mm)")
        out.append(float(s))
    for i in range(len(out) - 1):
        if not out[i + 1] - out[i] > l_f:
            raise DesignFileError(f"design.stations[{i + 1}]: {_mm(out[i + 1])} is too close to station {i} at "
                                  f"{fmt_mm(out[i])} mm: the {fmt_mm(l_f)} mm {what}s would overlap; stations must "
                                  f"increase by more than {fmt_mm(l_f)} mm")
    return tuple(out)


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
        raise DesignFileError(f"spec.cad.clamp_length: {_mm(length)} is too short for two {fmt_mm(bolt)} mm bolts; "
                              f"it must be at least {fmt_mm(minimum)} mm (holes {BOLT_EDGE:g} bolt diameters from "
                              f"the block's ends); or give a smaller spec.cad.bolt_diameter")
    return Clamp(length=length, width=block_width, height=height, bolt_diameter=bolt, bolt_clearance=clearance,
                 bolt_positions=(-length / 4, -3 * length / 4))


def _end_mill(cad: dict, p_len: float, p_wid: float, g_len: float, g_wid: float) -> float:
    given = _length(cad, "end_mill_diameter", "spec.cad", required=False)

    def gauge_fits(tool: float) -> bool:
        r = tool / 2
        cx, cy = p_len / 2 - r, p_wid / 2 - r  # centre of the corner arc
        gx, gy = g_len / 2, g_wid / 2          # corner of the gauge backing
        if gx > p_len / 2 + LENGTH_EPS or gy > p_wid / 2 + LENGTH_EPS:
            return False
        return gx <= cx or gy <= cy or math.hypot(gx - cx, gy - cy) <= r + LENGTH_EPS

    if given is None:
        fitting = [t for t in END_MILLS if t <= END_MILL_FRACTION * p_wid + LENGTH_EPS and gauge_fits(t)]
        if not fitting:
            raise DesignFileError(f"design.feature.width: {_mm(p_wid)} leaves no standard end mill (from 1 mm) "
                                  f"that cuts the slot and keeps the {fmt_mm(g_len)} x {fmt_mm(g_wid)} mm gauge clear "
                                  f"of its corners; give spec.cad.end_mill_diameter")
        return fitting[-1]
    if given > p_wid + LENGTH_EPS:
        raise DesignFileError(f"spec.cad.end_mill_diameter: {_mm(given)} is wider than the {fmt_mm(p_wid)} mm pocket; "
                              f"it must be at most the pocket width")
    if not gauge_fits(given):
        raise DesignFileError(f"spec.cad.end_mill_diameter: {_mm(given)} leaves corner radii that cut into the "
                              f"{fmt_mm(g_len)} x {fmt_mm(g_wid)} mm gauge backing in its "
                              f"{fmt_mm(p_len)} x {fmt_mm(p_wid)} mm pocket; use a smaller end mill")
    return given


def _channels(cad: dict, kind: str, depth: float, p_wid: float, end_mill: float | None) -> Channels:
    # On a slot the channel must enter through the straight part of the pocket's end wall.
    room = p_wid - end_mill if kind == "rectangle" else p_wid
    width = _length(cad, "channel_width", "spec.cad", required=False)
    if width is None:
        width = _round_down(min(CHANNEL_WIDTH, room if kind == "rectangle" else room / 2))
    if not 0 < width <= room + LENGTH_EPS:
        what = ("the pocket width less the end mill diameter, so that the channel enters the pocket's straight "
                "end wall" if kind == "rectangle" else "the pocket width")
        raise DesignFileError(f"spec.cad.channel_width: {_mm(width)} is too wide; it must be at most "
                              f"{fmt_mm(room)} mm ({what}); or set spec.cad.wire_channels: false")
    c_depth = _length(cad, "channel_depth", "spec.cad", required=False)
    if c_depth is None:
        c_depth = _round_down(min(CHANNEL_DEPTH, depth / 2))
    if not 0 < c_depth < depth:
        raise DesignFileError(f"spec.cad.channel_depth: {_mm(c_depth)} must be less than the pocket depth "
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
        positions = [x_min, (x_min + x_max) / 2, x_max]
    if not isinstance(positions, list) or not positions:
        raise DesignFileError(f"spec.cad.groove_positions: {positions!r} must be a list of positions (m)")
    g_depth = _length(cad, "groove_depth", "spec.cad", required=False)
    if g_depth is None:
        g_depth = _round_down(min(GROOVE_DEPTH, GROOVE_DEPTH_FRACTION * min(width, height)))
    if kind == "tube":
        min_wall = float(limits.get("min_wall") or 0.0)
        deepest, what = wall - min_wall, f"the tube wall less spec.limits.min_wall ({fmt_mm(min_wall)} mm)"
    else:
        deepest, what = min(width, height) / 2, "half the section's smaller side"
    if not 0 < g_depth < deepest:
        raise DesignFileError(f"spec.cad.groove_depth: {_mm(g_depth)} is too deep; it must be less than "
                              f"{fmt_mm(deepest)} mm ({what})")
    half = GROOVE_WIDTH / 2
    lo, hi = stations[-1] + l_f / 2 + half, length - half
    out = []
    for i, x in enumerate(positions):
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
            raise DesignFileError(f"spec.cad.groove_positions[{i}]: {x!r} must be a number (m from the clamp face)")
        if not lo - LENGTH_EPS <= x <= hi + LENGTH_EPS:
            which = f"{key}" if key.endswith("positions") else f"{key} (default groove at {fmt_mm(x)} mm)"
            raise DesignFileError(f"{which}: a groove at {_mm(x)} does not fit: grooves must lie between the last "
                                  f"gauge feature and the free end, from {fmt_mm(lo)} mm to {fmt_mm(hi)} mm; "
                                  f"give spec.cad.groove_positions or set spec.cad.load_grooves: false")
        out.append(float(x))
    out.sort()
    for a, b in zip(out, out[1:]):
        if not b - a > GROOVE_WIDTH:
            raise DesignFileError(f"{key}: grooves at {fmt_mm(a)} mm and {fmt_mm(b)} mm overlap; they must be more "
                                  f"than {fmt_mm(GROOVE_WIDTH)} mm apart")
    return Grooves(positions=tuple(out), width=GROOVE_WIDTH, depth=g_depth)


# ----------------------------------------------------------------- the solid

def build_solid(beam: BeamCad):
    """The beam as one cadquery ``Solid`` in millimetres (SPEC.md CAD frame)."""
    import cadquery as cq

    V = cq.Vector
    s = 1.0 / MM
    E = TOOL_OVERRUN_MM
    L, Lc = beam.length * s, beam.clamp.length * s
    W, H = beam.width * s, beam.height * s
    Wc, Hc = beam.clamp.width * s, beam.clamp.height * s
    R = W / 2

    if beam.section == "rectangle" and abs(Wc - W) < 1e-9:
        base = cq.Solid.makeBox(Lc + L, W, H, pnt=V(-Lc, -W / 2, -H / 2))
    else:
        if beam.section == "rectangle":
            bar = cq.Solid.makeBox(L, W, H, pnt=V(0, -W / 2, -H / 2))
        else:
            bar = cq.Solid.makeCylinder(R, L, pnt=V(0, 0, 0), dir=V(1, 0, 0))
        block = cq.Solid.makeBox(Lc, Wc, Hc, pnt=V(-Lc, -Wc / 2, -Hc / 2))
        base = block.fuse(bar).clean()

    tools = []
    if beam.section == "tube":
        bore = (R - beam.wall * s)
        tools.append(cq.Solid.makeCylinder(bore, L + E, pnt=V(0, 0, 0), dir=V(1, 0, 0)))
    half = H / 2  # the face's distance from the axis (square when biaxial)

    def on_faces(tool_on_plus_z):
        """Copies of a tool made for the +Z face, turned onto every featured face."""
        angles = {"+z": 0.0, "-z": 180.0, "+y": -90.0, "-y": 90.0}
        out = []
        for face in beam.cut_faces:
            angle = angles[face]
            out.append(tool_on_plus_z if angle == 0 else tool_on_plus_z.rotate(V(0, 0, 0), V(1, 0, 0), angle))
        return out

    if beam.feature == "pocket":
        p, lp, wp = beam.pocket_depth * s, beam.pocket_length * s, beam.pocket_width * s
        if beam.section == "rectangle":
            r = beam.corner_radius * s
            sketch = cq.Sketch()
            if abs(2 * r - wp) < 1e-9:
                sketch = sketch.slot(lp - wp, wp)
            else:
                sketch = sketch.rect(lp, wp).vertices().fillet(r)
            pocket = cq.Workplane("XY", origin=(0, 0, half - p)).placeSketch(sketch).extrude(p + E).val()
        else:
            pocket = cq.Solid.makeBox(lp, 2 * R + 2 * E, p + E, pnt=V(-lp / 2, -R - E, R - p))
        for d in beam.stations:
            tools += on_faces(pocket.translate(V(d * s, 0, 0)))
    elif beam.feature == "hole":
        dh = beam.hole_diameter * s
        for d in beam.stations:
            tools.append(cq.Solid.makeCylinder(dh / 2, W + 2 * E, pnt=V(d * s, -W / 2 - E, 0), dir=V(0, 1, 0)))

    if beam.channels is not None:
        cw, cd = beam.channels.width * s, beam.channels.depth * s
        reach = beam.stations[-1] * s
        straight = cq.Solid.makeBox(reach, cw, cd + E, pnt=V(0, -cw / 2, half - cd))
        end = cq.Solid.makeCylinder(cw / 2, cd + E, pnt=V(0, 0, half - cd), dir=V(0, 0, 1))
        tools += on_faces(straight.fuse(end).clean())

    c = beam.clamp
    for xb in c.bolt_positions:
        tools.append(cq.Solid.makeCylinder(c.bolt_clearance * s / 2, Hc + 2 * E,
                                           pnt=V(xb * s, 0, -Hc / 2 - E), dir=V(0, 0, 1)))

    if beam.grooves is not None:
        gw, gd = beam.grooves.width * s, beam.grooves.depth * s
        for xg in beam.grooves.positions:
            x0 = xg * s - gw / 2
            if beam.section == "rectangle":
                outer = cq.Solid.makeBox(gw, W + 2 * E, H + 2 * E, pnt=V(x0, -W / 2 - E, -H / 2 - E))
                inner = cq.Solid.makeBox(gw, W - 2 * gd, H - 2 * gd, pnt=V(x0, -W / 2 + gd, -H / 2 + gd))
            else:
                outer = cq.Solid.makeCylinder(R + E, gw, pnt=V(x0, 0, 0), dir=V(1, 0, 0))
                inner = cq.Solid.makeCylinder(R - gd, gw, pnt=V(x0, 0, 0), dir=V(1, 0, 0))
            tools.append(outer.cut(inner))

    shape = base.cut(*tools).clean() if tools else base
    solids = shape.Solids()
    if len(solids) != 1 or not solids[0].isValid():
        raise FpdError(f"the CAD kernel did not produce one valid solid for {beam.name!r} "
                       f"({len(solids)} solids); please report this design")
    return solids[0]


# ----------------------------------------------------------------- files

def step_name(name: str) -> str:
    """The product name as written into STEP: plain ASCII without quotes."""
    return _ascii(name).replace("'", "") or "design"


def write_step(solid, path: str | os.PathLike, name: str) -> Path:
    """Write ``solid`` (mm) as STEP AP214 in millimetres with one product named ``name``."""
    path = Path(path)
    with _temporary_sibling(path) as tmp:
        _step_file(solid, tmp, name)
        os.replace(tmp, path)
    return path


def write_stl(solid, path: str | os.PathLike) -> Path:
    """Write ``solid`` (mm) as binary STL, 0.01 mm chordal tolerance."""
    path = Path(path)
    with _temporary_sibling(path) as tmp:
        _stl_file(solid, tmp)
        os.replace(tmp, path)
    return path


def _step_file(solid, path: Path, name: str) -> None:
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer
    from OCP.StepBasic import StepBasic_Product
    from OCP.TCollection import TCollection_HAsciiString

    writer = STEPControl_Writer()
    # The writer's unit settings are global to OCCT; cadquery's own exporter sets them the same way.
    Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    writer.Transfer(solid.wrapped, STEPControl_StepModelType.STEPControl_AsIs)
    model = writer.Model()
    label = step_name(name)
    for i in range(1, model.NbEntities() + 1):
        entity = model.Value(i)
        if isinstance(entity, StepBasic_Product):
            entity.SetName(TCollection_HAsciiString(label))
            entity.SetId(TCollection_HAsciiString(label))
    status = writer.Write(str(path))
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise FpdError(f"{path}: the STEP file could not be written ({status})")


def _stl_file(solid, path: Path) -> None:
    ok = solid.exportStl(str(path), tolerance=STL_TOLERANCE_MM, angularTolerance=STL_ANGULAR_TOLERANCE,
                         ascii=False, relative=False)
    if not ok:
        raise FpdError(f"{path}: the STL file could not be written")


def _file_mode() -> int:
    """The permissions an ordinary new file gets (temporary files are private until moved)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def _temporary_sibling(path: Path):
    """A temporary file name next to ``path``; removed again unless it was moved into place."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, _file_mode())
    try:
        yield Path(tmp)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)


def read_step(path: str | os.PathLike):
    """The single solid of a STEP file (mm), read back from disk."""
    import cadquery as cq

    try:
        shapes = cq.importers.importStep(str(path)).solids().vals()
    except ValueError as exc:
        raise FpdError(f"{path}: not a readable STEP file ({exc})") from exc
    if len(shapes) != 1:
        raise FpdError(f"{path}: holds {len(shapes)} solids, expected one")
    return shapes[0]


def step_product_names(path: str | os.PathLike) -> list[str]:
    """The names of the PRODUCT entities of a STEP file."""
    text = Path(path).read_text(encoding="ascii", errors="replace")
    return re.findall(r"PRODUCT\('((?:[^']|'')*)'", text)


def planar_faces(solid, axis: str, level_mm: float, tol_mm: float = 1e-4) -> list[tuple]:
    """Centres (mm) of the planar faces normal to ``axis`` ('x', 'y', 'z') at ``axis = level_mm``."""
    i = "xyz".index(axis)
    out = []
    for face in solid.Faces():
        if face.geomType() != "PLANE":
            continue
        normal = face.normalAt().toTuple()
        if abs(abs(normal[i]) - 1.0) > 1e-9:
            continue
        centre = face.Center().toTuple()
        if abs(centre[i] - level_mm) <= tol_mm:
            out.append(centre)
    return sorted(out)


def cylinders(solid, axis: str, radius_mm: float, tol_mm: float = 1e-4) -> list[tuple]:
    """A point on the axis (mm) of each cylindrical face along ``axis`` with radius ``radius_mm``."""
    i = "xyz".index(axis)
    out = []
    for face in solid.Faces():
        if face.geomType() != "CYLINDER":
            continue
        cyl = face._geomAdaptor().Cylinder()
        direction = cyl.Axis().Direction()
        d = (direction.X(), direction.Y(), direction.Z())
        if abs(abs(d[i]) - 1.0) > 1e-9 or abs(cyl.Radius() - radius_mm) > tol_mm:
            continue
        loc = cyl.Location()
        out.append((loc.X(), loc.Y(), loc.Z()))
    return sorted(out)


def tessellate(solid, tolerance_mm: float, angular_tolerance: float = 0.2) -> dict:
    """The solid for a picture: ``{"vertices": (n, 3), "triangles": (m, 3), "edges": [(k, 3), ...]}``
    in mm: its triangles and its B-rep edges as polylines."""
    import numpy as np

    from OCP.BRep import BRep_Tool

    vertices, triangles = solid.tessellate(tolerance_mm, angular_tolerance)
    # seam edges close a periodic surface (a cylinder) on itself: not edges anyone sees
    seams = [e for f in solid.Faces() for e in f.Edges() if BRep_Tool.IsClosed_s(e.wrapped, f.wrapped)]
    edges = []
    for edge in solid.Edges():
        if any(edge.isSame(seam) for seam in seams):
            continue
        if edge.geomType() == "LINE":
            count = 2
        else:
            count = max(24, min(96, int(math.ceil(edge.Length() / max(tolerance_mm * 10, 1e-3)))))
        edges.append(np.array([v.toTuple() for v in edge.positions(np.linspace(0.0, 1.0, count))]))
    return {"vertices": np.array([v.toTuple() for v in vertices], dtype=float).reshape(-1, 3),
            "triangles": np.array(triangles, dtype=int).reshape(-1, 3), "edges": edges}


def clipped(solid, x_max_mm: float):
    """The part of ``solid`` at ``X <= x_max_mm`` (for a close-up picture)."""
    import cadquery as cq

    bb = solid.BoundingBox()
    if x_max_mm >= bb.xmax:
        return solid
    box = cq.Solid.makeBox(x_max_mm - bb.xmin + 1, bb.ylen + 2, bb.zlen + 2,
                           pnt=cq.Vector(bb.xmin - 1, bb.ymin - 1, bb.zmin - 1))
    return solid.intersect(box)


# ----------------------------------------------------------------- writing everything

def export(record: dict, step=None, stl=None, svg=None, png=None, drawing_png=None) -> dict[str, Path]:
    """Write the requested files for a design.json record; returns ``{kind: path}``.

    ``step``/``stl``: the solid; ``svg``/``drawing_png``: the dimensioned drawing; ``png``: a
    picture of the 3-D model. The record is checked first, every file is made in a temporary
    file beside its target and all are moved into place only when every one succeeded.
    """
    wanted = {k: Path(v) for k, v in (("step", step), ("stl", stl), ("svg", svg), ("png", png),
                                      ("drawing_png", drawing_png)) if v is not None}
    beam = resolve(record)
    if not wanted:
        return {}
    solid = build_solid(beam)
    return _write_all(beam, solid, wanted)


def write_cad_outputs(design: dict, out_dir: str | os.PathLike) -> dict[str, Path]:
    """The CAD outputs of ``optimize`` and ``evaluate`` in ``out_dir``.

    ``design`` is the design.json record (with its ``spec`` and ``design``). Writes
    ``<name>.step``, ``<name>-model.png`` (the 3-D picture), ``<name>-drawing.svg`` and
    ``<name>-drawing.png`` (the dimensioned drawing); returns ``{"step", "model_png",
    "drawing_svg", "drawing_png"}`` -> path.
    """
    beam = resolve(design)
    out_dir = Path(out_dir)
    stem = beam.file_stem
    wanted = {"step": out_dir / f"{stem}.step", "png": out_dir / f"{stem}-model.png",
              "svg": out_dir / f"{stem}-drawing.svg", "drawing_png": out_dir / f"{stem}-drawing.png"}
    written = _write_all(beam, build_solid(beam), wanted)
    names = {"step": "step", "png": "model_png", "svg": "drawing_svg", "drawing_png": "drawing_png"}
    return {names[k]: v for k, v in written.items()}


def _write_all(beam: BeamCad, solid, wanted: dict[str, Path]) -> dict[str, Path]:
    """Make every file in a temporary file beside its target; move them all into place only
    when all succeeded. The drawing is drawn once for both of its formats."""
    staged: list[tuple[Path, Path]] = []
    sheet = None
    try:
        for kind, target in wanted.items():
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
            os.close(fd)
            tmp = Path(tmp)
            staged.append((tmp, target))
            if kind == "step":
                _step_file(solid, tmp, beam.name)
            elif kind == "stl":
                _stl_file(solid, tmp)
            else:
                from designer.outputs import drawing

                if kind == "png":
                    tmp.write_bytes(drawing.figure_bytes(drawing.plot_model(model_meshes(beam, solid), beam), "png"))
                else:
                    sheet = sheet or drawing.plot_drawing(beam)
                    tmp.write_bytes(drawing.figure_bytes(sheet, "svg" if kind == "svg" else "png"))
        mode = _file_mode()
        for tmp, target in staged:
            os.chmod(tmp, mode)
            os.replace(tmp, target)
    finally:
        for tmp, _ in staged:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp)
    return dict(wanted)


def model_meshes(beam: BeamCad, solid) -> dict:
    """Meshes for the 3-D picture: the whole part, and a close-up of the clamp block and the
    gauge stations when they take up only part of a long beam."""
    size = max(beam.width, beam.height) / MM
    meshes = {"whole": tessellate(solid, tolerance_mm=max(0.02, size / 150))}
    last = beam.stations[-1] + beam.feature_length / 2
    reach = last + 0.75 * max(beam.width, beam.height)
    if beam.grooves is not None:  # do not cut through a load groove
        first = beam.grooves.positions[0] - beam.grooves.width
        reach = max(min(reach, first), (last + beam.grooves.positions[0]) / 2)
    if reach < 0.6 * beam.length:
        meshes["detail"] = tessellate(clipped(solid, reach / MM), tolerance_mm=max(0.01, size / 300))
    return meshes
