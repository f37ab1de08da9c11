"""The room the limits keep for a material's Poisson's ratio (docs/model.md §7).

The features' fits were taken on the study's 6061-T6 bars (``nu = FIT_POISSON``). The same study
bars in 3-D in 17-4PH-H900 (``nu`` 0.272), 301-full-hard (0.29) and Ti-6Al-4V (0.342), each
reading set beside the bar's own in 6061-T6 (``python benchmarks/feature_poisson_check.py``,
benchmarks/feature_poisson_check.md), move nearly in proportion to ``nu - 0.33``:

- the gauge strain, either way: short, deep round flats read up to 1.2 % more in 17-4PH-H900
  (on the gauge-strain limit's unsafe side) and 0.26 % less in Ti-6Al-4V; holes up to 1.4 % less
  in 17-4PH-H900 (on the accuracy targets' unsafe side) and 0.3 % more in Ti-6Al-4V; slots and
  tube flats within 0.6 %;
- the free-end deflection, more the lower ``nu``: up to 1.2 % in 17-4PH-H900 (deep round flats),
  0.2-0.4 % for every other bar; less in Ti-6Al-4V;
- a plain round bar's or tube's gauge near the clamp: up to 1.6 % more in 17-4PH-H900, where the
  model takes 5-8 % off for the clamp (the clamp stops the bar's Poisson contraction, less so the
  lower ``nu``), 0.3 % less in Ti-6Al-4V; the far gauge not at all.

The clamp's own loss on a wide bar, and a plain round bar's or tube's near the clamp, are scaled to
``nu`` in the model (``corrections.strain_factors``); what is left is kept as room: the
gauge-strain-borne limits and the targets keep ``STRAIN_ROOM[family] |nu - 0.33|`` more, the
deflection limit ``DEFLECTION_ROOM[family] (0.33 - nu)`` more below 0.33. Each factor is the
family's largest reading per unit of ``nu``, rounded up.
"""

from __future__ import annotations

from designer.model.corrections import CLAMP_POISSON as FIT_POISSON
from designer.model.ops import NUMERIC, Ops

# the largest change of the 3-D gauge strain over the model's per unit of |nu - FIT_POISSON|, rounded
# up: 13 round flats, 13 holes, 12 slots and 9 tube flats inside the fits' domain, in 17-4PH-H900 and
# Ti-6Al-4V (and 301-full-hard on a few), set beside 6061-T6 (benchmarks/feature_poisson_check.md); plain
# round bars and tubes (8 of each) after their near-clamp loss is scaled to nu (corrections.NEAR_POISSON_POWER):
# within 0.18 %
STRAIN_ROOM = {"round-pocket": 0.23, "rectangle-hole": 0.28, "rectangle-pocket": 0.09, "tube-pocket": 0.11,
               "round-none": 0.04, "tube-none": 0.04}
# ... of the free-end deflection per unit of FIT_POISSON - nu (a larger nu deflects less); plain
# rectangular bars 4, 8 and 16 times as wide as high read 0.3-0.4 % more in 17-4PH-H900 than in
# 6061-T6; plain round bars read 0.25-0.28 % more, tubes 0.11-0.26 %
DEFLECTION_ROOM = {"round-pocket": 0.21, "rectangle-hole": 0.08, "rectangle-pocket": 0.07, "tube-pocket": 0.07,
                   "rectangle-none": 0.08, "round-none": 0.08, "tube-none": 0.08}


# The rooms' corners rounded off within this much of nu: where a relaxation lets the material's
# properties free (search.run, a group of materials proved infeasible at once) nu is a variable,
# and IPOPT stalls at a kink. The rounded room is exact at 0.33 and at most this much of nu off.
SMOOTHING = 1e-4


def strain_room(family: str, poisson, ops: Ops = NUMERIC):
    """The share of the gauge strain by which 3-D may lie off the model for ``poisson`` (a number
    or the NLP's material parameter): ``STRAIN_ROOM |nu - 0.33|``, its corner rounded off."""
    d = poisson - FIT_POISSON
    return STRAIN_ROOM.get(family, 0.0) * (ops.sqrt(d * d + SMOOTHING ** 2) - SMOOTHING)


def deflection_room(family: str, poisson, ops: Ops = NUMERIC):
    """The share of the free-end deflection by which 3-D may lie above the model for ``poisson``:
    ``DEFLECTION_ROOM max(0.33 - nu, 0)``, its corner rounded off."""
    d = FIT_POISSON - poisson
    return DEFLECTION_ROOM.get(family, 0.0) * (d + ops.sqrt(d * d + SMOOTHING ** 2) - SMOOTHING) / 2
