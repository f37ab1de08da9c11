"""design.json: the complete record of a design and how it was judged (SPEC.md)."""

from __future__ import annotations

from designer.model.electronics import volts_per_strain
from designer.result.evaluation import Evaluation

VERSION = 1


def build_record(status: str, spec, evaluation: Evaluation, candidates=(), solver=None,
                 messages=(), extra=None) -> dict:
    """The design.json dictionary. ``status``: optimal | feasible | infeasible."""
    record = {
        "version": VERSION,
        "status": status,
        "spec": spec.to_dict(),
        "design": evaluation.design.to_dict(spec),
        "predicted": evaluation.predicted(),
        "constraints": evaluation.constraint_records(),
        "candidates": list(candidates),
        "solver": dict(solver or {"method": "none", "seconds": 0.0, "evaluations": 0}),
        "messages": list(messages),
    }
    tool = pocket_tool_record(spec, evaluation)
    if tool is not None:
        record["design"]["feature"]["tool"] = tool
    front_end = front_end_record(spec, evaluation)
    if front_end is not None:
        record["predicted"]["front_end"] = front_end
    if evaluation.analysis.budget is not None:
        record["predicted"]["budget"] = budget_record(spec, evaluation)
    if evaluation.tolerance is not None:
        record["tolerances"] = tolerance_record(spec, evaluation)
    elif (general := general_tolerance_record(spec, evaluation)) is not None:
        record["general_tolerances"] = general
    if evaluation.large_deflection:
        record["messages"].append(large_deflection_message(evaluation))
    if extra:
        record.update(extra)
    return record


def tolerance_record(spec, evaluation: Evaluation) -> dict:
    """The design at its tolerance corners (docs/model.md §14): the class, each toleranced size's
    deviation (m), each corner-checked limit at its worst corner, and how far the sensitivities k_i
    move across the corners (the least and the greatest k_i / k_i(nominal) - 1)."""
    return corner_record(spec.tolerances.label(), evaluation.tolerance)


def corner_record(label: str, check) -> dict:
    """A design at its tolerance corners (a ``model.tolerance.CornerCheck``) as design.json keeps it."""
    return {"label": label, "deviations": dict(check.deviations), "corners": check.count,
            "constraints": check.records(), "sensitivity_spread": list(check.sensitivity)}


# The general tolerances the drawing asks for when the spec's class is none (outputs.drawing.sheet).
DRAWING_CLASS = "m"


def general_tolerance_record(spec, evaluation: Evaluation) -> dict | None:
    """With ``tolerances: {class: none}`` the search judges nominal sizes only, while the drawing
    asks for the general tolerances of ISO 2768-m: the design at their corners (docs/model.md §14),
    as ``tolerance_record`` gives it, with ``checked: false``. None when the model cannot judge the
    corners (a design that is not a beam)."""
    from dataclasses import replace

    from designer.model import tolerance, unbuildable
    from designer.spec.tolerances import Tolerances

    design = evaluation.design
    if unbuildable(design.geometry) is not None:
        return None
    drawn = replace(spec, tolerances=Tolerances(DRAWING_CLASS))
    check = tolerance.check(design.geometry, design.material_params(drawn), drawn, design.adjustment)
    return {**corner_record(drawn.tolerances.label(), check), "class": DRAWING_CLASS, "checked": False}


def front_end_record(spec, evaluation: Evaluation) -> dict | None:
    """The catalogue front-end's figures for the design (docs/spec.md §4): its setting, the
    bridge output at F_max, x_max per station in V/V and in counts, the input range, and the
    noise referred to the bridge output, part by part (V RMS) and in counts; None without one."""
    fe = spec.front_end_noise
    if fe is None:
        return None
    e = spec.electronics
    per_strain = volts_per_strain(1.0, spec.gauge.factor, 1.0, spec.bridge_factor)   # V/V of excitation
    output = [per_strain * float(s) for s in evaluation.analysis.gauge_strain]
    entry = e.front_end
    return {
        "name": e.adc, "kind": entry.kind, "gain": e.gain, "rate": e.rate,
        "bits": entry.resolution if e.bits is None else e.bits,
        "full_scale": fe.full_scale, "full_scale_per_volt": fe.full_scale / e.excitation,
        "output_per_volt": output, "output_counts": [v * e.excitation / fe.step for v in output],
        "counts_per_volt": fe.counts_per_volt,
        "noise": {"converter": fe.converter, "johnson": fe.johnson, "quantisation": fe.quantisation,
                  "total": fe.total},
        "noise_counts": fe.total / fe.step,
        "source": entry.source,
    }


COVERAGE = 2  # the expanded uncertainty's coverage factor (JCGM 100 §6.3)


def budget_record(spec, evaluation: Evaluation) -> dict:
    """The error budget (docs/spec.md §4): for the force and for the position, the region's corner
    where the combined standard uncertainty is largest, every term's standard uncertainty and
    share of the variance there, the combined 1σ and the expanded value (k = 2); the noise
    alone, as without ``environment``; and the budget's inputs, from which the error maps draw
    the combined uncertainty over the whole region."""
    from designer.model.budget import budget_inputs, combined, effective_rigidity, recorded_inputs
    from designer.model.oiml import classify

    a = evaluation.analysis
    load = spec.load
    rigidity = effective_rigidity(float(a.deflection), load.force_max, load.position_max,
                                  evaluation.design.geometry.length)
    inputs = budget_inputs(spec, evaluation.design.material_params(spec), rigidity=rigidity)
    tared = spec.environment.tare
    out = {"coverage_factor": COVERAGE, "inputs": recorded_inputs(inputs),
           "noise_only": {"force_error": float(a.noise_force_error), "position_error": float(a.noise_position_error)}}
    for index, quantity in enumerate(("force", "position")):
        force, position, terms = max(a.budget, key=lambda point: float(combined(point[2])[index]))
        total = float(combined(terms)[index])
        variances = [float(t.force_var if index == 0 else t.position_var) for t in terms]
        out[quantity] = {
            "at": {"force": force, "position": position},
            "combined": total, "expanded": COVERAGE * total,
            "terms": [{"name": t.name + (" (tared)" if tared and t.name.startswith("zero drift") else ""),
                       "kind": t.kind, "u": v ** 0.5, "share": v / total ** 2} for t, v in zip(terms, variances)],
        }
    points = [(force, {t.name: t.force for t in terms}) for force, _, terms in a.budget]
    rated = classify(points, spec.load.force_max, spec.environment.swing, COVERAGE)
    out["oiml_r60"] = {"class": rated.accuracy_class, "n_lc": rated.n_lc, "limited_by": rated.limited_by}
    return out


def search_record(spec, found) -> dict:
    """The design.json record of a search result (``search.SearchResult``), before the checks
    the pipeline adds (large deflection, 3-D)."""
    record = build_record(found.status, spec, found.best, [c.record() for c in found.candidates], found.solver,
                          found.messages)
    if spec.search.stock != "none":
        record["stock"] = stock_summary(spec, found.best, found.get("continuous"))
    return record


def pocket_tool_record(spec, evaluation: Evaluation) -> dict | None:
    """design.json's ``design.feature.tool``: the end mill of the tool catalogue (docs/spec.md
    2.9) that cuts the pockets or flats, as the CAD picks it; None without pockets, or where no
    catalogue end mill cuts the slot (the CAD then says why)."""
    from designer.errors import DesignFileError
    from designer.outputs.cad.mills import pocket_tool

    try:
        tool = pocket_tool(spec, evaluation.design.geometry)
    except DesignFileError:
        return None
    return None if tool is None else tool.as_dict()


def stock_summary(spec, best: Evaluation, continuous: Evaluation | None) -> dict:
    """design.json's ``stock``: the stock item chosen, the best design of continuous sizes the
    search began from, and what stock costs in the objective's terms (``cost``: stock objective
    over the continuous one, minus one)."""
    item = best.design.stock
    out = {"system": spec.search.stock, "objective": spec.objective,
           "item": None if item is None else item.as_dict(), "continuous": None, "cost": None}
    if continuous is not None:
        out["continuous"] = {"material": continuous.design.material.name,
                             "section": continuous.design.section_dict(), "objective": continuous.objective}
        if best.feasible and continuous.objective > 0:
            out["cost"] = best.objective / continuous.objective - 1
    return out


def large_deflection_message(evaluation: Evaluation) -> str:
    ratio = float(evaluation.analysis.deflection) / float(evaluation.design.geometry.length)
    return (f"warning: the free end deflects {ratio:.1%} of the free length under F_max at x_max; "
            "above 10 % small-deflection (linear) beam theory no longer holds, so the predicted "
            "deflection, strains and errors are approximate")
