"""A pocket study row's extra length (docs/model.md §7): the extension of each reduced span for
which the beam model gives the row's 3-D free-end deflection, solved when the row is run
(``study.run_case``) and again after a change of the beam model (``refresh``, which records the
parameters the model has come to read as well), and how a row's two features share it
(``feature_weights``, ``features``) where a fit takes each feature's own clamp nearness, as the
model does (``corrections.widened``)."""

from __future__ import annotations

import math


def euler_deflection(g, analysis, material, spec) -> float:
    """The free-end deflection by Euler-Bernoulli theory with the reduced sections over their
    spans alone (no wire channel, no correction): what the table's ``deflection_ratio`` is over."""
    return widened_tip(g, analysis, material, spec, 0.0)


def widened_tip(g, analysis, material, spec, delta) -> float:
    """``euler_deflection`` with each reduced span ``delta`` longer (``delta/2`` at each end; one
    length for every span, or a tuple of one per span: ``corrections.Widened``)."""
    from designer import model
    from designer.model import corrections

    return float(model.tip_deflection(corrections.Widened(g, delta), analysis.props, float(material.E),
                                      spec.load.force_max, spec.load.position_max))


def beyond_euler(g, analysis, material, spec, stiffness=None) -> float:
    """What the beam model adds to ``euler_deflection`` besides the features' extra length: the
    wire channels, and the plain bar's ``stiffness`` fit where one is given."""
    from designer import model

    sp, E = analysis.props, float(material.E)
    f_max, x_max = spec.load.force_max, spec.load.position_max
    rest = float(model.channel_deflection(g, sp, E, f_max, x_max))
    if stiffness is not None:
        rest += float(stiffness.extra_deflection(g, sp, E, float(material.poisson), f_max, x_max))
    return rest


def extra_length(g, analysis, material, spec, deflection: float, stiffness=None) -> float:
    """The extension Δ of each reduced-section span (Δ/2 at each end) for which the beam model's
    deflection (beam theory with EI(s) piecewise, the wire channels, and the plain bar's
    ``stiffness`` fit where one is given) is ``deflection`` under F_max at x_max; negative if the
    beam is stiffer."""
    from scipy.optimize import brentq

    rest = beyond_euler(g, analysis, material, spec, stiffness)

    def tip(delta):
        return widened_tip(g, analysis, material, spec, delta) + rest - deflection

    span = g.stations[1] - g.stations[0] - g.feature_length
    lo, hi = -g.feature_length * 0.99, span * 0.99
    if tip(lo) * tip(hi) > 0:
        return math.nan
    return brentq(tip, lo, hi, xtol=1e-9)


def feature_weights(g, analysis, material, spec, delta: float) -> tuple[float, float]:
    """``(far_share, far_clamp_ratio)``: the far feature's share of the free-end deflection's slope
    in the extra length at ``delta`` (both spans widened by it), and its clamp ratio; nan where the
    extra length is. To first order the row's one ``extra_length`` is the two features' own
    weighted by these shares: a form in the clamp's nearness, which the model takes at each
    feature's own (``corrections.widened``), is fitted to that weighted sum (``features``)."""
    from designer.model import corrections

    if not math.isfinite(delta) or g.feature == "none" or len(g.stations) != 2:
        return math.nan, math.nan
    h = 1e-3 * g.size

    def tip(deltas):
        return widened_tip(g, analysis, material, spec, deltas)

    base = tip((delta, delta))
    near, far = tip((delta + h, delta)) - base, tip((delta, delta + h)) - base
    return far / (near + far), float(corrections.clamp_ratios(g)[1])


def features(row: dict, variables, quantity: str) -> list[tuple[float, dict]]:
    """``(share, parameters)`` of each feature whose own parameters a fit of ``quantity`` in
    ``variables`` takes at ``row``: the model takes an extra length in the clamp's nearness at each
    feature's own (``corrections.widened``), so a row that records its far feature's share of the
    deflection's slope (``far_share``, ``feature_weights``) holds the two features' fits in
    those shares; any other row or quantity (K_t is the near feature's), its own parameters."""
    from designer.model.corrections import CLAMP_NEAR

    share = row.get("far_share", math.nan)
    if quantity != "extra_length" or CLAMP_NEAR not in variables or not math.isfinite(share):
        return [(1.0, row)]
    return [(1.0 - share, row), (share, {**row, CLAMP_NEAR: row["clamp_near_far"]})]


def prediction(fit, quantity: str, row: dict) -> float:
    """What ``fit`` of ``quantity`` predicts for ``row``, its features weighted as ``features`` says."""
    return sum(share * float(fit(q)) for share, q in features(row, fit.variables, quantity))


def refresh(rows: list[dict], stiffness, plain_cases, parameters) -> list[dict]:
    """``rows`` with each pocket row's ``extra_length`` solved again from its 3-D deflection
    (``deflection_ratio`` times ``euler_deflection``) with today's beam model and ``stiffness``
    fit, and the parameters today's model reads that it does not record, without the 3-D check:
    each row is matched to its case (``plain_cases(families)``: ``study.plain_cases``, each case
    with its spec, evaluated design and plain analysis) by the parameters it records
    (``parameters(geometry)``: ``study.geometry_parameters``)."""
    out = list(rows)
    index = {}
    for i, r in enumerate(rows):
        if r["family"].endswith("pocket"):
            index.setdefault(r["family"], []).append(i)
    for case, spec, result, raw in plain_cases([*index]):
        design = result.evaluation.design
        g = design.geometry
        params = parameters(g)
        match = [i for i in index[case.family] if all(math.isclose(rows[i][k], v, rel_tol=1e-5, abs_tol=1e-9)
                                                      for k, v in params.items() if _recorded(rows[i], k))]
        if len(match) != 1:
            continue
        row = {**rows[match[0]], **{k: v for k, v in params.items() if not _recorded(rows[match[0]], k)}}
        euler = euler_deflection(g, raw, design.material, spec)
        fea = row["deflection_ratio"] * euler
        extra = extra_length(g, raw, design.material, spec, fea, stiffness)
        row["extra_length"] = extra / case.size
        row["far_share"], row["far_clamp_ratio"] = feature_weights(g, raw, design.material, spec, extra)
        row["base_ratio"] = fea / (euler + beyond_euler(g, raw, design.material, spec, stiffness))
        out[match[0]] = row
    return out


def _recorded(row: dict, key: str) -> bool:
    return not math.isnan(row.get(key, math.nan))
