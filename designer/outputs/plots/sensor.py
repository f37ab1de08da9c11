"""What the plots read from a design.json dictionary: ``SensorData``, checked, SI throughout
(m, N, V, Pa). A missing or impossible value raises DesignFileError naming the key."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from designer import model
from designer.errors import DesignFileError, brief


@dataclass(frozen=True)
class SensorData:
    """What the plots need from a design.json dictionary, SI units (m, N, V, Pa)."""

    name: str
    status: str
    material: str
    section: str                    # rectangle | round | tube
    feature: str                    # pocket | hole | none
    force_min: float
    force_max: float
    position_min: float
    position_max: float
    stations: tuple[float, ...]     # d_i from the clamp
    sensitivity: tuple[float, ...]  # k_i, V/(N m)
    noise: float                    # sigma_V per channel at the amplifier output, V
    length: float                   # free length, m
    min_snr: float
    gauge_strain: float             # eps_1 under F_max at x_max
    max_strain: float               # the gauge's strain limit
    stress_root: float              # Pa, under F_max at x_max
    stress_feature: float | None    # Pa, at the clamp-side edge of the first feature
    feature_edge: float | None      # m, where stress_feature acts
    stress_allowable: float
    stress_feature_allowable: float   # the nominal stress the feature's static and fatigue limits allow
    force_target: float | None      # sigma_F / F_min
    position_target: float | None   # sigma_x(F_min, x_max), m
    axes: int
    objective_kind: str             # error | deflection | mass
    objective: float | None
    error_ratio: float | None       # the error objective e, whatever the objective
    deflection: float | None
    natural_frequency: float | None

    @classmethod
    def from_design(cls, design: Mapping) -> "SensorData":
        """Read and check the keys; a missing or impossible value raises DesignFileError."""
        if not isinstance(design, Mapping):
            raise DesignFileError(f"design.json: must be a JSON object, not {type(design).__name__}")
        spec = _key(design, "spec")
        body = _key(design, "design")
        pred = _key(design, "predicted")
        f_min, f_max = _range(_key(spec, "load", "spec"), "force", "spec.load")
        x_min, x_max = _range(spec["load"], "position", "spec.load")
        stations = _numbers(_key(body, "stations", "design"), "design.stations")
        if len(stations) < 2 or any(b <= a for a, b in zip(stations, stations[1:])):
            raise DesignFileError(f"design.stations: {list(stations)!r} must be at least 2 positions "
                                  "increasing from the clamp outwards")
        problem = model.stations_before_load(stations, x_min)
        if problem is not None:
            raise DesignFileError(f"design.{problem[0]}: {problem[1]}")
        k = _numbers(_key(pred, "sensitivity", "predicted"), "predicted.sensitivity")
        axes = body.get("axes", 1)
        if axes not in (1, 2):
            raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
        if len(k) == axes * len(stations) and axes > 1:
            k = k[:len(stations)]  # one axis of a biaxial sensor; both axes are alike
        if len(k) != len(stations):
            raise DesignFileError(f"predicted.sensitivity: {len(k)} values for {len(stations)} stations; "
                                  "give one k_i per station")
        section = _key(body, "section", "design")
        feature = body.get("feature") or {"kind": "none"}
        limits = spec.get("limits") or {}
        targets = spec.get("targets") or {}
        stress_root = _positive(pred, "stress_root", "predicted", required=False)
        stress_feature = _positive(pred, "stress_feature", "predicted", required=False)
        if stress_root is None:  # older records: only the largest stress and no location
            stress_root, stress_feature = _positive(pred, "max_stress", "predicted"), None
        edge = _feature_edge(body, spec, stations[0]) if stress_feature is not None else None
        if edge is None:
            stress_feature = None
        return cls(
            name=str(spec.get("name") or "sensor"), status=str(design.get("status", "")),
            material=str(body.get("material", "")), section=str(_key(section, "kind", "design.section")),
            feature=str(feature.get("kind", "none")),
            force_min=f_min, force_max=f_max, position_min=x_min, position_max=x_max,
            stations=stations, sensitivity=k, noise=_noise(pred, spec),
            length=_positive(body, "length", "design"),
            min_snr=_positive(limits, "min_snr", "spec.limits", required=False) or 5.0,
            gauge_strain=_numbers(_key(pred, "gauge_strain", "predicted"), "predicted.gauge_strain")[0],
            max_strain=_max_strain(body, spec),
            stress_root=stress_root, stress_feature=stress_feature, feature_edge=edge,
            stress_allowable=_positive(pred, "stress_allowable", "predicted"),
            stress_feature_allowable=(_positive(pred, "stress_feature_allowable", "predicted", required=False)
                                      or _positive(pred, "stress_allowable", "predicted")),
            force_target=_positive(targets, "force_error", "spec.targets", required=False),
            position_target=_positive(targets, "position_error", "spec.targets", required=False),
            axes=axes, objective_kind=str(spec.get("objective", "error")),
            objective=optional_number(pred.get("objective")),
            error_ratio=optional_number(pred.get("error_ratio", pred.get("objective")
                                                 if spec.get("objective", "error") == "error" else None)),
            deflection=optional_number(pred.get("deflection")),
            natural_frequency=optional_number(pred.get("natural_frequency")),
        )

    @property
    def offsets(self) -> tuple[float, ...]:
        """Bridge offsets c_i: zero for a balanced, ideal bridge."""
        return (0.0,) * len(self.stations)

    @property
    def label(self) -> str:
        # a pocket on a round bar or a tube is a flat, as the drawing and the summary call it
        name = "flat" if self.feature == "pocket" and self.section != "rectangle" else self.feature
        feature = "" if self.feature == "none" else f", {name}s"
        return f"{self.material} {self.section}{feature}"

# --------------------------------------------------------------------------- reading helpers


def _key(obj, key: str, where: str = ""):
    path = f"{where}.{key}" if where else key
    if not isinstance(obj, Mapping):
        raise DesignFileError(f"{where or 'design.json'}: {brief(obj)} must be an object")
    if key not in obj or obj[key] is None:
        raise DesignFileError(f"{path}: missing; the plots need it")
    return obj[key]


def is_number(value) -> bool:
    return (not isinstance(value, bool) and isinstance(value, (int, float))
            and math.isfinite(value))


def optional_number(value) -> float | None:
    return float(value) if is_number(value) else None


def _positive(obj, key: str, where: str, required: bool = True) -> float | None:
    if not isinstance(obj, Mapping) or obj.get(key) is None:
        if required:
            raise DesignFileError(f"{where}.{key}: missing; the plots need it")
        return None
    value = obj[key]
    if not is_number(value) or value <= 0:
        raise DesignFileError(f"{where}.{key}: {value!r} must be a positive number (SI units)")
    return float(value)


def _numbers(values, where: str) -> tuple[float, ...]:
    if not isinstance(values, Sequence) or isinstance(values, str) or not values:
        raise DesignFileError(f"{where}: {brief(values)} must be a list of positive numbers")
    for i, v in enumerate(values):
        if not is_number(v) or v <= 0:
            raise DesignFileError(f"{where}[{i}]: {v!r} must be a positive number (SI units)")
    return tuple(float(v) for v in values)


def _range(obj, key: str, where: str) -> tuple[float, float]:
    lo_hi = _numbers(_key(obj, key, where), f"{where}.{key}")
    if len(lo_hi) != 2 or not lo_hi[0] < lo_hi[1]:
        raise DesignFileError(f"{where}.{key}: {list(lo_hi)!r} must be [min, max] with min < max")
    return lo_hi


def _noise(pred, spec) -> float:
    """sigma_V, V: as predicted, else the output noise the normalised spec records."""
    value = _positive(pred, "noise_voltage", "predicted", required=False)
    el = spec.get("electronics") or {}
    for key in ("noise_output", "noise"):
        if value is None:
            value = _positive(el, key, "spec.electronics", required=False)
    if value is None:
        raise DesignFileError("predicted.noise_voltage: missing, and spec.electronics gives no output "
                              "noise; the error maps need sigma_V")
    return value


def _max_strain(body, spec) -> float:
    for where, gauge in (("design.gauge", body.get("gauge")), ("spec.gauge", spec.get("gauge"))):
        value = _positive(gauge, "max_strain", where, required=False) if isinstance(gauge, Mapping) else None
        if value is not None:
            return value
    raise DesignFileError("design.gauge.max_strain: missing; the strain limit isoline needs it")


def _feature_edge(body, spec, d1: float) -> float | None:
    """s of the first feature's clamp-side edge, d_1 - l_f/2 (MODEL.md sections 1 and 4)."""
    feature = body.get("feature") or {}
    kind = feature.get("kind", "none")
    gauge = body.get("gauge") or spec.get("gauge") or {}
    length = model.feature_length(kind if kind in ("pocket", "hole") else "none", feature.get("length"),
                                  feature.get("diameter"), gauge.get("length") if isinstance(gauge, Mapping) else None)
    if not is_number(length) or not 0 <= length / 2 < d1:
        return None
    return d1 - length / 2
