"""What calibration and measurement need from a design.json: stations, k, sigma_V, the region."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from designer.calibration.data import Bridge, bridges_for
from designer.errors import DesignFileError, brief
from designer.model.electronics import BRIDGE_FACTORS, output_noise
from designer.model.sections import stations_before_load
from designer.spec.units import RANGES


@dataclass(frozen=True)
class DesignConstants:
    """What calibration and measurement need from a design.json (SI)."""

    name: str
    stations: tuple[float, ...]        # d_i, m
    sensitivity: tuple[float, ...]     # k_i, V/(N m), per station (both axes alike)
    noise: float                       # sigma_V per channel at the amplifier output, V
    axes: int
    force_range: tuple[float, float]   # F_min, F_max, N
    position_range: tuple[float, float]  # x_min, x_max, m
    prototype: str | None = None       # 'A', 'B' or 'C' when the beam is one of the paper's
    volts_per_count: float | None = None  # with a catalogue front-end: amplifier volts per converter count

    @property
    def bridges(self) -> tuple[Bridge, ...]:
        return bridges_for(len(self.stations), self.axes)

    def bridge_k(self) -> np.ndarray:
        """k per bridge in column order."""
        return np.repeat(np.asarray(self.sensitivity, dtype=float), self.axes)

    def bridge_d(self) -> np.ndarray:
        return np.repeat(np.asarray(self.stations, dtype=float), self.axes)


#: The paper's Table 1 sections, to recognise its prototypes (m): A, B and C.
PROTOTYPE_SECTIONS = {
    "A": ("rectangle", {"width": 0.050, "height": 0.00318}),
    "B": ("rectangle", {"width": 0.0127, "height": 0.0127}),
    "C": ("tube", {"diameter": 0.0127, "wall": 0.00165}),
}
#: Section sizes within this of Table 1 are taken as the prototype (m): 0.05 mm.
PROTOTYPE_MATCH = 5e-5


def json_number(value, key: str, positive: bool = False, error: type = DesignFileError) -> float:
    """``value`` as a float, or ``error`` naming ``key`` (a design.json or calibration.json key)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise error(f"{key}: {value!r} must be a finite number (SI units)")
    if positive and value <= 0:
        raise error(f"{key}: {value!r} must be positive")
    return float(value)


def _require(obj, key: str, where: str):
    if not isinstance(obj, dict) or obj.get(key) is None:
        raise DesignFileError(f"{where + '.' if where else ''}{key}: missing; it is required")
    return obj[key]


def _pair(value, key: str) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise DesignFileError(f"{key}: {value!r} must be a pair [min, max]")
    lo, hi = (json_number(v, f"{key}[{i}]", positive=True) for i, v in enumerate(value))
    if not lo < hi:
        raise DesignFileError(f"{key}: {value!r} must increase (min < max)")
    return lo, hi


#: The largest sigma_V, V: noise at the amplifier output no larger than a reading can be (the
#: spec's largest voltage, spec.units.RANGES, which readings.csv's volts are held to as well).
#: Beyond it the figure is a typing error; it would overflow the plan and simulate readings that
#: calibrate refuses.
LARGEST_NOISE = RANGES["voltage"][1]


def _bounded_noise(value: float, where: str) -> float:
    if value > LARGEST_NOISE:
        raise DesignFileError(f"{where} V is beyond what a reading can be; sigma_V at the amplifier output "
                              f"must be positive and at most {LARGEST_NOISE:g} V")
    return value


def _noise_from(record: dict) -> float:
    """sigma_V: predicted.noise_voltage, else ``model.output_noise`` of spec.electronics (MODEL.md
    section 3, the same precedence); each input it needs is checked first, naming its key, and
    sigma_V must be at most LARGEST_NOISE."""
    predicted = record.get("predicted") or {}
    if predicted.get("noise_voltage") is not None:
        value = json_number(predicted["noise_voltage"], "predicted.noise_voltage", positive=True)
        return _bounded_noise(value, f"predicted.noise_voltage: {predicted['noise_voltage']!r}")
    spec = record["spec"]
    e = _require(spec, "electronics", "spec")
    noise = noise_rti = noise_strain = excitation = gain = factor = bridge_factor = None
    if e.get("noise") is not None:
        noise = json_number(e["noise"], "spec.electronics.noise", positive=True)
    elif e.get("noise_rti") is not None:
        noise_rti = json_number(e["noise_rti"], "spec.electronics.noise_rti", positive=True)
        gain = json_number(_require(e, "gain", "spec.electronics"), "spec.electronics.gain", positive=True)
    elif e.get("noise_strain") is not None:
        gauge = spec.get("gauge") or record["design"].get("gauge") or {}
        bridge = spec.get("bridge", record["design"].get("bridge"))
        if bridge not in BRIDGE_FACTORS:
            raise DesignFileError(f"spec.bridge: {bridge!r} is not allowed; must be one of {list(BRIDGE_FACTORS)}")
        excitation = json_number(_require(e, "excitation", "spec.electronics"), "spec.electronics.excitation", True)
        factor = json_number(_require(gauge, "factor", "spec.gauge"), "spec.gauge.factor", True)
        gain = json_number(_require(e, "gain", "spec.electronics"), "spec.electronics.gain", True)
        bridge_factor = BRIDGE_FACTORS[bridge]
        noise_strain = json_number(e["noise_strain"], "spec.electronics.noise_strain", True)
    else:
        raise DesignFileError("predicted.noise_voltage: missing, and spec.electronics gives none of "
                              "noise, noise_rti, noise_strain; one is required")
    value = output_noise(excitation, gain, factor, bridge_factor, noise, noise_rti, noise_strain)
    return _bounded_noise(value, f"spec.electronics: the output noise it gives, {value:g}")


def _prototype(section) -> str | None:
    if not isinstance(section, dict):
        return None
    for letter, (kind, dims) in PROTOTYPE_SECTIONS.items():
        if section.get("kind") == kind and all(
                isinstance(section.get(k), (int, float)) and abs(section[k] - v) <= PROTOTYPE_MATCH
                for k, v in dims.items()):
            return letter
    return None


def design_constants(record: dict) -> DesignConstants:
    """The constants of a design.json record; DesignFileError names a missing or bad key."""
    if not isinstance(record, dict):
        raise DesignFileError("design.json: must be a JSON object with keys 'spec', 'design' and 'predicted'")
    spec = _require(record, "spec", "")
    design = _require(record, "design", "")
    predicted = _require(record, "predicted", "")
    if not isinstance(predicted, dict):
        raise DesignFileError(f"predicted: {brief(predicted)} must be an object of the predicted figures")
    raw_stations = _require(design, "stations", "design")
    if not isinstance(raw_stations, list) or len(raw_stations) < 2:
        raise DesignFileError(f"design.stations: {brief(raw_stations)} must be a list of at least 2 positions (m)")
    stations = tuple(json_number(s, f"design.stations[{i}]", positive=True) for i, s in enumerate(raw_stations))
    if any(b <= a for a, b in zip(stations, stations[1:])):
        raise DesignFileError(f"design.stations: {list(stations)!r} must increase from the clamp outwards")
    raw_k = predicted.get("sensitivity")
    if not isinstance(raw_k, list) or len(raw_k) != len(stations):
        raise DesignFileError(f"predicted.sensitivity: {raw_k!r} must list k (V/(N m)) for each of the "
                              f"{len(stations)} stations")
    k = tuple(json_number(v, f"predicted.sensitivity[{i}]", positive=True) for i, v in enumerate(raw_k))
    axes = design.get("axes", spec.get("axes", 1))
    if axes not in (1, 2):
        raise DesignFileError(f"design.axes: {axes!r} is not allowed; must be one of [1, 2]")
    load = _require(spec, "load", "spec")
    force = _pair(_require(load, "force", "spec.load"), "spec.load.force")
    position = _pair(_require(load, "position", "spec.load"), "spec.load.position")
    problem = stations_before_load(stations, position[0])
    if problem is not None:
        raise DesignFileError(f"design.{problem[0]}: {problem[1]}")
    name = spec.get("name") or "design"
    return DesignConstants(str(name), stations, k, _noise_from(record), int(axes), force, position,
                           _prototype(design.get("section")), _volts_per_count(predicted))


def _volts_per_count(predicted: dict) -> float | None:
    """Volts at the amplifier output per count of the converter, ``gain / counts_per_volt`` of
    ``predicted.front_end`` (docs/spec.md §4); None without a catalogue front-end."""
    fe = predicted.get("front_end")
    if fe is None:
        return None
    if not isinstance(fe, dict):
        raise DesignFileError(f"predicted.front_end: {brief(fe)} must be an object")
    gain = json_number(_require(fe, "gain", "predicted.front_end"), "predicted.front_end.gain", positive=True)
    per_volt = json_number(_require(fe, "counts_per_volt", "predicted.front_end"),
                           "predicted.front_end.counts_per_volt", positive=True)
    return gain / per_volt
