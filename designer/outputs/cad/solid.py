"""The solid: a designed beam as one machinable cadquery ``Solid`` in millimetres.

Built in the CAD frame of SPEC.md (origin on the beam's axis at the clamp face, ``+X`` to the
free end, the clamp block at ``X < 0``, ``Z`` the load direction, ``Y`` across). Besides the
section it carries the clamp block with its bolt holes, the feature of MODEL.md section 1 at
every station on both bending faces (all four when biaxial): a slot pocket with corner radii
equal to the end mill's radius on a rectangle, a flat on a round or tube, a through-hole along
``Y`` for ``hole``. Pockets and flats are cut as the tool leaves them: a slot is the path of a
bull-nose end mill plunged along ``Z`` and moved along the slot, so its floor meets its walls all
round in the tool's corner radius (``floor_radius``); a flat is cut with the end of the same kind
of mill moved across the bar (along ``Y``), so its floor meets its two end walls in that radius
and runs out on the round at its sides. Then the wire channels (through the nearer pockets,
ending in a half circle of their own width centred on the clamp face, as the cutter leaves them)
and the load grooves. cadquery is imported only inside ``build_solid``.
"""

from __future__ import annotations

from designer.errors import FpdError
from designer.outputs.part import MM, BeamCad

# Cutting tools run this far past the surfaces they break, so that no faces coincide (mm).
TOOL_OVERRUN_MM = 1.0


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

    if beam.block_is_bar:
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
        rf = beam.floor_radius * s
        if beam.section == "rectangle":
            r = beam.corner_radius * s
            sketch = cq.Sketch()
            if abs(2 * r - wp) < 1e-9:
                sketch = sketch.slot(lp - wp, wp)
            else:
                sketch = sketch.rect(lp, wp).vertices().fillet(r)
            pocket = cq.Workplane("XY", origin=(0, 0, half - p)).placeSketch(sketch).extrude(p + E)
            # the tool's corner radius all round the floor
            pocket = (pocket.faces("<Z").edges().fillet(rf) if rf > 0 else pocket).val()
        else:
            pocket = cq.Workplane("XY").box(lp, 2 * R + 2 * E, p + E, centered=(True, True, False))
            pocket = pocket.translate(V(0, 0, R - p))
            # the tool's corner radius where the floor meets the two end walls
            pocket = (pocket.faces("<Z").edges("|Y").fillet(rf) if rf > 0 else pocket).val()
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
        for xg in beam.grooves.positions:
            tools.append(_groove_tool(beam, xg * s, W, H))

    shape = base.cut(*tools).clean() if tools else base
    solids = shape.Solids()
    if len(solids) != 1 or not solids[0].isValid():
        raise FpdError(f"the CAD kernel did not produce one valid solid for {beam.name!r} "
                       f"({len(solids)} solids); please report this design")
    return solids[0]


def _groove_tool(beam: BeamCad, x: float, W: float, H: float):
    """The cutter of one load groove at ``x`` (mm): a full-radius groove, its root a half circle of
    half the groove's width (the U-notch whose K_t the beam model takes, docs/model.md §4, as a
    full-radius grooving insert cuts it), ``depth`` below the surface: all around a round bar or
    tube (a torus and the ring above its middle), across every face of a rectangle (a cylinder and
    the slab above its axis on each, crossing at the edges). A groove shallower than its radius is
    the circular arc alone."""
    import cadquery as cq

    V = cq.Vector
    s, E = 1.0 / MM, TOOL_OVERRUN_MM
    r, depth = beam.grooves.width * s / 2, beam.grooves.depth * s
    if beam.section != "rectangle":
        R = W / 2
        centre = R - depth + r      # the root circle's centre, from the axis
        ring = cq.Solid.makeCylinder(R + E, 2 * r, pnt=V(x - r, 0, 0), dir=V(1, 0, 0))
        if centre > 0:
            ring = ring.cut(cq.Solid.makeCylinder(centre, 2 * r, pnt=V(x - r, 0, 0), dir=V(1, 0, 0)))
        return ring.fuse(cq.Solid.makeTorus(centre, r, pnt=V(x, 0, 0), dir=V(1, 0, 0))).clean()
    parts = []
    for axis, half, span in (("z", H / 2, W), ("y", W / 2, H)):
        for sign in (1.0, -1.0):
            centre = sign * (half - depth + r)
            rise = half + E - (half - depth + r)          # from the root circle's centre out past the face
            if axis == "z":
                root = cq.Solid.makeCylinder(r, span + 2 * E, pnt=V(x, -span / 2 - E, centre), dir=V(0, 1, 0))
                z0 = centre if sign > 0 else centre - rise
                slab = cq.Solid.makeBox(2 * r, span + 2 * E, rise, pnt=V(x - r, -span / 2 - E, z0))
            else:
                root = cq.Solid.makeCylinder(r, span + 2 * E, pnt=V(x, centre, -span / 2 - E), dir=V(0, 0, 1))
                y0 = centre if sign > 0 else centre - rise
                slab = cq.Solid.makeBox(2 * r, rise, span + 2 * E, pnt=V(x - r, y0, -span / 2 - E))
            parts.append(root.fuse(slab))
    tool = parts[0]
    for part in parts[1:]:
        tool = tool.fuse(part)
    return tool.clean()
