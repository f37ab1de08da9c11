"""Feature corrections of the beam model, fitted to the project's own 3-D study (docs/model.md §7).

Euler-Bernoulli theory with closed-form sections misjudges a feature's neighbourhood: the gauge
strain over a pocket or a hole, the compliance of a reduced section (its influence spreads past
its ends) and the strain near the clamp. Each is corrected by a factor of dimensionless geometry,
fitted to ``fpdesign verify``'s 3-D elasticity over a parametric grid (``checks.study``) and
shipped as ``materials/corrections.yaml``:

- ``strain``: 3-D gauge strain over the beam model's, away from the clamp;
- ``extra_length``: how much longer, in section sizes, each reduced span acts (``Δ/2`` at each
  end), so that beam theory with EI(s) piecewise gives the 3-D free-end deflection;
- ``clamp``: the strain of a station near the clamp over the same station far from it (one fit
  for every family, under ``plain``: the clamp's restraint of the anticlastic bending of a wide
  bar, ``ClampFit``);
- ``near_clamp``: a family's own near-clamp strain beyond ``clamp`` (a round bar's or tube's decay,
  ``DecayFit`` and ``EdgeFit``; a slot's share of the plain bar's loss, ``ClampShareFit``);
- ``stress``: K_t, the 3-D peak stress at the feature (a pocket's or flat's floor radius at its
  ends, a hole's edge) over the beam model's nominal stress at the feature's clamp-side edge;
  a slot's ``stress_face`` the same at its rim on the loaded outer face (K_t the larger);
- ``stiffness`` (under ``plain``, ``StiffnessFit``): the plain bar's free-end deflection beyond Euler-Bernoulli
  theory, the clamp's plate effect on a wide bar and a stubby one's shear (``checks.stiffness_study``).

A fit is a polynomial in its family's parameters, smooth so that IPOPT keeps exact derivatives,
and valid over the box of the study (its ``domain``): designs are kept inside it by limits
(``model.domain``, ``model.limits``). The parameters are computed here, for the study and the model alike.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from designer.model.biaxial import biaxial_strain_factor, biaxial_strain_room
from designer.model.ops import NUMERIC, PEAK_SMOOTHING, ops_for, rounded_max
from designer.model.sections import Geometry, Widened, shoulder_ratio  # noqa: F401 - Widened: ours to give

TABLE = "corrections.yaml"
_last: list = [None, None]   # the geometry ``parameters`` last gave (kept alive: its id is no other's), its answer


def family(g: Geometry) -> str:
    """``section-feature``, e.g. ``rectangle-pocket``: the key of a geometry's fits."""
    return f"{g.section}-{g.feature}"


def parameters(g: Geometry) -> dict:
    """The dimensionless parameters of a geometry's feature (numbers or casadi expressions); the
    last geometry's are kept, as one analysis asks for the same ones several times."""
    if _last[0] is not g:
        _last[:] = [g, _parameters(g)]
    return dict(_last[1])


def _parameters(g: Geometry) -> dict:
    size = g.size
    out = {"length_ratio": g.feature_length / size, "width_ratio": g.breadth / size, "grid_ratio": g.grid_length / size}
    if g.feature == "pocket":
        out["depth_ratio"] = g.depth / (g.wall if g.section == "tube" else size)
        out["radius_ratio"] = g.floor_radius / g.depth    # r/t of Peterson's shoulder-fillet charts
        if g.floor_radius > 0:
            # sqrt(t/r): Peterson's shoulder-fillet K_t is a polynomial in it (Pilkey & Pilkey,
            # Peterson's Stress Concentration Factors, 3rd ed., ch. 3 curve fits), as K_t - 1
            # grows like sqrt(t/r) for a sharp fillet (Neuber)
            out["notch_ratio"] = (g.depth / g.floor_radius) ** 0.5
        if g.section == "rectangle":
            out["pocket_width_ratio"] = g.pocket_width / g.width
            if g.plan_radius > 0:
                # sqrt(p/r_m): Neuber's variable of the slot's corner in plan (the end mill's radius),
                # which orders its K_t at the rim on the loaded face (docs/model.md §7)
                out["plan_notch"] = (g.depth / g.plan_radius) ** 0.5
        else:
            out[SHOULDER] = shoulder_ratio(g)
    if g.feature == "hole":
        out["hole_ratio"] = g.hole / size
    if g.section == "tube":
        out["wall_ratio"] = g.wall / size
    clamp_ratio = clamp_ratios(g)[0] if g.feature != "none" else None
    return {**out, **derived_parameters(out, clamp_ratio, ops_for(clamp_ratio, *out.values()))}


def derived_parameters(values: dict, clamp_ratio=None, ops=None) -> dict:
    """The parameters computed from the others (``DERIVED``), for the model and the study's rows alike:
    - ``clamp_near``, the first feature's nearness to the clamp, exp(-3 u) of its clamp-side end
      ``clamp_ratio`` = u sizes out (``clamp_ratios``): 0.05 one size out (none without one);
    - a pocket's grid-gap decays (``grid_gap_decays``);
    - a slot's ``side_wall_ratio`` = (b - w_p)/h: the side walls carrying the load past a slot;
    - a hole's ``hole_edge`` (``hole_edge``);
    - a flat's ``shoulder_notch`` = sqrt(s/r), ``notch_ratio`` of the highest shoulder ``s`` its
      wire channel leaves (``shoulder_ratio``)."""
    out = {}
    if clamp_ratio is not None:
        out[CLAMP_NEAR] = clamp_nearness(clamp_ratio, ops)
    if SHOULDER in values and "notch_ratio" in values:
        out[SHOULDER_NOTCH] = values["notch_ratio"] * (ops or NUMERIC).sqrt(values[SHOULDER])
    if "hole_ratio" in values:
        out[HOLE_EDGE] = hole_edge(values["hole_ratio"], ops)
    if "depth_ratio" in values:
        out.update(grid_gap_decays(values["length_ratio"], values["grid_ratio"], ops))
    if "pocket_width_ratio" in values:
        out["side_wall_ratio"] = (1 - values["pocket_width_ratio"]) * values["width_ratio"]
    return out


# How the end effects of a short flat reach its gauge grid: exp(-k g) of the gap g between the
# grid's end and the flat's, in section sizes, at a rate (per size) chosen by the round flats'
# strain fit's left-out error (docs/model.md §7). A flat's floor strain rises well above the beam
# model's as its ends close on the grid (+9 % at g = 0.11 D).
GAP_RATES = {"gap_slow": 3.7}


def grid_gap_decays(length_ratio, grid_ratio, ops=None) -> dict:
    """``{gap_slow}``: ``exp(-k (l_f - l_grid) / (2 size))`` at GAP_RATES."""
    gap = (length_ratio - grid_ratio) / 2
    return {name: (ops or NUMERIC).exp(-rate * gap) for name, rate in GAP_RATES.items()}


# ``parameters``' measure of the first feature's nearness to the clamp: its extra length and K_t
# change within about a section size of the clamp face.
CLAMP_NEAR = "clamp_near"
CLAMP_NEAR_RATE = 3.0
# A hole's K_t: the peak stays at the outer fibre over a small hole and moves to the hole's edge,
# where it grows about as 1.8 d/h, once the hole passes about half the height (the 3-D study:
# 1.03 at d/h 0.3 and 0.45, 1.11 at 0.6, 1.38 at 0.75, far from the clamp). A polynomial in d/h
# cannot turn that corner: ``hole_edge`` = softplus(k (d/h - d_0)) / k, a smooth hinge at d_0.
HOLE_EDGE = "hole_edge"
HOLE_EDGE_AT = 0.5
HOLE_EDGE_RATE = 30.0


def hole_edge(hole_ratio, ops=None):
    """``log(1 + exp(k (d/h - d_0))) / k``: about 0 below ``d_0``, ``d/h - d_0`` above it."""
    ops = ops or NUMERIC
    z = HOLE_EDGE_RATE * (hole_ratio - HOLE_EDGE_AT)
    # log(1 + e^z) as max(z, 0) + log(1 + e^-|z|): the same, without e^z overflowing on a wild
    # trial point of a global search (a hole 24 heights across)
    return (ops.fmax(z, 0) + ops.log(1 + ops.exp(-ops.fabs(z)))) / HOLE_EDGE_RATE


# A flat's K_t read at the highest shoulder its wire channel leaves (``sections.shoulder_ratio``):
# Neuber's sqrt(t/r) there is ``shoulder_notch``, sqrt(p/r) sqrt(shoulder_ratio).
SHOULDER = "shoulder_ratio"
SHOULDER_NOTCH = "shoulder_notch"
# The parameters ``derived_parameters`` computes from the others (the study's table leaves them out).
DERIVED = (CLAMP_NEAR, *GAP_RATES, "side_wall_ratio", HOLE_EDGE, SHOULDER_NOTCH)


def clamp_nearness(clamp_ratio, ops=None):
    """``exp(-CLAMP_NEAR_RATE u)`` of a feature ``u`` section sizes from the clamp face."""
    return (ops or NUMERIC).exp(-CLAMP_NEAR_RATE * clamp_ratio)


def clamp_ratios(g: Geometry) -> tuple:
    """Each station's distance from the clamp face to its feature's clamp-side end, in sizes."""
    return tuple(a / g.size for a, _ in g.reduced_spans)


def station_width_ratios(g: Geometry) -> tuple:
    """Each station's distance from the clamp face over the section's width (b, or D): the clamp
    fit's variable. The clamp's restraint spreads about one width along the beam."""
    return tuple(d / g.breadth for d in g.stations)


def width_amplitude(peak, w0, w, ops):
    """``peak (1 - exp(-((w - 1)+ / w0)^2))``: how much of its plane-strain restraint a clamp puts
    on a bar ``w = b/h`` wide (none on a square bar or a round one, ``peak`` on a wide plate)."""
    # (w - 1)+ squared: the amplitude and its derivative vanish at w = 1 (square bars are common),
    # and a product, not a power, keeps the derivatives finite where the excess is zero
    excess = (w - 1 + abs(w - 1)) / (2 * w0)
    return peak * (1 - ops.exp(-excess * excess))


CLAMP_COEFFICIENTS = ("a", "w0", "k", "u0")
SECH_REACH = 15.0   # sech(15) = 6e-7
# ClampFit's loss (fitted on 6061-T6, nu 0.33) scales with a material's Poisson's ratio as
# (nu / CLAMP_POISSON)^CLAMP_POISSON_POWER: the clamp's series in four materials (benchmarks/clamp_poisson_check.py);
# a plain round bar's or tube's own near_clamp loss as (nu / CLAMP_POISSON)^NEAR_POISSON_POWER: least squares over
# 16 study bars in 17-4PH-H900 and Ti-6Al-4V (round bars 1.13, tubes 1.08; benchmarks/feature_poisson_check.md)
CLAMP_POISSON, CLAMP_POISSON_POWER, NEAR_POISSON_POWER = 0.33, 1.4, 1.1
NEAR_POISSON_FAMILIES = ("round-none", "tube-none")


@dataclass(frozen=True)
class ClampFit:
    """``C = 1 - A(w) sech(k (u - u0))`` with ``A(w) = a (1 - exp(-((w - 1)+ / w0)^2))``: the gauge
    strain near the clamp over the same station far from it, for ``w = width_ratio`` (b/h; 1 for
    round bars and tubes, which the clamp does not disturb) and ``u = d/b`` (``station_width_ratios``).

    A rigid clamp stops the anticlastic curvature of a wide bar, so near it the bar bends in plane
    strain and the surface strain falls towards ``1 - nu^2`` of the beam's; the restraint decays
    over about one width (the sech's exponential tail). Very close to the clamp face the clamp's
    own corner raises the strain again: the ``domain`` keeps ``u`` out of that zone."""

    a: float
    w0: float
    k: float
    u0: float
    domain: dict            # station_width_ratio, width_ratio -> (low, high)
    rms: float = 0.0
    loo_max: float = 0.0

    def __call__(self, w, u, ops=None):
        ops = ops or NUMERIC
        amplitude = width_amplitude(self.a, self.w0, w, ops)
        # beyond |z| = SECH_REACH the restraint is below 1e-6 of its peak: z is held there, so
        # that a narrow bar's station many widths out does not put e^z of 1e16 into the optimiser
        z = self.k * (ops.fmin(u, self.u0 + SECH_REACH / self.k) - self.u0)
        return 1 - 2 * amplitude / (ops.exp(z) + ops.exp(-z))


STIFFNESS_COEFFICIENTS = ("plate", "w0", "reach", "shear", "shear_bore")


@dataclass(frozen=True)
class StiffnessFit:
    """The plain bar's free-end deflection beyond Euler-Bernoulli theory, as two terms added to it:

    - the clamp's plate effect: near a rigid clamp a wide bar bends in plane strain (its
      anticlastic curvature is stopped), so its curvature falls by ``A(w) exp(-s / c)`` at ``s``
      from the clamp face, ``c = reach * b``, with ``A(w) = plate (1 - exp(-((w - 1)+ / w0)^2))``
      as in ``ClampFit`` (``w = b/h``; 0 for round bars and tubes). Over the plain ``EI`` it takes
      ``F A J / EI`` off the deflection at ``l``, ``J = int_0^x exp(-s/c) (x - s)(l - s) ds
      = c x l - c^2 (x + l + e (x - l)) + 2 c^3 (1 - e)``, ``e = exp(-x/c)``;
    - shear: ``phi F x / (kappa G A)`` with Cowper's ``kappa`` (``sections.shear_coefficient``) and
      ``phi = shear + shear_bore m^2`` (``m``: a tube's bore ratio): the clamp face, held flat,
      stops part of the shear deformation Timoshenko's theory gives.
    """

    plate: float
    w0: float
    reach: float
    shear: float
    shear_bore: float
    domain: dict            # width_ratio, slenderness -> (low, high)
    rms: float = 0.0
    loo_max: float = 0.0

    def extra_deflection(self, g: Geometry, sp, E, poisson, force, x, ops=None):
        """What the plate effect and shear add to Euler-Bernoulli's free-end deflection (m; the
        plate effect takes off) for ``force`` at ``x`` on ``g`` of section properties ``sp``."""
        from designer.model.sections import bore_ratio, shear_stiffness

        ops = ops or NUMERIC
        ell = g.length
        out = 0.0
        if g.section == "rectangle":
            c = self.reach * g.breadth
            e = ops.exp(-x / c)
            J = c * x * ell - c * c * (x + ell + e * (x - ell)) + 2 * c ** 3 * (1 - e)
            out = -force * width_amplitude(self.plate, self.w0, g.width / g.height, ops) * J / (E * sp.I)
        m = bore_ratio(g)
        return out + (self.shear + self.shear_bore * m * m) * force * x / shear_stiffness(g, sp, E, poisson)


@dataclass(frozen=True)
class Fit:
    """``sum_k c_k prod_j p_j^e_kj`` over ``variables``, valid inside ``domain``."""

    variables: tuple
    exponents: tuple        # one tuple of exponents per term
    coefficients: tuple
    domain: dict            # variable -> (low, high) of the study
    rms: float = 0.0        # fit residual, and the largest leave-one-out residual
    loo_max: float = 0.0
    # the shift to the safe side the coefficients include, for a fit that does not meet its rule
    # (``checks.fits.SAFE_SIDE``): K_t times (1 + margin), the extra length + margin sizes; 0
    # for a fit that meets it
    margin: float = 0.0
    notch_top: tuple = ()   # a pocket K_t's sharpest study points by depth (``domain.NOTCH_HULL``)

    def __call__(self, values: dict):
        powers = {}  # each variable's powers taken once (a casadi graph gets a node per operation)
        total = 0.0
        for exps, c in zip(self.exponents, self.coefficients):
            term = c
            for name, e in zip(self.variables, exps):
                if e:
                    if (name, e) not in powers:
                        powers[name, e] = values[name] if e == 1 else values[name] ** e
                    term = term * powers[name, e]
            total = total + term
        return total


class _OverPolynomial:
    """A fit whose variables and residuals are its polynomial's (``poly``, a Fit)."""

    @property
    def variables(self):
        return self.poly.variables

    @property
    def rms(self):
        return self.poly.rms

    @property
    def loo_max(self):
        return self.poly.loo_max


@dataclass(frozen=True)
class DecayFit(_OverPolynomial):
    """``C = 1 + exp(-rate u) A(rate, h) P``, ``P`` a polynomial (``poly``, a Fit) in the feature's
    parameters, ``u`` the station's (the gauge grid's centre's) distance from the clamp face in
    section sizes (``station_ratios``) and ``A = sinh(rate h) / (rate h)`` the mean of the local
    decay over the grid, ``h`` half its length in sizes (``grid_ratio / 2``): the strain of a
    station near the clamp over the same station far from it, beyond what ``ClampFit`` gives. A
    round bar or tube held in a rigid clamp reads up to 13 % less within a fifth of its diameter
    of the clamp face, and the clamp's effect fades over about a third of a diameter. The clamp's
    effect is local to the grid: a short grid a quarter diameter out reads what a long one
    reaching from the same backing's end does not."""

    rate: float
    poly: Fit
    domain: dict            # clamp_ratio and the poly's variables -> (low, high)

    def __call__(self, values: dict, u, ops=None):
        ops = ops or NUMERIC
        return 1 + ops.exp(-self.rate * u) * grid_mean(self.rate, values["grid_ratio"] / 2, ops) * self.poly(values)


@dataclass(frozen=True)
class EdgeFit(_OverPolynomial):
    """``C = 1 + mean over the grid of exp(-b s) (A cos(b s) + B sin(b s))``, ``s`` the distance
    from the clamp face in section sizes, ``b = k0 / sqrt(w (1 - w))`` per size (``w = wall_ratio``)
    and ``A``, ``B`` polynomials in ``w``: a tube's edge layer at the clamp, the damped bending wave
    of a thin shell held at its edge, which decays over ``sqrt(R t)`` (Timoshenko & Woinowsky-
    Krieger, Theory of Plates and Shells, ch. 15: ``b = (3 (1 - nu^2))^(1/4) sqrt(2) / sqrt(w (1 - w))``,
    k0 = 1.82 for nu = 0.33). A thin tube's strain dips to 0.89 of the far station's a tenth of a
    diameter from the clamp face and overshoots a little beyond; no monotone decay follows it.
    ``poly`` is a Fit over ``osc_c``, ``osc_s`` (the grid means of the cosine and sine terms) and
    ``wall_ratio``."""

    k0: float
    poly: Fit
    domain: dict

    def __call__(self, values: dict, u, ops=None):
        return 1 + self.poly({**values, **edge_means(self.k0, values["wall_ratio"], u, values["grid_ratio"] / 2, ops)})


# A ClampShareFit's per-station variables: the plain bar's loss to the clamp at the station, and
# the station's feature's nearness to the clamp face.
CLAMP_DROP = "clamp_drop"
STATION_NEAR = "station_near"
STATION_VARIABLES = (CLAMP_DROP, STATION_NEAR)


@dataclass(frozen=True)
class ClampShareFit(_OverPolynomial):
    """``C = 1 + P``, ``P`` a polynomial (``poly``, a Fit) in the feature's parameters and two of the
    station's own, each term holding one of them, so that ``C`` is 1 away from the clamp:
    ``clamp_drop = 1 - C_c(w, u)``, what a plain bar of the section loses to the clamp's plate
    effect at the station (``ClampFit``), and ``station_near = exp(-3 c)`` of the station's feature's
    clamp-side end ``c`` sizes out (as ``clamp_near`` of the first): the strain of a station near the
    clamp over the same station far from it, beyond what ``ClampFit`` gives. A slot's floor sees only
    a share of a wide bar's loss to the clamp, less the deeper the slot: a 22 x 3.4 mm bar's slot
    0.15 heights deep, 0.43 widths from the clamp face, reads 2.5 % above the plain bar's factor
    there, and a slot 0.27 heights deep in a 10:1 bar 5 %."""

    poly: Fit
    domain: dict            # the feature's parameters and its clamp_ratio -> (low, high)

    def __call__(self, values: dict, drop, near):
        return 1 + self.poly({**values, CLAMP_DROP: drop, STATION_NEAR: near})


def edge_means(k0, wall_ratio, u, half, ops=None) -> dict:
    """``{osc_c, osc_s}``: the means of ``exp(-b s) cos(b s)`` and ``exp(-b s) sin(b s)`` over
    ``s`` in ``[u - half, u + half]``, ``b = k0 / sqrt(w (1 - w))`` (closed-form antiderivatives
    ``exp(-b s) (sin - cos) / (2 b)`` and ``-exp(-b s) (sin + cos) / (2 b)``)."""
    ops = ops or NUMERIC
    b = k0 / ops.sqrt(wall_ratio * (1 - wall_ratio))

    def at(s):
        e = ops.exp(-b * s) / (2 * b)
        return e * (ops.sin(b * s) - ops.cos(b * s)), -e * (ops.sin(b * s) + ops.cos(b * s))

    (c0, s0), (c1, s1) = at(u - half), at(u + half)
    width = 2 * half
    return {"osc_c": (c1 - c0) / width, "osc_s": (s1 - s0) / width}


def grid_mean(rate, half, ops=None):
    """``sinh(rate half) / (rate half)``: the mean of ``exp(-rate s)`` over a grid ``2 half`` long
    over its value at the grid's centre."""
    ops = ops or NUMERIC
    z = ops.fmax(rate * half, 1e-6)   # a grid of no length (a point gauge): the value at its centre
    return (ops.exp(z) - ops.exp(-z)) / (2 * z)


def station_ratios(g: Geometry) -> tuple:
    """Each station's (gauge grid centre's) distance from the clamp face in section sizes."""
    return tuple(d / g.size for d in g.stations)


@dataclass(frozen=True)
class Corrections:
    """Every family's fits; a family or quantity without a fit is not corrected (factor 1, no extra)."""

    fits: dict              # family -> {quantity -> Fit}
    source: str = ""

    def fit(self, fam: str, quantity: str) -> Fit | None:
        return self.fits.get(fam, {}).get(quantity)


def data_path(name: str):
    """A file of the shipped catalogue folder (``materials/``)."""
    from designer.spec.catalogue import data_folder

    return data_folder() / name


@lru_cache(maxsize=1)
def load() -> Corrections:
    """The shipped table, or no corrections when it is absent."""
    from designer.spec import strict_yaml

    path = data_path(TABLE)
    if not path.exists():
        return Corrections({})
    return from_dict(strict_yaml.load_shipped(path.read_text(encoding="utf-8")))


def from_dict(raw: dict) -> Corrections:
    fits = {}
    for fam, quantities in (raw.get("families") or {}).items():
        fits[fam] = {q: _fit_from_dict(f) for q, f in quantities.items()}
    return Corrections(fits, raw.get("source", ""))


def _fit_from_dict(f: dict):
    domain = {k: (float(v[0]), float(v[1])) for k, v in f["domain"].items()}
    if f.get("form") == "clamp":
        return ClampFit(*(float(f["coefficients"][k]) for k in CLAMP_COEFFICIENTS), domain,
                        float(f.get("rms", 0.0)), float(f.get("loo_max", 0.0)))
    if f.get("form") == "edge":
        return EdgeFit(float(f["k0"]), _fit_from_dict({k: v for k, v in f.items() if k not in ("form", "k0")}), domain)
    if f.get("form") == "clamp_share":
        return ClampShareFit(_fit_from_dict({k: v for k, v in f.items() if k != "form"}), domain)
    if f.get("form") == "decay":
        return DecayFit(float(f["rate"]), _fit_from_dict({k: v for k, v in f.items() if k not in ("form", "rate")}),
                        domain)
    if f.get("form") == "stiffness":
        return StiffnessFit(*(float(f["coefficients"][k]) for k in STIFFNESS_COEFFICIENTS), domain,
                            float(f.get("rms", 0.0)), float(f.get("loo_max", 0.0)))
    return Fit(tuple(f["variables"]), tuple(tuple(e) for e in f["exponents"]),
               tuple(float(c) for c in f["coefficients"]), domain, float(f.get("rms", 0.0)),
               float(f.get("loo_max", 0.0)), float(f.get("margin", 0.0)),
               tuple((float(x), float(y)) for x, y in f.get("notch_top", ())))


def _fit_to_dict(f) -> dict:
    if isinstance(f, EdgeFit):
        return {"form": "edge", "k0": f.k0, **_fit_to_dict(f.poly), "domain": {k: list(v) for k, v in f.domain.items()}}
    if isinstance(f, ClampShareFit):
        return {"form": "clamp_share", **_fit_to_dict(f.poly), "domain": {k: list(v) for k, v in f.domain.items()}}
    if isinstance(f, DecayFit):
        return {"form": "decay", "rate": f.rate, **_fit_to_dict(f.poly), "domain": {k: list(v) for k, v in f.domain.items()}}
    for cls, form, names in ((ClampFit, "clamp", CLAMP_COEFFICIENTS), (StiffnessFit, "stiffness", STIFFNESS_COEFFICIENTS)):
        if isinstance(f, cls):
            return {"form": form, "coefficients": {k: getattr(f, k) for k in names},
                    "domain": {k: list(v) for k, v in f.domain.items()}, "rms": f.rms, "loo_max": f.loo_max}
    return {"variables": list(f.variables), "exponents": [list(e) for e in f.exponents],
            "coefficients": list(f.coefficients), "domain": {k: list(v) for k, v in f.domain.items()},
            "rms": f.rms, "loo_max": f.loo_max, **({"margin": f.margin} if f.margin else {}),
            **({"notch_top": [list(v) for v in f.notch_top]} if f.notch_top else {})}


def to_dict(c: Corrections) -> dict:
    return {"source": c.source,
            "families": {fam: {q: _fit_to_dict(f) for q, f in quantities.items()}
                         for fam, quantities in c.fits.items()}}


def clamp_fit(table: Corrections):
    """The clamp's fit (one for every family)."""
    return table.fit("plain", "clamp")


def stiffness_fit(table: Corrections):
    """The plain bar's stiffness fit (one for every family)."""
    return table.fit("plain", "stiffness")


def strain_factors(g: Geometry, table: Corrections, ops=None, poisson=None) -> tuple:
    """Each station's gauge-strain factor: the feature's ``strain`` fit times the ``clamp`` fit at the
    station's distance from the clamp over the width (its loss scaled to the material's ``poisson``,
    ``CLAMP_POISSON``), times the family's own ``near_clamp`` fit: a ``DecayFit`` or ``EdgeFit`` at its
    distance in sizes (on a plain round bar or tube, its loss scaled to ``poisson`` too), or a slot's
    ``ClampShareFit`` of the plain bar's loss to the clamp there, and on a biaxial sensor the side
    features' ``biaxial_strain_factor``; empty if the table corrects none."""
    fam = family(g)
    strain, clamp, near = table.fit(fam, "strain"), clamp_fit(table), table.fit(fam, "near_clamp")
    if strain is None and clamp is None and near is None:
        return ()
    values = parameters(g)
    base = (strain(values) if strain is not None else 1.0) * biaxial_strain_factor(g, ops)
    factors = [base for _ in g.stations]
    scale = 1.0 if poisson is None else (poisson / CLAMP_POISSON) ** CLAMP_POISSON_POWER
    plate = [1 - (1 - clamp(values["width_ratio"], u, ops)) * scale if clamp else 1.0 for u in station_width_ratios(g)]
    factors = [f * c for f, c in zip(factors, plate)]
    if isinstance(near, ClampShareFit):
        factors = [f * near(values, 1 - c, clamp_nearness(r, ops)) for f, c, r in zip(factors, plate, clamp_ratios(g))]
    elif near is not None:
        own = (1.0 if poisson is None or fam not in NEAR_POISSON_FAMILIES
               else (poisson / CLAMP_POISSON) ** NEAR_POISSON_POWER)
        factors = [f * (1 - (1 - near(values, u, ops)) * own) for f, u in zip(factors, station_ratios(g))]
    return tuple(factors)


def strain_allowance(g: Geometry, table: Corrections) -> float:
    """How far above the corrected model the 3-D gauge strain may lie: the largest left-out error
    of the fits that set it (the feature's ``strain`` fit, the clamp's and the family's
    ``near_clamp``), plus on a biaxial sensor with features ``biaxial_strain_room``. The
    gauge-strain limit keeps this much room, so that a design at that limit meets it in 3-D too."""
    fits = [table.fit(family(g), "strain"), clamp_fit(table), table.fit(family(g), "near_clamp")]
    return max((f.loo_max for f in fits if f is not None), default=0.0) + biaxial_strain_room(g)


# A fit meets its rule when it predicts each study point left out of it within these (the gauge-
# strain factor on itself, the extra length by the free-end deflection it implies, K_t relative to
# itself); a fit shifted to its safe side misses on the unsafe side by at most as much.
ACCEPT = {"strain": 0.02, "extra_length": 0.015, "stress": 0.05, "stress_face": 0.05}


def _unsafe_error(fit, quantity: str) -> float:
    """How far a shipped fit may err on the unsafe side: its left-out error, at most the rule. A fit
    that misses its rule ships shifted to its safe side until no left-out point misses on that side
    by more (``checks.fits.shifted``), by a shift of 0 where every miss beyond the rule was on the
    safe side (``Fit.margin`` 0, ``loo_max`` over the rule)."""
    return min(fit.loo_max, ACCEPT[quantity])


def deflection_allowance(g: Geometry, table: Corrections) -> float:
    """How far above the model the 3-D free-end deflection may lie: the largest unsafe-side error of
    the fits that set it (the feature's ``extra_length``, as a share of the deflection, and the
    plain bar's ``stiffness``). The deflection limit keeps this much room."""
    fits = [table.fit(family(g), "extra_length"), stiffness_fit(table)]
    return max((_unsafe_error(f, "extra_length") for f in fits if f is not None), default=0.0)


def stress_allowance(g: Geometry, table: Corrections) -> float:
    """How far above the model the 3-D peak stress at the feature may lie: the largest unsafe-side
    error of its K_t fits (KT_FITS). The fatigue limit at the feature keeps this much room."""
    fits = [table.fit(family(g), q) for q in KT_FITS]
    return max((_unsafe_error(f, "stress") for f in fits if f is not None), default=0.0)


# K_t's fits: ``stress`` (a slot's floor radius; a flat's, a hole's) and a slot's ``stress_face``,
# at its rim on the loaded outer face (``checks.fits.FACE``); K_t is the larger.
KT_FITS = ("stress", "stress_face")


def stress_concentrations(g: Geometry, table: Corrections) -> tuple:
    """K_t at each feature: the larger of its family's KT_FITS at the feature's own parameters (a
    fit in the clamp's nearness gives a feature far from the clamp a higher K_t), or 1 where the
    table has none."""
    fits = [f for f in (table.fit(family(g), q) for q in KT_FITS) if f is not None]
    if not fits:
        return (1.0,) * len(g.stations)

    def kt(values):     # the larger, rounded off as the features' peaks are (``ops.rounded_max``)
        k = [f(values) for f in fits]
        return k[0] if len(k) == 1 else rounded_max(k[0], k[1], PEAK_SMOOTHING * k[0], ops_for(*k))

    if all(CLAMP_NEAR not in f.variables for f in fits):
        return (kt(parameters(g)),) * len(g.stations)     # one K_t, the same object, at every feature
    return tuple(kt(p) for p in feature_parameters(g))


def widened(g: Geometry, table: Corrections) -> Geometry:
    """``g`` with each reduced span longer by the ``extra_length`` fit (half at each end); a fit in
    the clamp's nearness is taken at each feature's own (``feature_parameters``): the clamp
    stiffens the first feature's surroundings, not those of a feature far out."""
    fit = table.fit(family(g), "extra_length")
    if fit is None:
        return g
    if CLAMP_NEAR not in fit.variables:
        return Widened(g, fit(parameters(g)) * g.size)
    return Widened(g, tuple(fit(p) * g.size for p in feature_parameters(g)))


def feature_parameters(g: Geometry) -> list:
    """``parameters(g)`` for each feature, each with its own ``clamp_near`` (``clamp_ratios``)."""
    p = parameters(g)
    return [{**p, CLAMP_NEAR: clamp_nearness(u, ops_for(u))} for u in clamp_ratios(g)]

