"""The sensor as a force cell under OIML R 60 (Metrological regulation for load cells, edition
2021): the highest accuracy class and number of verification intervals n_LC its error budget
allows, and the term that stops it (docs/model.md §13).

With ``v = F_max / n_LC`` (the minimum verification interval taken equal to ``v``) and the
apportionment factor ``p_LC = 0.7`` (R 60's default):

- *errors at a load m*: R 60's maximum permissible error is ``p_LC × (0.5, 1.0, 1.5) v`` in
  three load bands (class C: up to 500 v, 2000 v, 10 000 v; class D: 50 v, 200 v, 1000 v). The
  budget's expanded uncertainty (k = 2) of the terms R 60's error test sees (all but creep and
  zero drift, which it tests on their own) must fit in it at F_min and at F_max;
- *zero*: the minimum dead-load output may move by at most ``p_LC × v`` per 5 °C: the zero
  drift terms' bound ``a``, scaled from the operating range's swing to 5 K;
- *creep*: over 30 min at most 0.7 times the mpe at the load (mpe with p_LC = 0.7).

Class C spans n_LC = 500 to 10 000, class D 100 to 1000; candidates are taken in steps of 500
and 100. A budget is a prediction, not a type test: the result says which class a type test
could reach, not that it would pass one.
"""

from __future__ import annotations

from dataclasses import dataclass

P_LC = 0.7
CLASSES = {  # n_LC candidates, and the load bands (in v) of mpe = p_LC x 0.5, 1.0, 1.5 v
    "C": (tuple(range(500, 10001, 500)), (500, 2000)),
    "D": (tuple(range(100, 1001, 100)), (50, 200)),
}
ZERO_STEP = 5.0  # K: R 60's zero (minimum dead load output) is judged per 5 °C


@dataclass(frozen=True)
class OimlResult:
    accuracy_class: str | None   # "C", "D", or None when not even D with 100 intervals
    n_lc: int | None
    limited_by: str              # what fails at the next step (or the class's own upper limit)


def mpe(load_in_v: float, bands) -> float:
    """The maximum permissible error at a load of ``load_in_v`` verification intervals, in v."""
    first, second = bands
    factor = 0.5 if load_in_v <= first else 1.0 if load_in_v <= second else 1.5
    return P_LC * factor


def failures(points, force_max: float, swing: float, n_lc: int, bands, coverage: float = 2.0) -> list[str]:
    """What keeps the sensor from ``n_lc`` intervals in a class of ``bands`` (empty: nothing).
    ``points``: ``(F, {term name: u(F)/F})`` at each corner of the region; ``swing`` the
    operating temperatures' largest distance from the calibration temperature, K."""
    v = force_max / n_lc
    out = []
    for force, terms in points:
        seen = {k: u for k, u in terms.items() if not k.startswith(("zero drift", "creep"))}
        expanded = coverage * sum(u * u for u in seen.values()) ** 0.5 * force
        allowed = mpe(force / v, bands) * v
        if expanded > allowed:
            worst = max(seen, key=seen.get)
            out.append(f"the error at {force:.4g} N (k = {coverage:g}: {expanded:.3g} N, mostly {worst}) exceeds "
                       f"the mpe {allowed:.3g} N")
    force, terms = points[0]
    zero = 3 ** 0.5 * sum(u * u for k, u in terms.items() if k.startswith("zero drift")) ** 0.5 * force
    zero_5k = zero * ZERO_STEP / swing
    if zero_5k > P_LC * v:
        out.append(f"the zero drift, {zero_5k:.3g} N per 5 K, exceeds p_LC·v = {P_LC * v:.3g} N")
    creep = 3 ** 0.5 * terms.get("creep", 0.0) * force_max
    if creep > 0.7 * mpe(n_lc, bands) * v:
        out.append(f"creep, {creep:.3g} N in 30 min at F_max, exceeds 0.7 mpe = {0.7 * mpe(n_lc, bands) * v:.3g} N")
    return list(dict.fromkeys(out))


def classify(points, force_max: float, swing: float, coverage: float = 2.0) -> OimlResult:
    """The highest class and n_LC the budget allows (class C before D, most intervals first)."""
    stop = ""
    for name, (candidates, bands) in CLASSES.items():
        # not monotonic in n: the top load moves into a band of larger mpe as n grows
        failed = {n: failures(points, force_max, swing, n, bands, coverage) for n in candidates}
        passing = [n for n in candidates if not failed[n]]
        if passing:
            best = passing[-1]
            later = [n for n in candidates if n > best]
            stop = (f"at n_LC = {later[0]}: " + "; ".join(failed[later[0]]) if later
                    else f"class {name} allows at most {best} intervals")
            return OimlResult(name, best, stop)
        stop = f"at n_LC = {candidates[0]}: " + "; ".join(failed[candidates[0]])
    return OimlResult(None, None, f"not even class D with 100 intervals: {stop}")
