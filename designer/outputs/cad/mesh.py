"""Meshes of the solid for the 3-D picture: triangles and B-rep edges, in millimetres.

cadquery and OCP are imported only inside the functions that need them.
"""

from __future__ import annotations

import math

from designer.outputs.part import MM, BeamCad

# The close-up of a floor radius spans this many radii either side of the pocket's end wall
# (or 1.2 pocket depths, when less), and at least CORNER_WINDOW_MIN_RADII.
CORNER_WINDOW_RADII = 8.0
CORNER_WINDOW_MIN_RADII = 5.0


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


def corner_window(beam: BeamCad) -> tuple:
    """The box (mm, ``((x0, x1), (y0, y1), (z0, z1))``) of the close-up of a floor radius: the
    clamp-side end of the first pocket or flat on the +Z face, the half ``Y <= 0`` (cut through
    the middle, so that the cut shows the radius in profile)."""
    s = 1 / MM
    xe = (beam.stations[0] - beam.pocket_length / 2) * s
    p, rf, half = beam.pocket_depth * s, beam.floor_radius * s, beam.height / 2 * s
    a = max(min(1.2 * p, CORNER_WINDOW_RADII * rf), CORNER_WINDOW_MIN_RADII * rf)
    return (xe - a, xe + a), (-beam.width / 2 * s - 1, 0.0), (half - p - 0.6 * a, half + 1)


def clipped_box(solid, box):
    """The part of ``solid`` inside ``box`` (mm)."""
    import cadquery as cq

    (x0, x1), (y0, y1), (z0, z1) = box
    return solid.intersect(cq.Solid.makeBox(x1 - x0, y1 - y0, z1 - z0, pnt=cq.Vector(x0, y0, z0)))


def model_meshes(beam: BeamCad, solid) -> dict:
    """Meshes for the 3-D picture: the whole part, a close-up of the clamp block and the gauge
    stations when they take up only part of a long beam, and a close-up of a pocket's floor
    radius (``corner``) when the part has pockets or flats."""
    size = max(beam.width, beam.height) / MM
    meshes = {"whole": tessellate(solid, tolerance_mm=max(0.02, size / 150))}
    last = beam.stations[-1] + beam.feature_length / 2
    reach = last + 0.75 * max(beam.width, beam.height)
    if beam.grooves is not None:  # do not cut through a load groove
        first = beam.grooves.positions[0] - beam.grooves.width
        reach = max(min(reach, first), (last + beam.grooves.positions[0]) / 2)
    if reach < 0.6 * beam.length:
        meshes["detail"] = tessellate(clipped(solid, reach / MM), tolerance_mm=max(0.01, size / 300))
    if beam.feature == "pocket" and beam.floor_radius > 0:
        meshes["corner"] = tessellate(clipped_box(solid, corner_window(beam)),
                                      tolerance_mm=beam.floor_radius / MM / 40, angular_tolerance=0.1)
    return meshes
