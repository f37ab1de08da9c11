"""The forward model: every predicted quantity of one design (docs/model.md §3-4)."""

from __future__ import annotations

import math

from dataclasses import dataclass
from typing import Any

from designer.model import corrections
from designer.model.adjust import Adjustment
from designer.model.budget import effective_rigidity, region_budget
from designer.model.beam import channel_deflection, natural_frequency, tip_deflection
from designer.model.biaxial import side_features
from designer.model.corrections import Corrections
from designer.model.electronics import volts_per_strain
from designer.model.estimator import sigmas
from designer.model.ops import NUMERIC, PEAK_SMOOTHING, Ops, ops_for, rounded_max
from designer.model.sections import Geometry, SectionProperties, channel_inertia, section_properties

# The optimiser passes the material as parameters in GPa, MPa and kg/m^3 so that the NLP's
# numbers stay near one.
E_UNIT = 1e9
STRESS_UNIT = 1e6
LENGTH_UNIT = 1e-3
PPM = 1e-6
PERCENT = 1e-2
# A biaxial sensor's notch peaks this much higher under a load at its worst angle (15-30 degrees
# off a flat's axis on a round bar, either side on a square) than under one along an axis: the
# largest of a 3-D sweep of the load's angle over nine designs (benchmarks/biaxial_peak.md).
DIRECTION_FACTOR = {"round": 1.08, "tube": 1.08, "rectangle": 1.06}


@dataclass(frozen=True)
class MaterialParams:
    """The material as the model needs it; floats, or casadi parameters."""

    E: Any
    allowable: Any          # min(yield, fatigue if used) / safety factor, Pa: the root's and the fatigue limit
    density: Any
    static_allowable: Any = None  # yield / safety factor, Pa: the nominal stress at a feature (docs/model.md §4);
                                  # None: the same as ``allowable``
    notch_length: Any = 0.0       # Peterson's characteristic length a, m (materials.yaml notch_length)
    poisson: Any = 0.3            # Poisson's ratio: the shear modulus G = E / (2 (1 + nu)) of the shear deflection
    modulus_tc: Any = 0.0         # (1/E) dE/dT, 1/K (the error budget's span drift)
    expansion: Any = 0.0          # thermal expansion coefficient, 1/K (the gauges' thermal output)
    creep: Any = 0.0              # the output's creep under a constant load over 30 min, as a fraction

    def __post_init__(self):
        if self.static_allowable is None:
            object.__setattr__(self, "static_allowable", self.allowable)

    @classmethod
    def of(cls, material, limits) -> "MaterialParams":
        """A catalogue material under the spec's ``limits`` (safety factor, fatigue)."""
        return cls(material.E, material.allowable_stress(limits.safety_factor, limits.fatigue), material.density,
                   material.allowable_stress(limits.safety_factor, False), material.notch_length, material.poisson,
                   *(getattr(material, k) or 0.0 for k in ("modulus_tc", "expansion", "creep")))

    def scaled(self) -> list:
        """``[E, allowable, density, static allowable, notch length, Poisson's ratio, modulus_tc,
        expansion, creep]`` in the optimiser's parameter units (GPa, MPa, kg/m^3, MPa, mm, 1,
        ppm/K, ppm/K, %)."""
        return [self.E / E_UNIT, self.allowable / STRESS_UNIT, self.density, self.static_allowable / STRESS_UNIT,
                self.notch_length / LENGTH_UNIT, self.poisson, self.modulus_tc / PPM, self.expansion / PPM,
                self.creep / PERCENT]

    @classmethod
    def from_scaled(cls, p) -> "MaterialParams":
        """The inverse of ``scaled``: ``p`` may be numbers, arrays or casadi parameters."""
        return cls(p[0] * E_UNIT, p[1] * STRESS_UNIT, p[2], p[3] * STRESS_UNIT, p[4] * LENGTH_UNIT, p[5],
                   p[6] * PPM, p[7] * PPM, p[8] * PERCENT)


@dataclass(frozen=True)
class Analysis:
    """Every predicted quantity of docs/model.md §3-4 for one design (SI)."""

    props: SectionProperties
    sensitivity: Any          # k of the beam model at a reduced section, V/(N m), before the corrections
    sensitivities: tuple      # k_i per station with the feature and clamp corrections (what is reported)
    sigma_v: float            # V
    force_error: Any          # sigma_F / F_min
    position_error: Any       # sigma_x(F_min, x_max), m
    stress_root: Any
    stress_feature: Any       # nominal, at the first feature's clamp-side edge
    stress_concentration: Any  # K_t: the features' largest peak over stress_feature (docs/model.md §4, §7)
    notch_sensitivity: Any    # Peterson's q = r / (r + a) at the feature's notch radius r
    gauge_strain: tuple       # at F_max, x_max, per station
    min_signal_snr: Any
    deflection: Any           # free end, m
    natural_frequency: Any
    mass: Any
    noise_strain: Any         # the noise as an equivalent gauge strain
    noise_force_error: Any = None     # sigma_F / F_min and sigma_x(F_min, x_max) of the noise alone
    noise_position_error: Any = None
    budget: Any = None        # with spec.environment: each corner's (F, x, contributions) (model.budget)
    # A biaxial sensor's features (docs/model.md §9): their notch's own nominal stress over
    # stress_feature (the single-axis fibre over the plain extreme fibre), and how much a load at the
    # worst angle raises the notch's peak over one along an axis; 1 for a single axis
    notch_fibre: Any = 1.0
    direction_factor: float = 1.0

    @property
    def max_stress(self):
        return max(self.stress_root, self.stress_feature)

    @property
    def stress_notch(self):
        """The nominal stress the features' K_t multiplies: stress_feature, or on a biaxial sensor
        the single-axis fibre's (a flat's floor, a square's face)."""
        return self.notch_fibre * self.stress_feature

    @property
    def stress_peak_axis(self):
        """The features' peak stress under a load along a bending axis: K_t times the notch's nominal."""
        return self.stress_concentration * self.stress_notch

    @property
    def stress_peak(self):
        """The peak stress at the features: K_t times the first feature's nominal stress (on a
        biaxial sensor, at the worst load direction)."""
        return self.direction_factor * self.stress_peak_axis

    @property
    def fatigue_factor(self):
        """K_f at the feature (docs/model.md §4), of the worst load direction's K_t."""
        return fatigue_factor(self.notch_sensitivity, self.direction_factor * self.stress_concentration)

    @property
    def stress_fatigue(self):
        """The stress the fatigue limit checks at the feature: K_f times the nominal stress; on a
        biaxial sensor K_f times the notch's nominal, or the plain extreme fibre's nominal stress
        where that is larger (a square's corner at 45 degrees)."""
        notched = self.fatigue_factor * self.stress_notch
        if self.direction_factor == 1.0:
            return notched
        plain = self.stress_feature
        return rounded_max(notched, plain, PEAK_SMOOTHING * plain, ops_for(notched, plain))


def analyse(g: Geometry, m: MaterialParams, spec, ops: Ops = NUMERIC, table: Corrections | None = None,
            adjust: Adjustment | None = None) -> Analysis:
    """The forward model for geometry ``g`` of material ``m`` under ``spec`` (a Spec), with the
    feature corrections of ``table`` (the shipped one by default; ``Corrections({})``: none) and
    the design's 3-D/model factors ``adjust`` (none by default: the plain model)."""
    load, e = spec.load, spec.electronics
    sp = section_properties(g, ops)
    gain = volts_per_strain(e.excitation, spec.gauge.factor, e.gain, spec.bridge_factor)
    # k = V_s G g n y_g / (4 E I_s), written in the order of operations the casadi graph has
    # always had (4 * gain is exactly V_s G g n): IPOPT's path depends on it at rounding level
    k = 4 * gain * sp.y_g / (4 * m.E * sp.I_s)
    table = corrections.load() if table is None else table
    # per-station factors on the gauge strain (and so on k_i): the feature and clamp corrections,
    # then the design's 3-D/model ratios
    station_factors = [corrections.strain_factors(g, table, ops, m.poisson)]
    arc = grid_arc_factor(g, ops)
    if arc is not None:
        station_factors.append([arc] * len(g.stations))
    if adjust is not None:
        if len(adjust.gauge_strain) != len(g.stations):
            raise ValueError(f"adjustment.gauge_strain: {len(adjust.gauge_strain)} factors for "
                             f"{len(g.stations)} stations")
        station_factors.append(adjust.gauge_strain)
    ks = _scaled([k] * len(g.stations), station_factors)
    sigma_v = spec.sigma_v
    d = list(g.stations)
    f_min, f_max, x_min, x_max = load.force_min, load.force_max, load.position_min, load.position_max
    sigma_f, position_error = sigmas(ks, d, sigma_v, f_min, x_max, ops)
    force_error = sigma_f / f_min
    noise_errors = (force_error, position_error)

    l_f = g.feature_length
    # each feature's moment arm under F_max at x_max, from its clamp-side edge
    arms = [x_max - (di - l_f / 2) for di in d]
    # the wire channels, where there are any, run into the clamp
    stress_root = f_max * x_max * sp.y_root / (sp.I - channel_inertia(g, ops))
    stress_feature = f_max * arms[0] * sp.y_e / sp.I_s
    strains = _scaled([f_max * (x_max - di) * sp.y_g / (m.E * sp.I_s) for di in d], station_factors)
    snr = ks[-1] * f_min * (x_min - d[-1]) / sigma_v

    widened = corrections.widened(g, table)
    deflection = tip_deflection(widened, sp, m.E, f_max, x_max) + channel_deflection(g, sp, m.E, f_max, x_max, ops)
    stiffness = corrections.stiffness_fit(table)
    if stiffness is not None:
        deflection = deflection + stiffness.extra_deflection(g, sp, m.E, m.poisson, f_max, x_max, ops)
    if adjust is not None:
        deflection = deflection * adjust.deflection
    budget_points = None
    if spec.environment is not None:  # the whole error budget (docs/model.md §13) replaces the noise alone
        rigidity = effective_rigidity(deflection, f_max, x_max, g.length)
        force_error, position_error, budget_points = region_budget(ks, d, strains, spec, m, ops, rigidity)
    frequency = natural_frequency(sp, m.E, m.density, g.length, ops)
    mass = m.density * (sp.A * g.length - len(d) * sp.feature_volume)
    noise_strain = sigma_v / gain
    kt = peak_concentration(corrections.stress_concentrations(g, table), arms, ops)
    if adjust is not None:
        kt = kt * adjust.stress_concentration
    q = notch_sensitivity(notch_radius(g), m.notch_length)
    notch, direction = 1.0, 1.0
    if side_features(g):
        # the K_t fits are single-axis designs', on the fibre a single-axis nominal takes: a flat's
        # floor R - p (y_g), a square's face h/2; stress_feature is at the plain extreme fibre (§9)
        notch = (g.height / 2 if g.section == "rectangle" else sp.y_g) / sp.y_e
        direction = DIRECTION_FACTOR[g.section]
    return Analysis(sp, k, ks, sigma_v, force_error, position_error, stress_root, stress_feature, kt, q,
                    strains, snr, deflection, frequency, mass, noise_strain, *noise_errors, budget_points,
                    notch, direction)


def _scaled(values: list, factor_lists: list) -> tuple:
    """``values`` times each list of per-station factors in turn (an empty list: none)."""
    for factors in factor_lists:
        if factors:
            values = [v * c for v, c in zip(values, factors)]
    return tuple(values)


WIDEST_GRID = 1 - 1e-6   # the largest grid width over the diameter grid_arc_factor takes


def grid_arc_factor(g: Geometry, ops: Ops = NUMERIC):
    """The strain a gauge grid of width ``w`` reads on the round surface of a bar or tube (no flat
    under it) over the top fibre's: across the grid the surface falls away from ``y_g = R`` as
    ``sqrt(R^2 - s^2)`` (``s`` across the beam), and the bending strain with it, so the grid
    averages ``(a sqrt(1 - a^2) + asin a) / (2 a)`` with ``a = w / (2 R) = w / D``. None where the
    gauge sits on a flat face (rectangles, pockets, flats) or the grid's width is not known."""
    if g.section == "rectangle" or g.feature != "none" or not g.grid_width:
        return None
    # a grid wider than the bar breaks gauge_face; there the factor is held at a's largest, short of
    # 1, where the square root's derivative is infinite: its value and derivative stay numbers (an
    # optimiser's start point may be such a bar)
    a = ops.fmin(g.grid_width / g.diameter, WIDEST_GRID)
    return (a * ops.sqrt(1 - a * a) + (math.pi / 2 - ops.acos(a))) / (2 * a)


def peak_concentration(kts, arms, ops: Ops = NUMERIC):
    """The features' peak stress over the first one's nominal stress: the largest of each
    feature's ``K_t,i`` times its nominal stress over the first's (its moment arm ``x - a_i`` over
    ``x - a_1``, the sections being the same). The first feature carries the largest moment, but
    one further from the clamp may have the higher K_t (a fit in the clamp's nearness) and so the
    peak; where every K_t is the same, the first's is the peak. The maximum is rounded off where
    two features come within PEAK_SMOOTHING of the first's K_t of each other (``ops.rounded_max``:
    never below the maximum, the maximum itself beyond). Taking K_f from
    this K_t errs safe: ``1 + q (K_t,i r_i - 1) >= r_i (1 + q (K_t,i - 1))`` for ``r_i <= 1``."""
    if all(k is kts[0] for k in kts[1:]):  # one K_t shared by every feature (no clamp term)
        return kts[0]
    width = PEAK_SMOOTHING * kts[0]
    out = kts[0]
    for k, arm in zip(kts[1:], arms[1:]):
        out = rounded_max(out, k * arm / arms[0], width, ops)
    return out


def fatigue_factor(notch_sensitivity, stress_concentration):
    """``K_f = 1 + q (K_t - 1)``: the fatigue notch factor of a notch of sensitivity ``q``."""
    return 1 + notch_sensitivity * (stress_concentration - 1)


def notch_radius(g: Geometry):
    """The root radius of the feature's notch: a pocket's floor radius, a hole's radius; 0 without one."""
    return {"pocket": g.floor_radius, "hole": g.hole / 2}.get(g.feature, 0.0)


def notch_sensitivity(radius, notch_length):
    """Peterson's notch sensitivity ``q = 1 / (1 + a / r) = r / (r + a)`` (R. E. Peterson, "Notch
    sensitivity", in G. Sines and J. L. Waisman (eds.), Metal Fatigue, McGraw-Hill, 1959; as used in
    N. E. Dowling, Mechanical Behavior of Materials, §10.3). A material without a constant
    (``a = 0``) is fully notch sensitive, ``q = 1``; a feature without a notch has ``q = 0``."""
    if isinstance(radius, (int, float)) and radius == 0:
        return 0.0
    return radius / (radius + notch_length)

