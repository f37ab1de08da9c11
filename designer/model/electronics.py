"""From gauge strain to bridge volts, and the noise per channel (docs/model.md §3)."""

from __future__ import annotations

from dataclasses import dataclass

# Active arms of a bridge: n in k = V_s G g n y_g / (4 E I_s).
BRIDGE_FACTORS = {"quarter": 1, "half": 2, "full": 4}


def volts_per_strain(excitation, gauge_factor, gain, bridge_factor):
    """Amplifier output per unit gauge strain, ``V_s G g n / 4`` (paper eqs. 4-7)."""
    return excitation * gauge_factor * gain * bridge_factor / 4


def output_noise(excitation, gain, gauge_factor, bridge_factor, noise=None, noise_rti=None,
                 noise_strain=None) -> float:
    """sigma_V, the noise per channel at the amplifier output, V, from whichever of ``noise``
    (output), ``noise_rti`` (referred to the bridge input) or ``noise_strain`` (equivalent
    gauge strain) is given, in that order of precedence (docs/model.md §3)."""
    if noise is not None:
        return noise
    if noise_rti is not None:
        return gain * noise_rti
    return excitation * gauge_factor * gain * bridge_factor * noise_strain / 4


# The front-end's noise (docs/model.md §3): the converter's, the bridge's Johnson noise and the
# quantisation step, each referred to the bridge output and added in quadrature.
BOLTZMANN = 1.380649e-23   # J/K, exact since the 2019 SI
ROOM_TEMPERATURE = 296.15  # K (23 °C): the bridge's temperature for its Johnson noise


def noise_bandwidth(rate: float) -> float:
    """The equivalent noise bandwidth of readings taken at ``rate``, Hz: a converter that averages
    its input over each conversion period ``1/rate`` (a sinc response) has ENBW ``rate/2``."""
    return rate / 2


def johnson_noise(resistance: float, bandwidth: float, temperature: float = ROOM_TEMPERATURE) -> float:
    """The thermal (Johnson-Nyquist) noise of ``resistance`` in ``bandwidth``, V RMS: ``sqrt(4 k T R B)``.
    A Wheatstone bridge of four equal arms R has an output resistance of R (two R/2 in series)."""
    return (4 * BOLTZMANN * temperature * resistance * bandwidth) ** 0.5


@dataclass(frozen=True)
class FrontEndNoise:
    """A front-end's noise and range, every voltage referred to the bridge output (V)."""

    converter: float      # the converter's (or amplifier's) own RMS noise
    johnson: float        # the bridge's thermal noise in the readings' noise bandwidth
    quantisation: float   # one code step / sqrt(12)
    full_scale: float     # the input range is +-full_scale
    step: float           # one code

    @property
    def total(self) -> float:
        return (self.converter ** 2 + self.johnson ** 2 + self.quantisation ** 2) ** 0.5

    @property
    def counts_per_volt(self) -> float:
        return 1 / self.step


def front_end_noise(front_end, gain: float, rate: float, excitation: float, resistance: float,
                    bits: int | None = None, reference: float | None = None) -> FrontEndNoise:
    """The noise and range of ``front_end`` (a ``spec.frontends.FrontEnd``) at ``gain`` and ``rate``
    reading a bridge of output resistance ``resistance`` excited at ``excitation``. The input range
    is ``±full_scale·V_ref/gain``, with ``V_ref`` the excitation for a ratiometric front-end; a
    converter of N bits divides twice that into 2^N codes. ``bits`` and ``reference`` are the
    converter's after an amplifier (the front-end's own resolution otherwise)."""
    v_ref = excitation if front_end.reference == "excitation" or reference is None else reference
    full_scale = front_end.full_scale * v_ref / gain
    n = front_end.resolution if bits is None else bits
    step = 2 * full_scale / 2 ** n
    return FrontEndNoise(converter=front_end.adc_noise(gain, rate),
                         johnson=johnson_noise(resistance, noise_bandwidth(rate)),
                         quantisation=step / 12 ** 0.5, full_scale=full_scale, step=step)
