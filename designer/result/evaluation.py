"""A finished design checked against every limit with the numeric model (MODEL.md 4-5).

``evaluate(design, spec)`` is the one place a design is judged: the optimiser's answers,
fixed designs from a spec and designs read back from design.json all pass through it.
"""

from __future__ import annotations

import copy
import math
from collections import OrderedDict
from dataclasses import dataclass, replace

import numpy as np

from designer import model
from designer.spec.catalogue import Material
from designer.spec.stock import StockItem
from designer.errors import InputError, SpecError
from designer.model import Adjustment, Analysis, Geometry, Limit, MaterialParams
from designer.model import tolerance
from designer.model.sections import wire_channel
from designer.model.tolerance import CornerCheck

ROUNDING = 1e-5  # designs are reported to 0.01 mm (MODEL.md section 5)


@dataclass(frozen=True)
class Design:
    """A material and a geometry, judged with the plain beam model or, with ``adjustment``,
    with the model adjusted to the design's 3-D check (docs/model.md §11)."""

    material: Material
    geometry: Geometry
    adjustment: Adjustment | None = None
    stock: StockItem | None = None   # the stock bar or tube the section is, when the search chose one

    def material_params(self, spec) -> MaterialParams:
        return MaterialParams.of(self.material, spec.limits)

    def rounded(self, cad) -> "Design":
        """Every length rounded to 0.01 mm, and the wire channel the CAD (``cad``: the spec's
        CadOptions) cuts for the rounded pocket; what is reported is what is checked. A stock
        section keeps its sizes as the table gives them (3/8 in is 9.525 mm)."""
        g = self.geometry

        def r(v):
            return None if v is None else round(float(v) / ROUNDING) * ROUNDING

        def section(v):
            return v if self.stock is not None else r(v)

        return Design(self.material, channelled(replace(
            g, width=section(g.width), height=section(g.height), diameter=section(g.diameter),
            wall=section(g.wall), depth=r(g.depth) if g.feature == "pocket" else 0.0,
            hole=r(g.hole) if g.feature == "hole" else 0.0,
            stations=tuple(r(s) for s in g.stations), length=r(g.length)), cad), self.adjustment, self.stock)

    def section_dict(self) -> dict:
        g = self.geometry
        if g.section == "rectangle":
            return {"kind": "rectangle", "width": g.width, "height": g.height}
        if g.section == "round":
            return {"kind": "round", "diameter": g.diameter}
        return {"kind": "tube", "diameter": g.diameter, "wall": g.wall}

    def feature_dict(self) -> dict:
        g = self.geometry
        if g.feature == "pocket":
            return {"kind": "pocket", "depth": g.depth, "length": g.pocket_length, "width": g.pocket_width}
        if g.feature == "hole":
            return {"kind": "hole", "diameter": g.hole}
        return {"kind": "none"}

    def shape_dict(self) -> dict:
        """The material and the geometry as design.json holds them (SI)."""
        g = self.geometry
        return {"material": self.material.name, "material_properties": self.material.properties(),
                "section": self.section_dict(), "feature": self.feature_dict(),
                "stations": [float(s) for s in g.stations], "length": float(g.length), "axes": g.axes}

    def to_dict(self, spec) -> dict:
        out = {**self.shape_dict(), "bridge": spec.bridge, "gauge": spec.gauge.as_dict()}
        if self.adjustment is not None:
            out["adjustment"] = self.adjustment.as_dict()
        if self.stock is not None:
            out["stock"] = self.stock.as_dict()
        return out

    def label(self) -> str:
        return f"{self.material.name} {self.geometry.section}"


@dataclass(frozen=True)
class Evaluation:
    design: Design
    analysis: Analysis
    limits: tuple[Limit, ...]
    objective: float
    error_ratio: float
    tolerance: CornerCheck | None = None   # the design at its tolerance corners (docs/model.md §14)

    @property
    def judged(self) -> tuple[Limit, ...]:
        """Every limit the design is judged on: at its nominal sizes, then at its tolerance corners."""
        return self.limits + (self.tolerance.limits if self.tolerance is not None else ())

    @property
    def violations(self) -> list[Limit]:
        """The limits broken by the nominal design, then those broken at a tolerance corner."""
        return [lim for lim in self.judged if float(lim.normalised) > model.FEASIBILITY_TOLERANCE]

    @property
    def feasible(self) -> bool:
        return not self.violations

    @property
    def worst_violation(self) -> float:
        """The largest normalised violation, 0 for a feasible design (one whose limits are met to
        within ``FEASIBILITY_TOLERANCE``: a rounding residue of 1e-16 is not a violation)."""
        if self.feasible:
            return 0.0
        return max(float(lim.normalised) for lim in self.judged)

    @property
    def large_deflection(self) -> bool:
        return model.is_large_deflection(self.analysis.deflection, self.design.geometry.length)

    def predicted(self) -> dict:
        a = self.analysis
        ell = float(self.design.geometry.length)
        return {
            "force_error": float(a.force_error), "position_error": float(a.position_error),
            "objective": self.objective, "error_ratio": self.error_ratio,
            "deflection": float(a.deflection), "deflection_ratio": float(a.deflection) / ell,
            "max_stress": float(a.max_stress), "stress_root": float(a.stress_root),
            "stress_feature": float(a.stress_feature),
            "stress_allowable": float(self.limits[0].limit),
            "stress_feature_allowable": self.feature_allowable,
            "stress_concentration": float(a.stress_concentration), "fatigue_factor": float(a.fatigue_factor),
            "stress_notch": float(a.stress_notch), "direction_factor": float(a.direction_factor),
            "stress_peak": float(a.stress_peak), "stress_fatigue": float(a.stress_fatigue),
            "gauge_strain": [float(s) for s in a.gauge_strain],
            "min_signal_snr": float(a.min_signal_snr),
            "sensitivity": [float(k) for k in a.sensitivities],
            "noise_voltage": float(a.sigma_v), "noise_strain": float(a.noise_strain),
            "mass": float(a.mass), "natural_frequency": float(a.natural_frequency),
            "mean_abs_force_error": float(a.force_error) * (2 / 3.141592653589793) ** 0.5,
            "mean_abs_position_error": float(a.position_error) * (2 / 3.141592653589793) ** 0.5,
        }

    @property
    def feature_allowable(self) -> float:
        """The largest nominal stress the feature's limits allow: the static limit, or the fatigue
        limit divided by K_f, whichever is lower (docs/model.md §4)."""
        by_name = {lim.name: lim for lim in self.limits}
        allowed = [float(by_name["stress_feature"].limit)]
        if "fatigue_feature" in by_name:
            # (the fatigue stress over the nominal: K_f, and on a biaxial sensor its notch's fibre)
            a = self.analysis
            allowed.append(float(by_name["fatigue_feature"].limit) * float(a.stress_feature) / float(a.stress_fatigue))
        return min(allowed)

    def constraint_records(self) -> list[dict]:
        return [lim.record() for lim in self.limits]


# The designs judged lately, by design and spec (``evaluate``): a search judges many a design
# more than once (an answer's rounding, then the same design as a neighbour's start or a front's
# candidate: about 40 % of the gripper finger's search's calls). The model is a pure function of the two.
_JUDGED: OrderedDict = OrderedDict()
JUDGED_KEPT = 1024


def evaluate(design: Design, spec) -> Evaluation:
    """Judge ``design``; sizes or electronics so far off that the numbers break are an InputError.
    A design judged lately under the same spec (the same object) is not judged again: its
    evaluation is returned as a copy (a new object: callers tell answers apart by identity)."""
    key = (design, id(spec))
    try:
        hit = _JUDGED.get(key)
    except TypeError:  # a design with an unhashable part is judged every time
        return _evaluate(design, spec)
    if hit is not None and hit[0] is spec:
        _JUDGED.move_to_end(key)
        return copy.copy(hit[1])
    ev = _evaluate(design, spec)
    _JUDGED[key] = (spec, ev)   # (the spec is held: its id cannot be taken by another while kept)
    if len(_JUDGED) > JUDGED_KEPT:
        _JUDGED.popitem(last=False)
    return ev


def _evaluate(design: Design, spec) -> Evaluation:
    params = design.material_params(spec)
    try:
        a = model.analyse(design.geometry, params, spec, adjust=design.adjustment)
        lims = tuple(model.limits(design.geometry, a, params, spec))
        ev = Evaluation(design, a, lims, float(model.objective(a, spec)), float(model.error_ratio(a, spec.targets)),
                        tolerance.check(design.geometry, params, spec, design.adjustment))
        predicted = ev.predicted()
    except ArithmeticError as exc:  # ZeroDivisionError, OverflowError
        raise InputError(f"the design cannot be evaluated ({exc}); a size, load or electronics value is far "
                         "outside the physical range") from exc
    broken = [k for k, v in predicted.items() if not all(math.isfinite(x) for x in np.ravel(v))]
    if broken:
        raise InputError(f"the design cannot be evaluated: {', '.join(broken)} come out infinite or undefined; "
                         "a size, load or electronics value is far outside the physical range")
    return ev


def channelled(g: Geometry, cad) -> Geometry:
    """``g`` with the wire channels the CAD (``cad``: the spec's CadOptions) cuts for its pocket:
    their depth follows the pocket's (``sections.wire_channel``), so a geometry whose depth was
    rounded must have them cut again."""
    width, depth = wire_channel(cad, g.section, g.feature, g.depth, g.pocket_width)
    return replace(g, channel_width=width, channel_depth=depth)


def geometry_for(spec, section, feature, stations, length, axes=None) -> Geometry:
    """A Geometry from spec dataclasses (Section, Feature) and station positions."""
    lp, wp = spec.pocket_size()
    return milled(Geometry(
        section=section.kind, feature=feature.kind, stations=tuple(stations), length=length,
        width=section.width, height=section.height, diameter=section.diameter, wall=section.wall,
        depth=feature.depth if feature.kind == "pocket" else 0.0,
        hole=feature.diameter if feature.kind == "hole" else 0.0,
        pocket_length=feature.length if feature.kind == "pocket" else lp,
        pocket_width=feature.width if feature.kind == "pocket" else wp,
        gauge_length=spec.gauge.length, grid_length=spec.gauge.grid_length,
        grid_width=spec.gauge.grid_width, axes=axes or spec.axes,
        floor_radius=spec.cad.corner_radius if feature.kind == "pocket" else 0.0), spec)


def milled(g: Geometry, spec) -> Geometry:
    """``g`` with its wire channels (``channelled``) and a slot's corner radius in plan, the radius
    of the end mill the CAD cuts it with (``outputs.cad.mills.pocket_tool``; DesignFileError where
    none can)."""
    g = channelled(g, spec.cad)
    if g.section != "rectangle" or g.feature != "pocket":
        return g
    from designer.outputs.cad.mills import pocket_tool

    return replace(g, plan_radius=pocket_tool(spec, g).diameter / 2)


def fixed_design(spec) -> Design:
    """The spec's ``design:`` block as a Design."""
    from designer.spec import catalogue

    fd = spec.design
    geometry = geometry_for(spec, fd.section, fd.feature, fd.stations, spec.free_length)
    design = Design(catalogue.material(fd.material, "design.material"), geometry)
    # (and as it is judged: a size under 0.005 mm rounds to nothing on the 0.01 mm grid)
    for g, rounded in ((geometry, ""), (design.rounded(spec.cad).geometry, " (rounded to 0.01 mm, as the design "
                                                                           "is judged)")):
        problem = model.unbuildable(g) or model.features_apart(g.stations, g.length, g.feature_length, g.feature)
        if problem is not None:  # not a beam at all: bad input, nothing to judge or write
            key, reason = problem
            raise SpecError(f"design.{key}: {reason}{rounded}")
    return design
