"""A design at the corners of its tolerances (docs/model.md §14).

The section's sizes and the feature's depth (or hole) are each built anywhere within their
deviation ± t (``spec.tolerances``). Every limit a built part must meet (CORNER_LIMITS) is
judged at each corner: every combination of each toleranced size at its nominal - t and + t.
The geometry rules, the corrections' fitted domain and the accuracy targets stay judged on the
nominal design: they are rules of the drawing, and each built sensor's own calibration absorbs
its k (the report gives how far k moves across the corners).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, fields, replace

import numpy as np

from designer.model import grooves
from designer.model.analysis import analyse
from designer.model.limits import Limit, limits
from designer.model.sections import Geometry, no_beam, wire_channel

# The limits of docs/model.md §4 a built part must meet whatever its sizes within tolerance.
CORNER_LIMITS = ("stress_root", "stress_feature", "gauge_strain", "min_signal_snr", "adc_range", "fatigue_feature",
                 "deflection", "natural_frequency", *grooves.LIMIT_NAMES)
# Of those, the limits worst where the part is strongest: every section size at its largest and
# the feature at its smallest (the least strain, so the least signal); the others are worst where
# it is weakest (``searched_corners``).
STRONG_CORNER_LIMITS = ("min_signal_snr",)
# Which deviation each toleranced size of a Geometry takes, and the least it is at a corner (m): a
# pocket or hole smaller than its deviation is, at its least, not cut at all; a section size at
# least 1 µm (a deviation as large as the size leaves no beam).
PART = {"width": "section", "height": "section", "diameter": "section", "wall": "section",
        "depth": "feature", "hole": "feature"}
LEAST = {"section": 1e-6, "feature": 0.0}
# A corner at which the model gives no number (a pocket through the section) breaks this limit.
UNBUILDABLE = "corner_unbuildable"
# A corner is written as where each toleranced size is, e.g. "D min, p max" (a thin bar, a deep flat).
SYMBOLS = {"width": "b", "height": "h", "diameter": "D", "wall": "t", "depth": "p", "hole": "d_h"}


def toleranced(g: Geometry) -> list[tuple[str, str]]:
    """``(field, part)`` of each toleranced size of ``g``: the section's sizes, then the feature's."""
    names = {"rectangle": ["width", "height"], "round": ["diameter"], "tube": ["diameter", "wall"]}[g.section]
    names += {"pocket": ["depth"], "hole": ["hole"]}.get(g.feature, [])
    return [(name, PART[name]) for name in names]


def searched_corners(parts) -> list[tuple[bool, tuple[float, ...]]]:
    """``(weak, signs)`` of the corners the search's NLP holds the limits at, for toleranced sizes
    of ``parts`` ("section" or "feature" each): the section's sizes at their least for the
    limits worst where the part is weakest (``weak``) and at their greatest for the others
    (STRONG_CORNER_LIMITS), the feature's depth or hole at both ends for either: a thicker or
    wider section is stiffer, but a deeper pocket may bring its floor, where the gauge is, nearer
    the neutral axis. Every corner is checked again on the rounded design."""
    feature = [k for k, part in enumerate(parts) if part == "feature"]
    out = []
    for weak in (True, False):
        for ends in itertools.product((-1.0, 1.0), repeat=len(feature)):
            signs = [-1.0 if weak else 1.0] * len(parts)
            for k, e in zip(feature, ends):
                signs[k] = e
            out.append((weak, tuple(signs)))
    return out


def signs(g: Geometry) -> np.ndarray:
    """Every corner as a row of -1/+1, one column per ``toleranced`` size."""
    return np.array(list(itertools.product((-1.0, 1.0), repeat=len(toleranced(g)))))


def corners(g: Geometry, tol, cad) -> Geometry:
    """``g`` (numbers, or arrays of n designs) at its nominal sizes and then at each corner: every
    array of n becomes one of n (1 + c), the nominal designs first, then each corner's n. The wire
    channel follows the built pocket's depth, as the CAD cuts it."""
    corner = signs(g)
    c = len(corner)
    n = _count(g)
    out = {}
    for f in fields(g):  # the stations and every array, once for the nominal designs and once a corner
        v = getattr(g, f.name)
        if isinstance(v, tuple):
            out[f.name] = tuple(_tiled(x, n, c) for x in v)
        elif isinstance(v, np.ndarray):
            out[f.name] = _tiled(v, n, c)
    for j, (name, part) in enumerate(toleranced(g)):
        nominal = np.broadcast_to(np.asarray(getattr(g, name), dtype=float), (n,))
        dev = tol.deviation(nominal, part)
        out[name] = np.concatenate([nominal] + [np.maximum(nominal + s * dev, LEAST[part]) for s in corner[:, j]])
    built = replace(g, **out)
    width, depth = wire_channel(cad, g.section, g.feature, built.depth, g.pocket_width)
    return replace(built, channel_width=width, channel_depth=depth)


def _count(g: Geometry) -> int:
    sizes = [np.size(x) for x in (*g.stations, *(getattr(g, f.name) for f in fields(g))) if isinstance(x, np.ndarray)]
    return max(sizes, default=1)


def _tiled(v, n: int, c: int) -> np.ndarray:
    """``v`` (a number or n of them) repeated for the nominal designs and each of ``c`` corners."""
    return np.tile(np.broadcast_to(np.asarray(v, dtype=float), (n,)), c + 1)


def worst(g: Geometry, m, spec, adjust=None) -> np.ndarray:
    """For each of ``g``'s n designs, the largest normalised value of CORNER_LIMITS over its
    tolerance corners (not its nominal design); -inf (to broadcast) when the spec has none."""
    rows = _worst_rows(g, m, spec, adjust)
    return rows.max(axis=0) if len(rows) else np.array(-np.inf)


def worst_each(g: Geometry, m, spec, adjust=None) -> np.ndarray:
    """For one design ``g`` (numbers), each CORNER_LIMITS limit's largest normalised value over
    its tolerance corners, as an array (empty when the spec has no tolerances)."""
    return _worst_rows(g, m, spec, adjust)[:, 0]


def _worst_rows(g: Geometry, m, spec, adjust) -> np.ndarray:
    """Each CORNER_LIMITS limit's largest normalised value over the corners, one row a limit and
    one column a design of ``g``; 1 where the model gives no number, as the UNBUILDABLE limit says."""
    if not spec.tolerances.active:
        return np.zeros((0, 1))
    n = _count(g)
    _, lims, count = _at_corners(corners(g, spec.tolerances, spec.cad), m, spec, adjust)
    rows = np.array([np.broadcast_to(np.asarray(lim.normalised, dtype=float), (count,)).reshape(-1, n)[1:].max(axis=0)
                     for lim in lims]).reshape(-1, n)
    return np.where(np.isnan(rows), 1.0, rows)


def _at_corners(built: Geometry, m, spec, adjust):
    """``(analysis, CORNER_LIMITS limits, how many designs)`` of ``built`` (``corners``' arrays);
    a limit's value is NaN, as the model gives none, where the design is no beam (``sections.no_beam``)."""
    with np.errstate(all="ignore"):
        a = analyse(built, m, spec, adjust=adjust)
        count = _count(built)
        lost = np.broadcast_to(no_beam(built), (count,))
        lims = [lim for lim in limits(built, a, m, spec, include_targets=False, rules=False)
                if lim.name in CORNER_LIMITS]
        if lost.any():
            lims = [replace(lim, value=np.where(lost, np.nan, np.broadcast_to(np.asarray(lim.value, dtype=float),
                                                                              (count,))))
                    for lim in lims]
        return a, lims, count


@dataclass(frozen=True)
class CornerCheck:
    """One design at its tolerance corners. ``limits``: each CORNER_LIMITS limit at its worst corner
    (named as the limit); ``corners``: that corner, as ``label`` writes it; ``deviations``:
    ``(field, ± m)``; ``sensitivity``: the least and the greatest k_i / k_i(nominal) - 1 over the
    stations and the corners; ``count``: how many corners."""

    limits: tuple[Limit, ...]
    corners: tuple[str, ...]
    deviations: tuple
    sensitivity: tuple[float, float]
    count: int

    def records(self) -> list[dict]:
        return [{**lim.record(), "corner": corner} for lim, corner in zip(self.limits, self.corners)]


def check(g: Geometry, m, spec, adjust=None) -> CornerCheck | None:
    """``g`` (numbers) at each of its tolerance corners; None when the spec has no tolerances."""
    tol = spec.tolerances
    if not tol.active:
        return None
    names = [name for name, _ in toleranced(g)]
    corner = signs(g)
    a, lims, _ = _at_corners(corners(g, tol, spec.cad), m, spec, adjust)
    k = np.array([np.broadcast_to(np.asarray(x, dtype=float), (len(corner) + 1,)) for x in a.sensitivities])
    out, where, lost = [], [], None
    for lim in lims:
        values = np.broadcast_to(np.asarray(lim.normalised, dtype=float), (len(corner) + 1,))
        if np.isnan(values[1:]).any():
            lost = 1 + int(np.flatnonzero(np.isnan(values[1:]))[0]) if lost is None else lost
        if not np.isfinite(values[1:]).any() or not np.isfinite(values[0]):
            continue
        i = 1 + int(np.nanargmax(np.where(np.isfinite(values[1:]), values[1:], -np.inf)))
        out.append(Limit(lim.name, float(_at(lim.value, i)), float(_at(lim.limit, i)), lim.upper,
                         None if lim.scale is None else float(_at(lim.scale, i)), lim.unit,
                         None if lim.rating is None else float(_at(lim.rating, i))))
        where.append(label(names, corner[i - 1]))
    if lost is not None:  # a corner the model cannot evaluate: the part is not a beam there
        out.append(Limit(UNBUILDABLE, 1.0, 0.0, scale=1.0))
        where.append(label(names, corner[lost - 1]))
    deviations = tuple((name, float(tol.deviation(getattr(g, name), part))) for name, part in toleranced(g))
    ratio = k[:, 1:] / k[:, :1] - 1
    ratio = ratio[np.isfinite(ratio)] if np.isfinite(ratio).any() else np.zeros(1)
    return CornerCheck(tuple(out), tuple(where), deviations, (float(ratio.min()), float(ratio.max())),
                       len(corner))


def _at(value, i: int):
    return np.asarray(value, dtype=float).ravel()[i] if np.size(value) > 1 else value


def label(names, sign) -> str:
    """A corner as ``D min, p max``."""
    return ", ".join(f"{SYMBOLS[name]} {'max' if s > 0 else 'min'}" for name, s in zip(names, sign))
