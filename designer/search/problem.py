"""One section family's optimisation problem: its variables, and its NLP as a casadi graph.

The graph is built once from the same model expressions the evaluator runs (``model.analyse``,
``model.limits``, ``model.objective`` over casadi's Ops) and re-solved with the material as
parameters. Variables are in millimetres and constraints normalised (``value/limit - 1 <= 0``).
"""

from __future__ import annotations

import contextlib
import copy
import io
import sys
from dataclasses import dataclass, replace

import numpy as np

from designer import interrupt, model
from designer.errors import SpecError
from designer.model import Geometry, MaterialParams, corrections, domain, grooves, tolerance
from designer.model.limits import pocket_floors, shallowest_pocket
from designer.model.ops import ops_for
from designer.model.sections import wire_channel
from designer.result.evaluation import Design, Evaluation

MM = 1e-3
METHODS = ("ipopt", "slsqp", "mma", "ccsaq", "cobyla", "isres", "direct", "grid")
IPOPT_TOLERANCE = 1e-9
IPOPT_MAX_ITER = 300
# With tolerances (docs/model.md §14) the corners' deviations are taken at the start; when the
# answer's sizes lie in another size range of the class, it is solved again from there, at most
# this many times. The NLP's variables that the tolerances move, and which deviation each takes:
DEVIATION_ROUNDS = 3
TOLERANCED = {**tolerance.PART, "side": "section"}
#: casadi's options of every IPOPT solve. ``show_eval_warnings`` off: a trial step of IPOPT's
#: line search may leave the beam's domain (a negative wall, a pocket deeper than the bar), where
#: the model is NaN; IPOPT then shortens the step (it is built for that), but casadi would print
#: "NaN detected" on standard error for every such trial, which is noise to the user.
#: ``expect_infeasible_problem``: IPOPT turns to its restoration phase as soon as the constraint
#: violation stops falling, and so ends a locally infeasible solve in about a third of the
#: iterations. With the feature corrections' fitted domain most materials x families of a
#: tightly specified spec are infeasible (the weigh-bar example: 22 of 27), and proving it was
#: most of the search's time; on the bench suite every feasible spec gets the same answer
#: (benchmarks/bench_optimize.py).
IPOPT_OPTIONS = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.constr_viol_tol": 1e-9,
                 "ipopt.mu_strategy": "adaptive", "ipopt.expect_infeasible_problem": "yes",
                 "error_on_fail": False, "show_eval_warnings": False, "calc_lam_p": False}
# IPOPT's answers that are a verdict on the problem, not a failure of the solver: it converged
# to a point that minimises the constraint violation. When every start ends so, another method
# is not tried (on the bench suite such a fallback never found a feasible design).
IPOPT_INFEASIBLE = ("Infeasible_Problem_Detected",)
# IPOPT's warm start (``FamilyProblem.solve_ipopt``'s ``warm``): the multipliers of a solve nearby
# and a small barrier parameter; a trade-off front's level started from its neighbour's answer
# converges in about half the iterations of a cold start (the gripper finger: 9 -> 4-7)
WARM_OPTIONS = {"ipopt.warm_start_init_point": "yes", "ipopt.mu_init": 1e-6, "ipopt.warm_start_bound_push": 1e-9,
                "ipopt.warm_start_mult_bound_push": 1e-9, "ipopt.warm_start_slack_bound_push": 1e-9}
EPIGRAPH_UPPER = 1e6
LEAST_LIFT = 1e-6   # mm: the least-violation NLP's lower bounds over the variables' own (``least_violation``)
NO_CAP = 1e12  # the primary-objective cap of a first-stage solve: never reached
# Limits that are plain variable bounds in the NLP; they are still checked on every answer.
BOUND_LIMITS = {"width_min", "width_max", "height_min", "height_max", "diameter_min", "diameter_max",
                "wall_min", "pocket_depth_min", "hole_min"}


@dataclass(frozen=True)
class Family:
    section: str
    feature: str

    @property
    def label(self) -> str:
        return self.section if self.feature in ("pocket", "none") else f"{self.section}+{self.feature}"


def families(spec) -> list[Family]:
    """The section families the search solves: the spec's, less those whose size bounds leave no
    room (``unsearchable``); SpecError (the first family's) when that leaves none."""
    every, left_out = _every_family(spec), unsearchable(spec)
    out = [fam for fam in every if fam not in left_out]
    if every and not out:
        raise SpecError(left_out[every[0]])
    return out


def unsearchable(spec) -> dict:
    """``{family: why}`` for the spec's families whose size bounds leave no room (limits.width
    [60, 70] mm with the default heights leaves a round bar none): reported as not searched, while
    the others are searched."""
    out = {}
    for fam in _every_family(spec):
        try:
            FamilyVariables.of(spec, fam)
        except SpecError as exc:
            out[fam] = str(exc)
    return out


def _no_room_for_pocket(spec, section: str, size: float) -> str:
    """Why a pocket of ``section`` cannot be cut: its least depth (``pocket_floors``) is deeper
    than ``limits.max_pocket_fraction`` of the largest section the limits allow (``size``)."""
    least, key, value = pocket_floors(spec)[0]
    fraction = spec.limits.max_pocket_fraction
    deepest = fraction * size
    cut = "" if key == "limits.min_pocket_depth" else " (cut 0.01 mm deeper)"
    largest = ("height" if spec.axes == 1 else "side") if section == "rectangle" else "diameter"
    return (f"{key}: {value * 1e3:g} mm leaves no room for a {section}'s pocket{cut} within "
            f"limits.max_pocket_fraction {fraction:g} of its largest {largest} ({size * 1e3:g} mm): "
            f"{deepest * 1e3:.3g} mm; must be at most {(deepest - least + value) * 1e3:.3g} mm")


def _every_family(spec) -> list[Family]:
    feature = spec.search.feature
    return [Family(s, feature) for s in spec.search.sections if not (feature == "hole" and s != "rectangle")]


@dataclass(frozen=True)
class Solve:
    """One solver run: the raw answer, before rounding and checking."""

    x: np.ndarray
    success: bool          # what the solver said: recorded, never trusted
    message: str
    evaluations: int
    method: str
    multipliers: tuple | None = None   # IPOPT's (lam_x, lam_g) at the answer: a warm start for a solve near it


@dataclass(frozen=True)
class FamilyVariables:
    """The variables of one family (mm), their bounds and start points; no casadi graph."""

    spec: object
    family: Family
    names: tuple
    lower: np.ndarray
    upper: np.ndarray
    adjustment: object = None  # model.Adjustment: the model adjusted to a 3-D check, carried by every design
    plan_radius: float = 0.0   # a slot's corner radius in plan, its end mill's radius (the spec's alone)

    @classmethod
    def of(cls, spec, family: Family, adjustment=None) -> "FamilyVariables":
        """The variables of ``family`` under ``spec``; SpecError when the limits leave no room."""
        fam = family
        lim = spec.limits
        names, lo, hi = [], [], []

        def add(name, a, b):
            names.append(name)
            lo.append(a / MM)
            hi.append(b / MM)

        if fam.section == "rectangle":
            if spec.axes == 2:
                add("side", max(lim.width[0], lim.height[0]), min(lim.width[1], lim.height[1]))
            else:
                add("width", *lim.width)
                add("height", *lim.height)
            size_hi = min(lim.width[1], lim.height[1]) if spec.axes == 2 else lim.height[1]
        else:
            add("diameter", max(lim.width[0], lim.height[0]), min(lim.width[1], lim.height[1]))
            size_hi = min(lim.width[1], lim.height[1])
            if fam.section == "tube":
                add("wall", lim.min_wall, size_hi / 2)
        if fam.feature == "pocket":
            shallowest, deepest = shallowest_pocket(spec), lim.max_pocket_fraction * size_hi
            if shallowest > deepest:
                raise SpecError(_no_room_for_pocket(spec, fam.section, size_hi))
            add("depth", shallowest, deepest)
        elif fam.feature == "hole":
            add("hole", lim.min_wall, max(lim.min_wall, size_hi - 2 * lim.min_wall))
        for i in range(spec.stations):
            add(f"station_{i + 1}", lim.clamp_clearance, spec.load.position_min)
        if lo and any(a > b for a, b in zip(lo, hi)):
            bad = names[[a > b for a, b in zip(lo, hi)].index(True)]
            if bad.startswith("station"):
                raise SpecError(f"limits.clamp_clearance: {lim.clamp_clearance * 1e3:g} mm leaves no room for the "
                                f"stations before the load range, which begins at load.position "
                                f"{spec.load.position_min * 1e3:g} mm; must be less than that")
            raise SpecError(f"limits: the bounds leave no room for {bad}; check limits.width and limits.height")
        plan_radius = 0.0
        if fam.section == "rectangle" and fam.feature == "pocket":
            from designer.outputs.cad.mills import slot_plan_radius

            plan_radius = slot_plan_radius(spec)
        return cls(spec, family, tuple(names), np.array(lo), np.array(hi), adjustment, plan_radius)

    def geometry(self, v) -> Geometry:
        """A Geometry from variable values in SI (floats, arrays or casadi)."""
        spec, fam = self.spec, self.family
        named = dict(zip(self.names, v))
        lp, wp = spec.pocket_size()
        if "side" in named:
            named["width"] = named["height"] = named["side"]
        stations = tuple(named[f"station_{i + 1}"] for i in range(spec.stations))
        depth = named.get("depth", 0.0)
        channel = wire_channel(spec.cad, fam.section, fam.feature, depth, wp, ops_for(depth))
        g = Geometry(section=fam.section, feature=fam.feature, stations=stations, length=spec.free_length,
                     width=named.get("width"), height=named.get("height"), diameter=named.get("diameter"),
                     wall=named.get("wall"), depth=depth, hole=named.get("hole", 0.0),
                     pocket_length=lp, pocket_width=wp, gauge_length=spec.gauge.length,
                     grid_length=spec.gauge.grid_length, grid_width=spec.gauge.grid_width, axes=spec.axes,
                     floor_radius=spec.cad.corner_radius if fam.feature == "pocket" else 0.0,
                     plan_radius=self.plan_radius, channel_width=channel[0], channel_depth=channel[1])
        return pocket_as_needed(g, lp)

    def design(self, x, material) -> Design:
        return Design(material, self.geometry([float(v) * MM for v in x[: len(self.names)]]), self.adjustment)

    @property
    def epigraph(self) -> bool:
        """Under the error objective the NLP has one more variable: the error ratio's bound."""
        return self.spec.objective == "error"

    @property
    def size(self) -> int:
        return len(self.names) + (1 if self.epigraph else 0)

    def bounds(self):
        lo, hi = list(self.lower), list(self.upper)
        if self.epigraph:
            lo.append(0.0)
            hi.append(EPIGRAPH_UPPER)
        return np.array(lo), np.array(hi)

    def starts(self, fractions=(0.35, 0.7)) -> list[np.ndarray]:
        """Deterministic start points: sections at 35 % and 70 % of their range (or ``fractions``),
        stations spread evenly over the room between the clamp and the load region."""
        spec, lim = self.spec, self.spec.limits
        out = []
        for frac in fractions:
            v = {}
            for name, a, b in zip(self.names, self.lower, self.upper):
                share = {"depth": 0.3, "hole": 0.5, "wall": 0.2}.get(name, frac)
                v[name] = a + share * (b - a)
            half = model.feature_length(self.family.feature, spec.pocket_size()[0] / MM, v.get("hole"),
                                        spec.gauge.length / MM) / 2
            first = lim.clamp_clearance / MM + half
            last = max(grooves.stations_end(spec) / MM - half, first + 1.0)
            for i, d in enumerate(np.linspace(first, last, spec.stations)):
                v[f"station_{i + 1}"] = d
            x = np.clip([v[n] for n in self.names], self.lower, self.upper)
            out.append(np.append(x, 1.0) if self.epigraph else x)
        return out


POCKET_SMOOTHING = 0.01


def pocket_as_needed(g: Geometry, least: float, step: float = 0.0) -> Geometry:
    """``g`` with its pocket ``least`` long (the spec's rule: the gauge's backing and margins), or
    longer where the feature corrections hold only for a longer one (``domain.least_pocket_length``:
    a flat on a tube at least the tube's diameter long); with ``step``, that
    longer length rounded up to it (a design's sizes are on the 0.01 mm grid; the rule's is kept)."""
    if g.feature != "pocket":
        return g
    need = domain.least_pocket_length(g, corrections.load())
    if not step:
        # a smooth maximum, never below either (IPOPT stalls at a kink of max(): the bench suite's
        # 011-loose-limits slot, 4.9 % above COBYLA's): at most POCKET_SMOOTHING x the rule above it
        width = POCKET_SMOOTHING * least
        return replace(g, pocket_length=(least + need + ops_for(need).sqrt((need - least) ** 2 + width ** 2)) / 2)
    # on the grid the need itself, rounded up: the smooth maximum lies a little above it (0.7 um
    # on the weigh-bar's flat), which can round up a grid step further (11.80 mm where its
    # Ø29.47 mm bar needs 11.79 mm)
    need = np.asarray(need, dtype=float)
    length = np.where(need > least, np.ceil(need / step - 1e-9) * step, least)
    return replace(g, pocket_length=float(length) if length.ndim == 0 else length)


def in_nlp_units(value, objective: str):
    """An objective value in the NLP's units: mm for deflection, g for mass (the error ratio as is)."""
    if objective == "deflection":
        return value / MM
    if objective == "mass":
        return value * 1e3
    return value


# The NLP's parameters: the material's (MaterialParams.scaled), then the cap on the primary objective,
# then, in a swept problem, the swept limit's level.
CAP = 9
#: the limits a trade-off front sweeps (``search.tradeoff``), and each one's unit in the NLP (SI per unit)
SWEPT_UNITS = {"max_deflection": MM, "min_frequency": 1.0}
#: each swept spec key's limit (``model.limits``' name), which is also the analysis' figure it bounds
SWEPT_LIMIT = {"max_deflection": "deflection", "min_frequency": "natural_frequency"}


def material_params(material, spec, cap: float = NO_CAP) -> list[float]:
    """The NLP's parameters: the material in GPa, MPa, kg/m^3, and the cap on the primary objective."""
    return MaterialParams.of(material, spec.limits).scaled() + [cap]


class FamilyProblem:
    """The NLP of one family as casadi functions, over ``FamilyVariables``; material as parameters.

    ``adjustment`` (a ``model.Adjustment``) puts a design's 3-D/model factors into the model as
    constants; without it the graph is the plain model's. ``swept`` (a key of SWEPT_UNITS) makes
    that limit a parameter of the graph, so that one graph serves every level of a trade-off
    front (``at``); the spec's own value of it is then not used.
    """

    def __init__(self, spec, family: Family, adjustment=None, swept: str | None = None):
        import casadi as ca

        self.variables = variables = FamilyVariables.of(spec, family, adjustment)
        self.spec, self.family, self.swept = spec, family, swept
        self.extra: list[float] = []  # the parameters after the cap: the swept limit's level (``at``)
        n, epigraph = len(variables.names), variables.epigraph
        x = ca.SX.sym("x", variables.size)
        # the material (MaterialParams.scaled: GPa, MPa, kg/m^3, MPa, mm, 1, ppm/K, ppm/K, %), then the cap on
        # the primary objective, then the swept limit (mm or Hz)
        par = ca.SX.sym("p", CAP + 1 + (swept is not None))
        if swept is not None:
            spec = replace(spec, limits=replace(spec.limits, **{swept: par[CAP + 1] * SWEPT_UNITS[swept]}))
        ops = model.casadi_ops()
        mat = MaterialParams.from_scaled(par)
        # the model once, over the sizes and the pocket's drawn length: the design itself at the
        # length its sizes need (``pocket_as_needed``), its tolerance corners (below) at its own
        xs, drawn = ca.SX.sym("xs", variables.size), ca.SX.sym("l_p")
        built = replace(variables.geometry([xs[i] * MM for i in range(n)]), pocket_length=drawn)
        a = model.analyse(built, mat, spec, ops, adjust=adjustment)
        every = [lim for lim in model.limits(built, a, mat, spec, ops=ops) if lim.name not in BOUND_LIMITS]
        # under the error objective the targets are met through the epigraph variable, not as
        # rows; their own rows serve the least-violation NLP (``least_violation``) only
        lims = [lim for lim in every if not (epigraph and lim.name in model.TARGET_LIMITS)]
        targets = [lim for lim in every if epigraph and lim.name in model.TARGET_LIMITS]
        terms = list(model.error_terms(a, spec.targets)) if epigraph else []
        length = variables.geometry([x[i] * MM for i in range(n)]).pocket_length
        outputs = [lim.normalised for lim in lims] + [a.deflection, a.mass] + terms + \
            [lim.normalised for lim in targets]
        model_at = ca.Function("model", [xs, par, drawn], [ca.vertcat(*outputs)])
        nominal = model_at(x, par, length)
        g = [nominal[i] for i in range(len(lims))]
        # with tolerances, each corner-checked limit again at every corner of the toleranced
        # variables (docs/model.md §14): the deviations (mm) are parameters after the others
        self.moved = [i for i, name in enumerate(variables.names) if name in TOLERANCED] \
            if spec.tolerances.active else []
        dev = ca.SX.sym("t", len(self.moved))
        checked = [j for j, lim in enumerate(lims) if lim.name in tolerance.CORNER_LIMITS] if self.moved else []
        self.limit_names = [lim.name for lim in lims]
        if checked:
            # a corner is the part as drawn, built at the corner's sizes: its pocket as long as the
            # nominal design's (a drawn length), not as long as the corner's sizes would need, as
            # tolerance.corners builds it for the check
            rows = ca.Function("rows", [xs, par, drawn], [ca.vertcat(*[lims[j].normalised for j in checked])])
            parts = [TOLERANCED[variables.names[i]] for i in self.moved]
            for weak, signs in tolerance.searched_corners(parts):
                xc = [x[i] for i in range(variables.size)]
                for k, (i, sign) in enumerate(zip(self.moved, signs)):
                    xc[i] = ca.fmax(x[i] + sign * dev[k], tolerance.LEAST[parts[k]] / MM)
                at = rows(ca.vertcat(*xc), par, length)
                here = [r for r, j in enumerate(checked) if (lims[j].name in tolerance.STRONG_CORNER_LIMITS) != weak]
                g += [at[r] for r in here]
                self.limit_names += [lims[checked[r]].name for r in here]
        n_limits = len(lims)   # the nominal outputs after the limit rows: deflection, mass, the error terms
        in_units = {"deflection": in_nlp_units(nominal[n_limits], "deflection"),
                    "mass": in_nlp_units(nominal[n_limits + 1], "mass")}
        # every limit's row, nominal and at the corners, and the targets' (the least-violation NLP's)
        self._rows = ca.vertcat(*g, *[nominal[n_limits + 2 + len(terms) + k] for k in range(len(targets))])
        self.row_names = self.limit_names + [lim.name for lim in targets]
        self._terms = []   # the epigraph's rows (error term - e)
        if epigraph:  # minimise e subject to each error term <= e
            e = x[n]
            self._terms = [nominal[n_limits + 2 + k] - e for k in range(len(terms))]
            g += self._terms
            f = e
        else:
            f = in_units[spec.objective]
        secondary = in_units[model.SECONDARY[spec.objective]]
        # The tie rule (docs/model.md §5) as a second stage: the secondary objective with the
        # primary capped inside the tie band. With a huge cap the constraint is idle.
        g.append(f / par[CAP] - 1)
        self.n_constraints = len(g)
        gv = ca.vertcat(*g)
        full = ca.vertcat(par, dev)
        self.nlp = {"x": x, "p": full, "f": f, "g": gv}
        self.nlp_secondary = {"x": x, "p": full, "f": secondary, "g": gv}
        self._functions = ca.Function("fg", [x, full], [f, ca.gradient(f, x), gv, ca.jacobian(gv, x)])
        self._ipopt = {}
        self._rows_function = None

    def functions(self, x, params):
        """``(f, grad f, g, jac g)`` at ``x`` (NLP units) for ``params`` (``params``), the tolerance
        corners' rows taken with the deviations of the sizes at ``x``."""
        return self._functions(x, self.with_deviations(params, x))

    def deviations(self, x) -> list[float]:
        """The tolerances' deviations (mm) of the toleranced variables at ``x`` (NLP units)."""
        return [float(self.spec.tolerances.deviation(float(x[i]) * MM, TOLERANCED[self.names[i]])) / MM
                for i in self.moved]

    def with_deviations(self, params, x) -> list[float]:
        """The NLP's parameters: ``params`` and the deviations at ``x``."""
        return list(params) + self.deviations(x)

    def at(self, spec, level: float) -> "FamilyProblem":
        """This swept problem at one level of its limit: ``spec`` is the spec with that level set
        (it checks every answer), and the compiled graph and solvers are shared."""
        if self.swept is None:
            raise ValueError("at: the problem sweeps no limit")
        other = copy.copy(self)
        other.spec = spec
        other.variables = FamilyVariables.of(spec, self.family, self.adjustment)
        other.extra = [level / SWEPT_UNITS[self.swept]]
        return other

    def params(self, material, cap: float = NO_CAP) -> list[float]:
        """The NLP's parameters for ``material`` (``material_params``), and the swept level if any."""
        return material_params(material, self.spec, cap) + self.extra

    # the variables ----------------------------------------------------------
    names = property(lambda self: self.variables.names)
    lower = property(lambda self: self.variables.lower)
    upper = property(lambda self: self.variables.upper)
    epigraph = property(lambda self: self.variables.epigraph)
    adjustment = property(lambda self: self.variables.adjustment)
    size = property(lambda self: self.variables.size)

    def geometry(self, v) -> Geometry:
        return self.variables.geometry(v)

    def design(self, x, material) -> Design:
        return self.variables.design(x, material)

    def bounds(self):
        return self.variables.bounds()

    def starts(self, fractions=(0.35, 0.7)) -> list[np.ndarray]:
        return self.variables.starts(fractions)

    # solvers ----------------------------------------------------------------
    def ipopt(self, stage: str = "primary"):
        """IPOPT on the NLP of ``stage``: ``primary``, ``secondary`` (the tie rule's), or ``relaxed``:
        the primary with the material's parameters (the first CAP of ``params``) as variables after
        the design's, bounded per solve (``infeasible_for_every``)."""
        if stage not in self._ipopt:
            import casadi as ca

            opts = dict(IPOPT_OPTIONS, **{"ipopt.tol": IPOPT_TOLERANCE, "ipopt.max_iter": IPOPT_MAX_ITER})
            if stage == "warm":
                opts.update(WARM_OPTIONS)
            nlp = self.nlp_secondary if stage == "secondary" else self.nlp
            if stage == "least":   # the worst of the rows weighed 1 minimised, the others held, the error terms kept
                worst, weight = ca.SX.sym("worst"), ca.SX.sym("weight", self._rows.numel())
                nlp = {"x": ca.vertcat(nlp["x"], worst), "p": ca.vertcat(nlp["p"], weight), "f": worst,
                       "g": ca.vertcat(self._rows - weight * worst, *self._terms)}
            if stage == "relaxed":
                par = nlp["p"]
                nlp = dict(nlp, x=ca.vertcat(nlp["x"], par[:CAP]), p=par[CAP:])
            self._ipopt[stage] = ca.nlpsol(f"fpd_{self.family.section}_{self.family.feature}_{stage}", "ipopt",
                                           nlp, opts)
        return self._ipopt[stage]

    def margins(self, names, margin: float) -> np.ndarray:
        """A ``margin`` for ``solve_ipopt`` that tightens the rows of the limits ``names`` only
        (the tie band's cap row has no name and is never tightened); zero elsewhere."""
        out = np.zeros(self.n_constraints)
        out[[i for i, name in enumerate(self.limit_names) if name in set(names)]] = margin
        return out

    def solve_ipopt(self, params, x0, stage: str = "primary", margin=0.0, fixed=None, box=None,
                    warm: Solve | None = None, least: bool = False) -> Solve:
        """One IPOPT run; ``margin`` (a number, or one per constraint row as ``margins`` gives)
        tightens the constraints to ``g <= -margin``; ``fixed`` maps
        variable indices to values (NLP units) they are held at, ``box`` to ``(low, high)`` bounds
        that replace the variable's own. ``warm``: a primary solve near ``x0`` whose multipliers
        start this one (IPOPT's warm start; solved again cold if that does not succeed).
        ``least``: the tolerance corners taken with each size's least deviation over its bounds
        (the box's), not the answer's: a relaxation whose objective bounds every design in the
        box, solved once (a stock search's sets of rows, ``search.stock``)."""
        if stage == "primary" and warm is not None and self._fits(warm):
            s = self._solve(params, x0, "warm", margin, fixed, box, warm.multipliers, least)
            if s.success:
                return s
            cold = self._solve(params, x0, stage, margin, fixed, box, least=least)
            return replace(cold, evaluations=cold.evaluations + s.evaluations)
        return self._solve(params, x0, stage, margin, fixed, box, least=least)

    def _fits(self, warm: Solve) -> bool:
        return (warm.multipliers is not None and len(warm.multipliers[0]) == self.size
                and len(warm.multipliers[1]) == self.n_constraints)

    def _solve(self, params, x0, stage, margin, fixed, box, multipliers=None, least: bool = False) -> Solve:
        lo, hi = self.bounds()
        x0 = np.array(x0, dtype=float)
        for i, (a, b) in (box or {}).items():
            lo[i], hi[i] = a, b
            x0[i] = min(max(x0[i], a), b)
        for i, v in (fixed or {}).items():
            lo[i] = hi[i] = x0[i] = v
        start = {} if multipliers is None else {"lam_x0": multipliers[0], "lam_g0": multipliers[1]}
        # the class's deviation grows with the size: at the lower bounds it is the least
        s = _run_ipopt(self.ipopt(stage), x0=x0, p=self.with_deviations(params, lo if least else x0), lbx=lo, ubx=hi,
                       lbg=-np.inf, ubg=-margin, **start)
        if least:
            return s
        runs = s.evaluations
        for _ in range(DEVIATION_ROUNDS):  # the answer's sizes crossed into another range of the class
            if not s.success or self.deviations(s.x) == self.deviations(x0):
                break
            x0 = s.x
            s = _run_ipopt(self.ipopt("primary" if stage == "warm" else stage), x0=x0,
                           p=self.with_deviations(params, x0), lbx=lo, ubx=hi, lbg=-np.inf, ubg=-margin)
            runs += s.evaluations
        return replace(s, evaluations=runs)

    def least_violation(self, params, x0, soft, free=(), margin: float = 0.0, fixed=None, box=None,
                        least: bool = False) -> tuple[Solve, float]:
        """IPOPT from ``x0`` on the NLP of the least violation: the design whose worst normalised row
        among the limits named in ``soft`` (nominal and at the tolerance corners) is least, every
        other row met (``margin`` inside its limit), but for those named in ``free``, which are let
        go; within the variables' bounds (``box`` and ``least`` as ``solve_ipopt``'s: a relaxation
        whose worst row bounds every design's in the box), ``fixed`` (``{index: value}``, NLP units)
        held at their values. The closest design of a family none of whose designs meets every limit
        (``search.closest``). Returns the Solve (its ``x``, the design's variables) and that worst
        row at its answer, as the NLP has it."""
        lo, hi = self.bounds()
        for i, (a, b) in (box or {}).items():
            lo[i], hi[i] = a, b
        # IPOPT relaxes a bound by 1e-8 of itself; at a pocket's least depth, when the tolerance's
        # deviation is as deep (ISO 2768-v: 0.5 mm), a corner's pocket is cut to no depth, where the
        # fatigue limit's derivative is no number (IPOPT's Invalid_Number_Detected): kept 1 nm over
        lo = lo + LEAST_LIFT
        weight = np.array([1.0 if name in soft else 0.0 for name in self.row_names])
        upper = np.array([np.inf if name in free else 0.0 if name in soft else -margin for name in self.row_names]
                         + [0.0] * len(self._terms))
        for i, v in (fixed or {}).items():
            lo[i] = hi[i] = v
        x, runs = np.clip(np.array(x0, dtype=float), lo, hi), 0
        for _ in range(DEVIATION_ROUNDS):   # the corners' deviations at the answer's sizes, as ``_solve``
            p = self.with_deviations(params, lo - LEAST_LIFT if least else x)
            start = float(np.max(self._rows_at(x, p)[weight > 0], initial=0.0))
            s = _run_ipopt(self.ipopt("least"), x0=np.append(x, start), p=np.append(p, weight),
                           lbx=np.append(lo, -np.inf), ubx=np.append(hi, np.inf), lbg=-np.inf, ubg=upper)
            runs += s.evaluations
            moved = self.deviations(s.x[:-1]) != self.deviations(x)
            x = s.x[:-1]
            if not s.success or not moved or least:
                break
        return replace(s, x=x, evaluations=runs, multipliers=None), float(s.x[-1])

    def _rows_at(self, x, p) -> np.ndarray:
        import casadi as ca

        if self._rows_function is None:
            self._rows_function = ca.Function("rows", [self.nlp["x"], self.nlp["p"]], [self._rows])
        return np.asarray(self._rows_function(x, p)).ravel()

    def infeasible_for_every(self, materials, starts=None) -> tuple[bool, list]:
        """Whether no design of this family meets every limit in any of ``materials``, and the
        solves that said so. The material's parameters are let free between the least and the
        greatest of ``materials``' values, each on its own: every material lies in that box, so
        when IPOPT finds the relaxed NLP infeasible from every start (``starts``, in that order;
        the usual ones unless given), each material's NLP is too (with the same trust as a verdict
        on one material's NLP: IPOPT's infeasibility is local)."""
        table = np.array([self.params(m) for m in materials], dtype=float)
        low, high = table[:, :CAP].min(axis=0), table[:, :CAP].max(axis=0)
        lo, hi = self.bounds()
        solves = []
        for x0 in self.starts() if starts is None else starts:
            s = _run_ipopt(self.ipopt("relaxed"), x0=np.concatenate([x0, (low + high) / 2]),
                           p=np.concatenate([table[0, CAP:], self.deviations(x0)]),
                           lbx=np.concatenate([lo, low]), ubx=np.concatenate([hi, high]), lbg=-np.inf, ubg=0.0)
            solves.append(replace(s, x=s.x[: self.size]))
            if s.message not in IPOPT_INFEASIBLE:
                return False, solves
        return True, solves


def _run_ipopt(solver, **args) -> Solve:
    """One call of a casadi IPOPT solver, as a Solve (``x0`` is the answer when IPOPT raised)."""
    # casadi writes its warnings through Python's standard error; a signal inside IPOPT makes
    # it warn "KeyboardInterruptException" before the run stops with its own one line: held
    # back here, and passed on only when the run goes on
    said = io.StringIO()
    try:
        with contextlib.redirect_stderr(said):
            sol = solver(**args)
    except RuntimeError as exc:
        interrupt.check()
        sys.stderr.write(said.getvalue())
        return Solve(np.asarray(args["x0"], dtype=float), False, f"IPOPT raised: {exc}", 0, "ipopt")
    interrupt.check()  # IPOPT reports Ctrl-C or SIGTERM as a user stop and returns
    sys.stderr.write(said.getvalue())
    stats = solver.stats()
    evals = int(stats.get("iter_count", 0))
    return Solve(np.asarray(sol["x"]).ravel(), bool(stats.get("success")), str(stats.get("return_status")),
                 evals, "ipopt", (np.asarray(sol["lam_x"]).ravel(), np.asarray(sol["lam_g"]).ravel()))


def start_from(problem: FamilyProblem, ev: Evaluation):
    """The NLP's variables (mm) at a checked design."""
    g = ev.design.geometry
    values = {"width": g.width, "height": g.height, "side": g.width, "diameter": g.diameter, "wall": g.wall,
              "depth": g.depth, "hole": g.hole}
    values.update({f"station_{i + 1}": s for i, s in enumerate(g.stations)})
    x = np.clip([float(values[n]) / MM for n in problem.names], problem.lower, problem.upper)
    return np.append(x, ev.objective) if problem.epigraph else x
