"""A rendered picture of the solid (matplotlib only): the tessellated part in orthographic
projection, shaded triangles painted far to near, and the solid's edges with hidden parts
removed against a depth buffer; the gauges are painted on their faces for orientation."""

from __future__ import annotations

import math

import numpy as np

from designer.outputs.part import MM, BeamCad, fmt_mm

BASE_COLOUR = np.array([0.72, 0.76, 0.82])   # anodised-aluminium grey-blue
EDGE_COLOUR = (0.12, 0.13, 0.16)
AMBIENT, KEY, HEAD = 0.30, 0.60, 0.20        # light shares: ambient, key light, head light
VIEW = (22.0, -62.0)                         # elevation and azimuth of the camera, degrees
DETAIL_VIEW = (26.0, -50.0)
CORNER_VIEW = (18.0, 62.0)                   # onto the cut through the middle and the pocket's end wall
GAUGE_COLOUR = (0.25, 0.50, 0.95)            # the gauges' backings, for orientation only
GAUGE_LIFT_MM = 0.02                         # drawn this far off their face
X_AXIS = np.array([1.0, 0.0, 0.0])
PIECES = 12                                  # triangles are split to 1/PIECES of the picture's size
EDGE_BUFFER_PIXELS = 1400                    # depth-buffer resolution along the picture's longer side
EDGE_DEPTH_TOLERANCE = 3.0                   # an edge within this many pixels of the nearest depth is seen
SPAN_SLACK = 0.05                            # pixels added to each side of a scan-line span
HIDDEN_SHARE = 0.1                           # a triangle nearest at fewer of its pixels is hidden
MIN_EDGE_RUN = 3                             # visible runs of an edge shorter than this (pixels) are noise


def _camera(elev: float, azim: float):
    """Unit vectors: towards the eye, screen right, screen up."""
    e, a = np.radians(elev), np.radians(azim)
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    right = np.cross([0.0, 0.0, 1.0], eye)
    right /= np.linalg.norm(right)
    return eye, right, np.cross(eye, right)


def _split_long(tri: np.ndarray, normal: np.ndarray, max_edge: float) -> tuple[np.ndarray, np.ndarray]:
    """Halve triangles (m, 3, 3) across their longest edge until no edge exceeds ``max_edge``,
    so that a depth sort by centroid orders them correctly against small neighbours; each half
    keeps its parent's ``normal`` (m, 3)."""
    done, done_n = [], []
    for _ in range(24):
        lengths = np.linalg.norm(tri[:, [1, 2, 0]] - tri, axis=2)
        k = lengths.argmax(axis=1)
        idx = np.arange(len(tri))
        big = lengths[idx, k] > max_edge
        done.append(tri[~big])
        done_n.append(normal[~big])
        tri, normal, k = tri[big], normal[big], k[big]
        if not len(tri):
            break
        idx = np.arange(len(tri))
        a, b, c = tri[idx, k], tri[idx, (k + 1) % 3], tri[idx, (k + 2) % 3]
        m = (a + b) / 2
        tri = np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])
        normal = np.concatenate([normal, normal])
    done.append(tri)
    done_n.append(normal)
    return np.concatenate(done), np.concatenate(done_n)


def _smooth_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """One normal per triangle: the mean of its vertices' area-weighted normals. Slivers of the
    tessellation, whose own normals are round-off, take their neighbours'; facets of a cylinder
    shade a little smoother."""
    tri = vertices[triangles]
    face = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])   # twice the area, outward
    per_vertex = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(per_vertex, triangles[:, k], face)
    per_vertex /= np.maximum(np.linalg.norm(per_vertex, axis=1), 1e-300)[:, None]
    n = per_vertex[triangles].sum(axis=1)
    return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]


def _resample(line: np.ndarray, step: float) -> np.ndarray:
    """Points along a polyline no farther apart than ``step``."""
    a, d = line[:-1], np.diff(line, axis=0)
    count = np.maximum(1, np.ceil(np.linalg.norm(d, axis=1) / step)).astype(int)
    seg = np.repeat(np.arange(len(d)), count)
    k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count) + 1   # 1 .. count per segment
    t = np.where(k == count[seg], 1.0, k * (1.0 / count[seg]))[:, None]
    return np.concatenate([line[:1], a[seg] + t * d[seg]])


def _zbuffer(xy: np.ndarray, depth: np.ndarray, lo: np.ndarray, pixel: float, shape: tuple,
             hidden: bool = False):
    """Nearest depth per pixel of projected triangles ``xy`` (m, 3, 2) with vertex depths (m, 3),
    by scan lines, all triangles at once. With ``hidden``, also which triangles cover pixels
    but are nearest at none of them."""
    zbuf = np.full(shape, -np.inf)
    p = (xy - lo) / pixel                                   # pixel units; pixel centres at i + 0.5
    x, y = p[..., 0], p[..., 1]
    # the depth plane of each triangle: z = a x + b y + c
    A = np.stack([x, y, np.ones_like(x)], axis=2)
    ok = np.abs(np.linalg.det(A)) > 1e-9
    index = np.flatnonzero(ok)
    depth_all = depth
    x, y, A, depth = x[ok], y[ok], A[ok], depth[ok]
    a, b, c = np.linalg.solve(A, depth[..., None])[..., 0].T
    # spans are widened by a hair so that triangles sharing an edge leave no pixel between them
    r0 = np.clip(np.ceil(y.min(axis=1) - 0.5 - SPAN_SLACK), 0, shape[0] - 1).astype(int)
    r1 = np.clip(np.floor(y.max(axis=1) - 0.5 + SPAN_SLACK), -1, shape[0] - 1).astype(int)
    count = np.maximum(r1 - r0 + 1, 0)
    tri = np.repeat(np.arange(len(x)), count)
    row = r0[tri] + np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    yc = row + 0.5
    left = np.full(len(row), np.inf)
    right = np.full(len(row), -np.inf)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        y0, y1, x0, x1 = y[tri, i], y[tri, j], x[tri, i], x[tri, j]
        lo_y, hi_y = np.minimum(y0, y1) - SPAN_SLACK, np.maximum(y0, y1) + SPAN_SLACK
        crosses = (yc >= lo_y) & (yc <= hi_y) & (y0 != y1)
        t = np.clip(np.where(crosses, (yc - y0) / np.where(y0 != y1, y1 - y0, 1.0), 0.0), 0.0, 1.0)
        xc = x0 + t * (x1 - x0)
        left = np.where(crosses, np.minimum(left, xc), left)
        right = np.where(crosses, np.maximum(right, xc), right)
    c0 = np.clip(np.ceil(left - 0.5 - SPAN_SLACK), 0, shape[1] - 1)
    c1 = np.clip(np.floor(right - 0.5 + SPAN_SLACK), -1, shape[1] - 1)
    width = np.where(np.isfinite(left), np.maximum(c1 - c0 + 1, 0), 0).astype(int)
    span = np.repeat(np.arange(len(row)), width)
    col = c0[span].astype(int) + np.arange(width.sum()) - np.repeat(np.cumsum(width) - width, width)
    r, t = row[span], tri[span]
    z = a[t] * (col + 0.5) + b[t] * (r + 0.5) + c[t]
    np.maximum.at(zbuf, (r, col), z)
    # a pixel centre exactly on an edge shared by two triangles can fall between them by
    # round-off: fill such pin holes (empty, with covered neighbours on two opposite sides)
    pad = np.pad(zbuf, 1, constant_values=-np.inf)
    left, right, down, up = pad[1:-1, :-2], pad[1:-1, 2:], pad[:-2, 1:-1], pad[2:, 1:-1]
    hole = ~np.isfinite(zbuf) & ((np.isfinite(left) & np.isfinite(right)) | (np.isfinite(down) & np.isfinite(up)))
    at = np.nonzero(hole)
    zbuf[at] = np.maximum(np.maximum(left[at], right[at]), np.maximum(down[at], up[at]))
    if not hidden:
        return zbuf
    won = z >= zbuf[r, col] - 1e-9 * (np.abs(z) + 1.0)
    covered = np.bincount(index[t], minlength=len(xy))
    owned = np.bincount(index[t[won]], minlength=len(xy))
    # nearest at almost none of its pixels: seen only through pin holes between other triangles
    behind = (covered > 0) & (owned < HIDDEN_SHARE * covered)
    # a sliver that covers no pixel centre is judged at its centroid
    centre = (xy - lo).mean(axis=1) / pixel
    ci = np.clip(np.floor(centre).astype(int), 0, np.array(shape)[::-1] - 1)
    behind |= (covered == 0) & (depth_all.mean(axis=1) + EDGE_DEPTH_TOLERANCE * pixel < zbuf[ci[:, 1], ci[:, 0]])
    return zbuf, behind


def _gauge_quads(beam: BeamCad) -> tuple[np.ndarray, np.ndarray]:
    """The gauges' backings as quads (k, 4, 3) in mm on their faces, and their outward normals."""
    normals = {"+z": (0, 0, 1), "-z": (0, 0, -1), "+y": (0, 1, 0), "-y": (0, -1, 0)}
    across = {"+z": (0, 1, 0), "-z": (0, 1, 0), "+y": (0, 0, 1), "-y": (0, 0, 1)}
    quads, out = [], []
    gl, gw = beam.gauge_length / MM / 2, beam.gauge_width / MM / 2
    for face in beam.faces:
        n, a = np.array(normals[face], float), np.array(across[face], float)
        half = (beam.height if face.endswith("z") else beam.width) / 2
        level = (half - (beam.pocket_depth if beam.feature == "pocket" else 0.0)) / MM + GAUGE_LIFT_MM
        for d in beam.stations:
            c = np.array([d / MM, 0.0, 0.0]) + level * n
            quads.append([c - gl * X_AXIS - gw * a, c + gl * X_AXIS - gw * a, c + gl * X_AXIS + gw * a,
                          c - gl * X_AXIS + gw * a])
            out.append(n)
    return np.array(quads, float).reshape(-1, 4, 3), np.array(out, float).reshape(-1, 3)


def _render(ax, mesh: dict, view: tuple, pieces: int, gauges=None) -> None:
    """Shaded triangles facing the camera, painted far to near, and the solid's visible edges
    (hidden ones removed against a depth buffer), in orthographic projection on a 2-D axes.
    ``gauges``: optional quads and normals drawn in the gauge colour."""
    from matplotlib.collections import LineCollection, PolyCollection

    eye, right, up = _camera(*view)
    to2d = np.column_stack([right, up])
    v = mesh["vertices"]
    tri = v[mesh["triangles"]]
    xy_all = v @ to2d
    lo, hi = xy_all.min(axis=0), xy_all.max(axis=0)
    span = float((hi - lo).max())

    n = _smooth_normals(v, mesh["triangles"])
    front = n @ eye > 0                         # faces turned away are hidden anyway
    # short triangles, so that sorting them by the depth of their centroids paints them right
    tri, n = _split_long(tri[front], n[front], span / pieces)
    # a depth buffer finds the triangles hidden behind others (dropped: painted out of order
    # they would show through) and which parts of the edges are seen
    pixel = span / EDGE_BUFFER_PIXELS
    shape = (int(math.ceil((hi[1] - lo[1]) / pixel)) + 2, int(math.ceil((hi[0] - lo[0]) / pixel)) + 2)
    zbuf, behind = _zbuffer(tri @ to2d, tri @ eye, lo, pixel, shape, hidden=True)
    tri, n = tri[~behind], n[~behind]
    segments = []
    for line in mesh["edges"]:
        if len(line) < 2:
            continue
        pts = _resample(line, pixel)
        mid = (pts[:-1] + pts[1:]) / 2
        ij = np.floor((mid @ to2d - lo) / pixel).astype(int)
        ij[:, 0] = np.clip(ij[:, 0], 0, shape[1] - 1)
        ij[:, 1] = np.clip(ij[:, 1], 0, shape[0] - 1)
        seen = mid @ eye + EDGE_DEPTH_TOLERANCE * pixel >= zbuf[ij[:, 1], ij[:, 0]]
        p2 = pts @ to2d
        # one polyline per run of visible segments
        flags = np.concatenate([[False], seen, [False]]).astype(int)
        starts = np.flatnonzero(np.diff(flags) == 1)
        stops = np.flatnonzero(np.diff(flags) == -1)
        segments += [p2[a:b + 1] for a, b in zip(starts, stops) if b - a >= MIN_EDGE_RUN]
    key = eye + 0.7 * up - 0.5 * right
    key /= np.linalg.norm(key)
    shade = AMBIENT + KEY * np.clip(n @ key, 0, 1) + HEAD * np.clip(n @ eye, 0, 1)
    colours = np.clip(BASE_COLOUR[None, :] * shade[:, None], 0, 1)
    order = np.argsort((tri @ eye).mean(axis=1), kind="stable")
    ax.add_collection(PolyCollection((tri @ to2d)[order], facecolors=colours[order],
                                     edgecolors=colours[order], linewidths=0.6))
    # gauges lie on their faces: painted where the depth buffer sees them, as an image
    if gauges is not None and len(gauges[0]):
        quads, quad_normals = gauges
        facing = quad_normals @ eye > 0
        quads, quad_normals = quads[facing], quad_normals[facing]
        if len(quads):
            halves = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
            gz = _zbuffer(halves @ to2d, halves @ eye, lo, pixel, shape)
            seen = np.isfinite(gz) & (gz + EDGE_DEPTH_TOLERANCE * pixel >= zbuf)
            light = AMBIENT + KEY * np.clip(quad_normals @ key, 0, 1).mean() + HEAD * (quad_normals @ eye).mean()
            image = np.zeros(shape + (4,))
            image[..., :3] = np.clip(np.array(GAUGE_COLOUR) * light, 0, 1)
            image[..., 3] = seen
            ax.imshow(image, origin="lower", interpolation="bilinear", zorder=2.5,
                      extent=(lo[0], lo[0] + shape[1] * pixel, lo[1], lo[1] + shape[0] * pixel))
    ax.add_collection(LineCollection(segments, colors=[EDGE_COLOUR], linewidths=0.6, capstyle="round", zorder=3))
    pad = 0.04 * span
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()


def _projected_aspect(mesh: dict, view: tuple) -> float:
    """Height over width of the picture of ``mesh`` seen from ``view``."""
    eye, right, up = _camera(*view)
    xy = mesh["vertices"] @ np.column_stack([right, up])
    span = np.ptp(xy, axis=0)
    return float(span[1] / span[0])


def plot_model(meshes: dict, beam: BeamCad, ax=None):
    """A shaded picture of the solid; below it a close-up of the clamp block and gauge stations
    and one of a pocket's floor radius, when ``meshes`` has them. ``meshes``: ``{"whole": mesh
    [, "detail": mesh][, "corner": mesh]}`` from ``cad.model_meshes``."""
    from matplotlib.figure import Figure

    detail, corner = meshes.get("detail"), meshes.get("corner")
    ax_detail = ax_corner = None
    if ax is None:
        width = 11.0
        h_whole = min(max(width * _projected_aspect(meshes["whole"], VIEW), 1.6), 6.0)
        # the lower row: the close-up of the stations (0.8 of the width, or 0.6 beside the corner)
        share = 0.6 if corner is not None else 0.8
        h_detail = min(max(width * share * _projected_aspect(detail, DETAIL_VIEW), 2.0), 5.0) if detail else 0.0
        if corner is not None:
            h_detail = max(h_detail, min(max(width * 0.3 * _projected_aspect(corner, CORNER_VIEW), 2.0), 3.5))
        lower = detail is not None or corner is not None
        title, gap = 0.45, 0.35 if lower else 0.0
        height = title + h_whole + gap + h_detail
        fig = Figure(figsize=(width, height))
        ax = fig.add_axes((0.02, (h_detail + gap) / height, 0.96, h_whole / height))
        row = h_detail / height * 0.9  # room for the panels' titles
        if detail is not None:
            ax_detail = fig.add_axes((0.02, 0.0, 0.6, row) if corner is not None else (0.1, 0.0, 0.8, row))
        if corner is not None:
            ax_corner = fig.add_axes((0.66, 0.0, 0.32, row) if detail is not None else (0.3, 0.0, 0.4, row))
    fig = ax.figure
    gauges = _gauge_quads(beam)
    _render(ax, meshes["whole"], VIEW, pieces=PIECES, gauges=gauges)
    title = (f"{beam.name}: {beam.material} {beam.section_label()}, free length {fmt_mm(beam.length)} mm, "
             f"stations {', '.join(fmt_mm(d) for d in beam.stations)} mm from the clamp face")
    fig.suptitle(title, fontsize=10, y=0.995, va="top")
    if ax_detail is not None:
        _render(ax_detail, detail, DETAIL_VIEW, pieces=PIECES, gauges=gauges)
        cut = float(detail["vertices"][:, 0].max())
        ax_detail.set_title(f"clamp block and gauge stations (cut at {cut:.4g} mm; gauges shown blue)", fontsize=9)
    if ax_corner is not None:
        _render(ax_corner, corner, CORNER_VIEW, pieces=PIECES)
        what = "slot" if beam.section == "rectangle" else "flat"
        ax_corner.set_title(f"R{fmt_mm(beam.floor_radius)} floor radius at the {what}'s end\n"
                            "(first station, cut through the middle)", fontsize=9)
    return fig
