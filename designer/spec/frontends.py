"""The front-end catalogue: bridge ADCs and instrumentation amplifiers (``materials/frontends.yaml``).

A front-end of kind ``adc`` (a programmable-gain amplifier and a delta-sigma converter on one
chip, e.g. HX711, NAU7802, ADS1232) has a table of input-referred RMS noise at each gain and
output data rate it offers; only those pairs can be chosen. One of kind ``amplifier`` (an
instrumentation amplifier before a converter the user names by its bits and reference) has a
white input noise density and a gain range. Every figure names its datasheet.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

from designer.errors import CatalogueError, SpecError, brief, describe_allowed
from designer.spec.catalogue import quantity, read_shipped

FILE = "frontends.yaml"
KINDS = ("adc", "amplifier")
ENTRY_KEYS = ("name", "description", "kind", "resolution", "full_scale", "reference", "gains", "gain_range",
              "rates", "rate_range", "noise", "noise_density", "excitation", "offset_drift", "gain_drift", "source")
NOISE_KEYS = ("gain", "rate", "rms")


@dataclass(frozen=True)
class FrontEnd:
    """One front-end. ``full_scale``: the differential input range is ``±full_scale·V_ref/gain``;
    ``reference`` ``excitation`` means the converter's reference is the bridge's excitation
    (ratiometric), ``external`` that the spec gives it. ``noise`` maps ``(gain, rate)`` to the
    input-referred RMS noise, V (kind adc); ``noise_density`` is V/sqrt(Hz) (kind amplifier)."""

    name: str
    kind: str
    full_scale: float
    reference: str
    source: str
    description: str = ""
    resolution: int | None = None          # bits; an amplifier's converter is the spec's
    noise: tuple = ()                      # ((gain, rate, rms V), ...), kind adc
    noise_density: float | None = None     # V/sqrt(Hz), kind amplifier
    gain_range: tuple | None = None        # (low, high), kind amplifier
    rate_range: tuple | None = None        # (low, high) Hz where noise_density holds, kind amplifier
    excitation: tuple | None = None        # (low, high) V the front-end can supply or accept
    offset_drift: float | None = None      # input-referred, V/K
    gain_drift: float | None = None        # 1/K

    def rates(self) -> tuple:
        return tuple(sorted({r for _, r, _ in self.noise}))

    def gains(self, rate: float | None = None) -> tuple:
        return tuple(sorted({g for g, r, _ in self.noise if rate is None or r == rate}))

    def adc_noise(self, gain: float, rate: float) -> float:
        """The converter's input-referred RMS noise at ``gain`` and ``rate``, V."""
        if self.kind == "amplifier":
            from designer.model.electronics import noise_bandwidth

            return self.noise_density * noise_bandwidth(rate) ** 0.5
        return next(rms for g, r, rms in self.noise if g == gain and r == rate)


def _number(value, key: str, positive: bool = True) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (positive and not value > 0):
        raise CatalogueError(f"{key}: {value!r} must be a number" + (" > 0" if positive else ""))
    return float(value)


def _density(value, key: str) -> float:
    """A white noise density written ``"50 nV/√Hz"`` (or ``/rtHz``), V/sqrt(Hz)."""
    if isinstance(value, str):
        for suffix in ("/√Hz", "/rtHz", "/sqrt(Hz)"):
            if value.strip().endswith(suffix):
                return quantity(value.strip()[: -len(suffix)], "voltage", key)
    raise CatalogueError(f"{key}: {value!r} must be a noise density such as '50 nV/√Hz'")


def _pair(value, kind: str, key: str) -> tuple:
    if not isinstance(value, list) or len(value) != 2:
        raise CatalogueError(f"{key}: {value!r} must be [low, high]")
    low, high = (quantity(v, kind, key) if kind else _number(v, key) for v in value)
    if not low <= high:
        raise CatalogueError(f"{key}: {value!r} must be [low, high] with low <= high")
    return low, high


def parse_entry(entry, where: str) -> FrontEnd:
    """One catalogue entry, every key checked (CatalogueError names the entry and the key)."""
    from designer.spec import stock as stock_file

    if not isinstance(entry, dict) or not isinstance(entry.get("name"), str) or not entry["name"].strip():
        raise CatalogueError(f"{where}: {brief(entry)} must be a mapping with a name")
    key = f"{where} ({entry['name']})"
    stock_file.known_keys(entry, ENTRY_KEYS, key)
    for k in ("kind", "full_scale", "reference", "source"):
        stock_file.required(entry, k, key)
    kind = entry["kind"]
    if kind not in KINDS:
        raise CatalogueError(f"{key}.kind: {kind!r} is not allowed; must be {describe_allowed(KINDS)}")
    if entry["reference"] not in ("excitation", "external"):
        raise CatalogueError(f"{key}.reference: {entry['reference']!r} must be excitation or external")
    if not isinstance(entry["source"], str) or not entry["source"].strip():
        raise CatalogueError(f"{key}.source: must be a text naming the datasheet")
    fields = dict(name=entry["name"].strip(), kind=kind, full_scale=_number(entry["full_scale"], f"{key}.full_scale"),
                  reference=entry["reference"], source=entry["source"], description=str(entry.get("description", "")))
    if kind == "adc":
        for k in ("resolution", "noise"):
            stock_file.required(entry, k, key)
        fields["resolution"] = int(_number(entry["resolution"], f"{key}.resolution"))
        rows = entry["noise"]
        if not isinstance(rows, list) or not rows:
            raise CatalogueError(f"{key}.noise: must be a list of {{gain, rate, rms}}")
        noise = []
        for i, row in enumerate(rows):
            at = f"{key}.noise[{i}]"
            if not isinstance(row, dict):
                raise CatalogueError(f"{at}: {brief(row)} must be a mapping with keys {describe_allowed(NOISE_KEYS)}")
            stock_file.known_keys(row, NOISE_KEYS, at)
            for k in NOISE_KEYS:
                stock_file.required(row, k, at)
            noise.append((_number(row["gain"], f"{at}.gain"), quantity(row["rate"], "frequency", f"{at}.rate"),
                          quantity(row["rms"], "voltage", f"{at}.rms")))
        fields["noise"] = tuple(noise)
    else:
        for k in ("noise_density", "gain_range"):
            stock_file.required(entry, k, key)
        fields["noise_density"] = _density(entry["noise_density"], f"{key}.noise_density")
        fields["gain_range"] = _pair(entry["gain_range"], "", f"{key}.gain_range")
        if entry.get("rate_range") is not None:
            fields["rate_range"] = _pair(entry["rate_range"], "frequency", f"{key}.rate_range")
    if entry.get("excitation") is not None:
        fields["excitation"] = _pair(entry["excitation"], "voltage", f"{key}.excitation")
    if entry.get("offset_drift") is not None:
        fields["offset_drift"] = quantity(entry["offset_drift"], "voltage_drift", f"{key}.offset_drift")
    if entry.get("gain_drift") is not None:
        fields["gain_drift"] = quantity(entry["gain_drift"], "drift", f"{key}.gain_drift")
    return FrontEnd(**fields)


@functools.lru_cache(maxsize=1)
def catalogue() -> dict[str, FrontEnd]:
    """Every front-end of the shipped catalogue, by name."""
    entries = read_shipped(FILE)
    return {fe.name: fe for fe in (parse_entry(e, f"{FILE}[{i}]") for i, e in enumerate(entries))}


def front_end(name, key: str = "electronics.adc") -> FrontEnd:
    table = catalogue()
    if name not in table:
        raise SpecError(f"{key}: {name!r} is not in the front-end catalogue; must be {describe_allowed(table)}")
    return table[name]
