"""From gauge strain to bridge volts, and the noise per channel (docs/model.md §3)."""

from __future__ import annotations

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
