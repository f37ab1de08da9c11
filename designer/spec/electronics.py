"""The spec's electronics: the bridge's excitation, the gain, and the noise, given as a figure or
by a front-end of the catalogue (``spec.frontends``; docs/spec.md §2.2)."""

from __future__ import annotations

from dataclasses import dataclass

from designer.errors import SpecError, describe_allowed
from designer.spec import units
from designer.spec.keys import mapping as _mapping, required as _required

NOISE_KEYS = ("noise", "noise_rti", "noise_strain")
KEYS = ("excitation", "gain", *NOISE_KEYS, "adc", "rate", "bits", "reference")


@dataclass(frozen=True)
class Electronics:
    excitation: float                  # V
    gain: float
    noise: float | None = None         # sigma_V at the amplifier output, V
    noise_rti: float | None = None     # referred to the bridge input, V
    noise_strain: float | None = None  # as an equivalent strain
    adc: str | None = None             # a front-end of the catalogue (spec.frontends), instead of a noise key
    rate: float | None = None          # its output data rate, Hz
    bits: int | None = None            # the converter after an amplifier front-end
    reference: float | None = None     # that converter's reference, V (the excitation if not given)

    @property
    def front_end(self):
        """The catalogue entry of ``adc`` (None without one)."""
        from designer.spec import frontends

        return None if self.adc is None else frontends.front_end(self.adc)


def parse_electronics(raw) -> Electronics:
    """The spec's ``electronics``: exactly one noise key, or a front-end of the catalogue (``adc``)."""
    raw = _mapping(raw, "electronics", KEYS)
    excitation = units.parse_positive(_required(raw, "excitation", "electronics"), "voltage",
                                      "electronics.excitation")
    if raw.get("adc") is not None:
        return _front_end(raw, excitation)
    extra = [k for k in ("rate", "bits", "reference") if raw.get(k) is not None]
    if extra:
        raise SpecError(f"electronics.{extra[0]}: only with a front-end of the catalogue (electronics.adc); "
                        "without one give the noise as noise, noise_rti or noise_strain")
    gain = units.parse_positive(raw.get("gain", 1.0), "ratio", "electronics.gain")
    given = [k for k in NOISE_KEYS if raw.get(k) is not None]
    if len(given) != 1:
        what = "none is given" if not given else f"{len(given)} are given ({', '.join(given)})"
        raise SpecError("electronics: give exactly one of [noise, noise_rti, noise_strain] "
                        f"(RMS noise per channel), or a front-end as electronics.adc; {what}")
    kind = "strain" if given[0] == "noise_strain" else "voltage"
    value = units.parse_positive(raw[given[0]], kind, f"electronics.{given[0]}")
    return Electronics(excitation=excitation, gain=gain, **{given[0]: value})


def _front_end(raw: dict, excitation: float) -> Electronics:
    """``electronics`` naming a front-end of the catalogue: its gain and rate must be ones it
    offers (by default its lowest rate and, at it, its highest gain); an amplifier's converter is
    given by ``bits`` (and ``reference``, else the excitation)."""
    from designer.spec import frontends

    name = raw["adc"]
    if not isinstance(name, str):
        raise SpecError(f"electronics.adc: {name!r} must be the name of a front-end; must be "
                        f"{describe_allowed(frontends.catalogue())}")
    fe = frontends.front_end(name.strip())
    given = [k for k in NOISE_KEYS if raw.get(k) is not None]
    if given:
        raise SpecError(f"electronics.{given[0]}: not with electronics.adc ({fe.name}): the front-end's noise is "
                        "its catalogue figure; give one or the other")
    if fe.excitation is not None and not fe.excitation[0] <= excitation <= fe.excitation[1]:
        raise SpecError(f"electronics.excitation: {excitation:g} V is outside what {fe.name} works with; must be "
                        f"{fe.excitation[0]:g} V to {fe.excitation[1]:g} V")
    if fe.kind == "adc":
        rates = fe.rates()
        rate = units.parse_positive(raw.get("rate", rates[0]), "frequency", "electronics.rate")
        match = [r for r in rates if abs(r - rate) <= 1e-9 * r]
        if not match:
            raise SpecError(f"electronics.rate: {rate:g} Hz is not a rate {fe.name} offers; must be one of "
                            + ", ".join(f"{r:g} Hz" for r in rates))
        rate = match[0]
        gains = fe.gains(rate)
        gain = units.parse_positive(raw.get("gain", gains[-1]), "ratio", "electronics.gain")
        if gain not in gains:
            raise SpecError(f"electronics.gain: {gain:g} is not a gain {fe.name} offers at {rate:g} Hz; must be one "
                            "of " + ", ".join(f"{g:g}" for g in gains))
        for k in ("bits", "reference"):
            if raw.get(k) is not None:
                raise SpecError(f"electronics.{k}: not with {fe.name}, which has its own converter; "
                                "only an amplifier front-end takes the converter's bits and reference")
        return Electronics(excitation=excitation, gain=gain, adc=fe.name, rate=rate)
    for k in ("gain", "rate", "bits"):
        _required(raw, k, "electronics")
    gain = units.parse_positive(raw["gain"], "ratio", "electronics.gain")
    low, high = fe.gain_range
    if not low <= gain <= high:
        raise SpecError(f"electronics.gain: {gain:g} is outside {fe.name}'s gain range; must be {low:g} to {high:g}")
    rate = units.parse_positive(raw["rate"], "frequency", "electronics.rate")
    if fe.rate_range is not None and not fe.rate_range[0] <= rate <= fe.rate_range[1]:
        low, high = fe.rate_range
        raise SpecError(f"electronics.rate: {rate:g} Hz is outside the rates where {fe.name}'s noise density holds; "
                        f"must be {low:g} Hz to {high:g} Hz")
    bits = raw["bits"]
    if isinstance(bits, bool) or not isinstance(bits, int) or not 8 <= bits <= 32:
        raise SpecError(f"electronics.bits: {bits!r} must be the converter's resolution, a whole number of bits "
                        "from 8 to 32")
    reference = (units.parse_positive(raw["reference"], "voltage", "electronics.reference")
                 if raw.get("reference") is not None else None)
    if reference is not None and fe.excitation is not None and reference > fe.excitation[1]:
        raise SpecError(f"electronics.reference: {reference:g} V is above what {fe.name} can output (its supply is "
                        f"{fe.excitation[0]:g} V to {fe.excitation[1]:g} V); must be at most {fe.excitation[1]:g} V")
    return Electronics(excitation=excitation, gain=gain, adc=fe.name, rate=rate, bits=bits, reference=reference)
