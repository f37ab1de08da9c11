"""Meshes of the solid for the 3-D picture: triangles and B-rep edges, in millimetres.

cadquery and OCP are imported only inside the functions that need them.
"""

from __future__ import annotations

import math

from designer.outputs.part import MM, BeamCad


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
