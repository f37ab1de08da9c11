"""The spec's ``environment`` (operating temperatures, calibration temperature, hold time) and
``calibration`` (weights' class, placement of the load) blocks: what the error budget needs
beyond the electronics (docs/spec.md §2.10, docs/model.md §13)."""

from __future__ import annotations

from dataclasses import dataclass

from designer.errors import SpecError, describe_allowed
from designer.spec import catalogue, units
from designer.spec.keys import mapping, required

ROOM = 296.15  # K: 23 °C, the usual calibration temperature
HOLD = 1800.0  # s: OIML R 60's creep test lasts 30 min

#: OIML R 111-1:2004, Table 1: the maximum permissible error of a 1 kg weight of each class
#: (E1 0.5 mg ... M3 500 mg), as a fraction of its mass. Smaller weights have larger relative
#: errors (an M1 100 g weight 5 mg, 10 g 2 mg): the figure suits weights of about 100 g and up.
WEIGHT_CLASSES = {"E1": 0.5e-6, "E2": 1.6e-6, "F1": 5e-6, "F2": 16e-6, "M1": 50e-6, "M2": 160e-6, "M3": 500e-6}


@dataclass(frozen=True)
class Environment:
    temperature: tuple        # (low, high), K
    calibrated_at: float = ROOM
    hold: float = HOLD        # s: how long a load stays on (creep)
    tare: bool = False        # the offsets are re-measured unloaded at the operating temperature (no zero drift)

    @property
    def swing(self) -> float:
        """The largest distance from the calibration temperature to either end of the range, K."""
        low, high = self.temperature
        return max(high - self.calibrated_at, self.calibrated_at - low)


@dataclass(frozen=True)
class CalibrationSetup:
    weights: str = "M1"        # OIML R 111 class of the calibration weights
    placement: float = 0.1e-3  # the worst error in placing the load on the beam, m

    @property
    def weights_error(self) -> float:
        """The weights' maximum permissible error as a fraction (WEIGHT_CLASSES)."""
        return WEIGHT_CLASSES[self.weights]


def parse_environment(raw) -> Environment | None:
    if raw is None:
        return None
    raw = mapping(raw, "environment", ("temperature", "calibrated_at", "hold", "tare"))
    value = required(raw, "temperature", "environment")
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise SpecError(f"environment.temperature: {value!r} must be [lowest, highest], such as [0 °C, 40 °C]")
    for i, v in enumerate(value):
        if isinstance(v, str) and "delta" in v.lower():
            raise SpecError(f"environment.temperature[{i}]: {v!r} is a temperature difference; give a temperature, "
                            "such as 0 °C, 273 K or 32 degF")
    low, high = (units.parse(v, "temperature", f"environment.temperature[{i}]") for i, v in enumerate(value))
    for i, t in enumerate((low, high)):
        if not t > 0:
            raise SpecError(f"environment.temperature[{i}]: {value[i]!r} is at or below absolute zero; must be "
                            "above -273.15 °C (0 K)")
    if not low < high:
        raise SpecError(f"environment.temperature: {value!r} is reversed or empty; the lowest must come first")
    cal = units.parse(raw.get("calibrated_at", ROOM), "temperature", "environment.calibrated_at")
    if not low <= cal <= high:
        raise SpecError(f"environment.calibrated_at: {raw.get('calibrated_at', '23 °C')!r} is outside the operating "
                        f"temperatures; must be from {low - 273.15:g} °C to {high - 273.15:g} °C")
    hold = units.parse_positive(raw.get("hold", HOLD), "time", "environment.hold")
    tare = raw.get("tare", False)
    if not isinstance(tare, bool):
        raise SpecError(f"environment.tare: {tare!r} must be true or false")
    return Environment((low, high), cal, hold, tare)


def parse_calibration(raw) -> CalibrationSetup:
    raw = mapping(raw, "calibration", ("weights", "placement"))
    weights = raw.get("weights", "M1")
    if weights not in WEIGHT_CLASSES:
        raise SpecError(f"calibration.weights: {weights!r} is not an OIML R 111 class; must be "
                        f"{describe_allowed(WEIGHT_CLASSES)}")
    placement = units.parse_positive(raw.get("placement", 0.1e-3), "length", "calibration.placement",
                                     allow_zero=True)
    return CalibrationSetup(weights, placement)


def check_thermal(spec) -> None:
    """With an environment, the gauge and every material must give the error budget's figures."""
    missing = spec.gauge.thermal_missing()
    if missing:
        raise SpecError(f"gauge.{missing[0]}: {spec.gauge.name} does not give it, and environment needs it for the "
                        f"error budget; give {', '.join(missing)} in gauge: (docs/spec.md §2.3)")
    names = [spec.design.material] if spec.design is not None else spec.search.materials
    for name in names:
        lacking = catalogue.material(name).thermal_missing()
        if lacking:
            raise SpecError(f"environment: the material {name!r} gives no {lacking[0]}, which the error budget needs; "
                            "add it in a catalogue of your own or leave the material out")
