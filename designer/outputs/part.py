"""The machined part: one designed beam as the CAD model and the drawing both see it.

``BeamCad`` holds every size of the part in SI units with every CAD default already picked
(``designer.outputs.cad.resolve`` makes it from a design.json record). The CAD frame is the
one of SPEC.md: origin on the beam's axis at the clamp face, ``+X`` along the beam to the free
end, the clamp block at ``X < 0``, ``Z`` the load direction, ``Y`` across. Sizes on files and
drawings are millimetres (``MM``, ``fmt_mm``).

Nothing here imports cadquery or matplotlib; ``designer.outputs.cad`` (the solid and its
files) and ``designer.outputs.drawing`` (the sheet and the picture) both build on it.
"""

from __future__ import annotations

import re
import unicodedata
from dataclasses import dataclass

from designer import model
from designer.model.sections import flat_half_chord

MM = 1e-3  # metres per millimetre; CAD files are in millimetres (SPEC.md, the CAD frame)

FACES = ("+z", "-z", "+y", "-y")

#: The longest file name made of a design's name, in characters: the names of its files
#: (``<name>-drawing.png``, the longest) and their temporary copies stay far inside the 255
#: bytes a file name may have, whatever the length of the spec's free-text ``name``.
MAX_FILE_STEM = 100


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
    floor_radius: float        # the end mill's own corner radius: pocket and flat floors meet walls in it
    gauge_name: str
    gauge_length: float
    gauge_width: float
    clamp: Clamp
    channels: Channels | None
    grooves: Grooves | None
    tool: str = ""             # the end mill that cuts the pockets or flats ("end mill Ø3 R0.2 mm"); "" if none
    stock: str = ""            # the stock item the section is cut from ("round bar Ø10 mm (EN 754-3)"); "" if none
    tolerances: str = ""       # the tolerances the design was checked at ("ISO 2768-m"); "" if none
    tolerances_hold: bool = False   # whether every limit holds at each of their corners

    @property
    def radius(self) -> float:
        """R = D/2 of a round or tube."""
        return self.width / 2

    @property
    def corner_radius(self) -> float:
        """A slot's corner radius in plan view: the end mill's radius."""
        return self.end_mill / 2 if self.end_mill else 0.0

    @property
    def geometry(self) -> model.Geometry:
        """The beam as the sensor model describes it (docs/model.md §1)."""
        rectangle = self.section == "rectangle"
        return model.Geometry(section=self.section, feature=self.feature, stations=self.stations,
                              length=self.length, width=self.width if rectangle else None,
                              height=self.height if rectangle else None,
                              diameter=None if rectangle else self.width, wall=self.wall,
                              depth=self.pocket_depth, hole=self.hole_diameter, pocket_length=self.pocket_length,
                              pocket_width=self.pocket_width, gauge_length=self.gauge_length, axes=self.axes,
                              floor_radius=self.floor_radius if self.feature == "pocket" else 0.0,
                              plan_radius=self.corner_radius if self.feature == "pocket" and rectangle else 0.0,
                              channel_width=self.channels.width if self.channels else 0.0,
                              channel_depth=self.channels.depth if self.channels else 0.0)

    @property
    def feature_length(self) -> float:
        """l_f of MODEL.md section 1: pocket length, hole diameter, or the gauge's length."""
        return model.feature_length(self.feature, self.pocket_length, self.hole_diameter, self.gauge_length)

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
        return flat_half_chord(self.radius, self.pocket_depth)

    @property
    def block_is_bar(self) -> bool:
        """True when the clamp block is simply the bar continued (no edge at the clamp face)."""
        return self.section == "rectangle" and abs(self.clamp.width - self.width) < 1e-12

    @property
    def overall_length(self) -> float:
        return self.clamp.length + self.length

    @property
    def file_stem(self) -> str:
        """The name made safe for file names: plain ASCII, at most ``MAX_FILE_STEM`` characters."""
        stem = re.sub(r"[^A-Za-z0-9._-]+", "-", ascii_text(self.name)).strip("-.")
        return stem[:MAX_FILE_STEM].rstrip("-.") or "design"

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


def ascii_text(text: str) -> str:
    """``text`` with accents dropped and anything else outside ASCII removed."""
    return unicodedata.normalize("NFKD", str(text)).encode("ascii", "ignore").decode("ascii")
