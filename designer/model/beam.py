"""Euler-Bernoulli beam quantities of a cantilever with ``EI(s)`` piecewise (docs/model.md §4)."""

from __future__ import annotations

import math

from designer.model.ops import NUMERIC, Ops
from designer.model.sections import Geometry, SectionProperties, channel_inertia, channel_spans

# First root of 1 + cos(b) cosh(b) = 0 for a clamped-free beam (Euler-Bernoulli).
CLAMPED_FREE_ROOT = 1.8751040687
# A deflection above this fraction of the free length leaves small-deflection theory.
LARGE_DEFLECTION_RATIO = 0.10


def _moment_arm_integral(s, x, ell):
    """Antiderivative of (x - s)(ell - s) in s."""
    return x * ell * s - (x + ell) * s ** 2 / 2 + s ** 3 / 3


def tip_deflection(g: Geometry, sp: SectionProperties, E, force, x):
    """Free-end deflection for ``force`` at ``x`` with EI piecewise (unit-load method).

    ``w(ell) = F * integral_0^x (x - s)(ell - s) / EI(s) ds`` equals ``w(x) + theta(x)(ell - x)``;
    each feature's reduced section acts over its span (``Geometry.reduced_spans``).
    """
    ell = g.length
    plain = ((ell - x) * x ** 2 / 2 + x ** 3 / 3) / (E * sp.I)
    extra = 1 / (E * sp.I_s) - 1 / (E * sp.I)
    for a, b in g.reduced_spans:
        plain = plain + extra * (_moment_arm_integral(b, x, ell) - _moment_arm_integral(a, x, ell))
    return force * plain


def channel_deflection(g: Geometry, sp: SectionProperties, E, force, x, ops: Ops = NUMERIC):
    """What the wire channels add to the free-end deflection: ``EI`` falls to ``E (I - I_c)``
    (``sections.channel_inertia``) over ``sections.channel_spans`` (shortened as the 3-D solves
    find them), by the same unit-load integral as ``tip_deflection``; 0 without channels."""
    spans = channel_spans(g, ops)
    if not spans:
        return 0.0
    ell = g.length
    extra = 1 / (E * (sp.I - channel_inertia(g, ops))) - 1 / (E * sp.I)
    total = 0.0
    for a, b in spans:
        total = total + _moment_arm_integral(b, x, ell) - _moment_arm_integral(a, x, ell)
    return force * extra * total


def rigidity_segments(g: Geometry, sp: SectionProperties, E: float) -> list[tuple[float, float, float]]:
    """``EI(s)`` as ``(s0, s1, EI)`` segments from the clamp to the free end (numbers): the
    reduced section over each span of ``Geometry.reduced_spans``, the section less its wire
    channels over ``sections.channel_spans``, the plain section elsewhere; clipped to the beam."""
    ell = float(g.length)
    EI = E * float(sp.I)
    features = [(float(a), float(b)) for a, b in g.reduced_spans]
    channels = [(float(a), float(b)) for a, b in channel_spans(g)]
    EI_c = E * (float(sp.I) - float(channel_inertia(g))) if channels else EI
    cuts = sorted({0.0, ell, *(min(max(v, 0.0), ell) for span in features + channels for v in span)})
    segs: list[tuple[float, float, float]] = []
    for s0, s1 in zip(cuts, cuts[1:]):
        mid = (s0 + s1) / 2
        rigidity = (E * float(sp.I_s) if any(a <= mid <= b for a, b in features)
                    else EI_c if any(a <= mid <= b for a, b in channels) else EI)
        if segs and segs[-1][2] == rigidity:
            segs[-1] = (segs[-1][0], s1, rigidity)
        else:
            segs.append((s0, s1, rigidity))
    return segs


def natural_frequency(sp: SectionProperties, E, density, length, ops: Ops = NUMERIC):
    """First bending frequency of the plain clamped-free beam, Hz (docs/model.md §4)."""
    return CLAMPED_FREE_ROOT ** 2 / (2 * math.pi) * ops.sqrt(E * sp.I / (density * sp.A * length ** 4))


def is_large_deflection(deflection: float, length: float) -> bool:
    """Whether small-deflection theory stops holding (deflection above 10 % of the free length)."""
    return float(deflection) > LARGE_DEFLECTION_RATIO * float(length)
