"""The search: every allowed material x section family, each solved as a smooth NLP.

Each family's problem is built once as a casadi graph from the same model expressions the
evaluator runs (``model.analyse`` and ``model.limits`` over casadi's Ops), then re-solved with
the material as parameters. Variables are in millimetres and constraints are normalised
(``value/limit - 1 <= 0``). No solver's success flag is trusted: every answer is rounded to
0.01 mm and checked against every limit with the numeric model (``evaluation.evaluate``).
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from designer.spec import catalogue
from designer import model
from designer.result.designfile import validate
from designer.errors import DesignFileError, InputError, SolverError, SpecError, describe_allowed
from designer.result.evaluation import ROUNDING, Design, Evaluation, evaluate
from designer.model import Geometry, MaterialParams

MM = 1e-3
METHODS = ("ipopt", "slsqp", "mma", "ccsaq", "cobyla", "isres", "direct", "grid")
TIE_TOLERANCE = 1e-3          # objectives within 0.1 % tie (MODEL.md section 5)
IPOPT_TOLERANCE = 1e-9
IPOPT_MAX_ITER = 300
NLOPT_XTOL = 1e-8
# Evaluation budgets per nlopt run: deterministic, unlike a wall-clock limit (CCSAQ's inner
# solves make each of its evaluations about 10x dearer, hence its smaller budget).
NLOPT_MAX_EVAL = {"slsqp": 500, "mma": 1000, "ccsaq": 200, "cobyla": 2000, "isres": 4000, "direct": 2000}
GRID_LEVELS = 9               # points per section variable in the grid method
EPIGRAPH_UPPER = 1e6
NAN_PENALTY = 1e6
ALL_STARTS = False  # True: every start point even after a verified answer
FEASIBILITY_TOLERANCE = 1e-9  # as evaluation.Evaluation.violations
# When rounding to 0.01 mm breaks a limit that IPOPT's answer met (several limits active at
# once, rounding each way breaks one), IPOPT solves again with every constraint tightened by
# these normalised margins in turn until the rounded design checks out.
ROUNDING_MARGINS = (1e-4, 1e-3, 1e-2, 5e-2)  # those below the violation rounding caused are skipped
# MMA/CCSAQ inner iterations per outer step, and evaluations of their dual subproblem: both are
# unbounded by default, and the dual solve alone can spin for seconds on these problems.
CCSA_INNER_MAX_EVAL = 50
CCSA_DUAL_MAX_EVAL = 100
NLOPT_SAFETY_SECONDS = 5.0    # a stalled run must not stall the search; budgets end runs first
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


@dataclass(frozen=True)
class Solve:
    """One solver run: the raw answer, before rounding and checking."""

    x: np.ndarray
    success: bool          # what the solver said: recorded, never trusted
    message: str
    evaluations: int
    method: str


@dataclass
class Candidate:
    material: str
    family: Family
    evaluation: Evaluation | None
    status: str                       # optimal | infeasible | failed
    solves: list = field(default_factory=list)
    fallbacks: list = field(default_factory=list)

    def record(self) -> dict:
        ev = self.evaluation
        out = {"material": self.material, "section": self.family.label, "status": self.status,
               "objective": None, "error_ratio": None, "deflection": None, "mass": None,
               "natural_frequency": None, "worst_violation": None}
        if ev is not None:
            a = ev.analysis
            out.update(objective=ev.objective, error_ratio=ev.error_ratio, deflection=float(a.deflection),
                       mass=float(a.mass), natural_frequency=float(a.natural_frequency),
                       worst_violation=ev.worst_violation,
                       violated=[lim.name for lim in ev.violations])
        if self.fallbacks:
            out["fallbacks"] = list(self.fallbacks)
        return out


def families(spec) -> list[Family]:
    feature = spec.search.feature
    return [Family(s, feature) for s in spec.search.sections if not (feature == "hole" and s != "rectangle")]


# --------------------------------------------------------------------------- the NLP of a family

class FamilyProblem:
    """Variables (mm), bounds, and casadi functions of one family; material as parameters."""

    def __init__(self, spec, family: Family):
        import casadi as ca

        self.spec, self.family = spec, family
        self.names, self.lower, self.upper = self._variables()
        n = len(self.names)
        epigraph = spec.objective == "error"
        self.size = n + (1 if epigraph else 0)
        x = ca.SX.sym("x", self.size)
        # E (GPa), allowable stress (MPa), density (kg/m^3), cap on the primary objective
        par = ca.SX.sym("p", 4)
        ops = model.casadi_ops()
        geometry = self.geometry([x[i] * MM for i in range(n)])
        mat = MaterialParams(par[0] * 1e9, par[1] * 1e6, par[2])
        a = model.analyse(geometry, mat, spec, ops)
        lims = [lim for lim in model.limits(geometry, a, mat, spec, include_targets=not epigraph, ops=ops)
                if lim.name not in BOUND_LIMITS]
        self.limit_names = [lim.name for lim in lims]
        g = [lim.normalised for lim in lims]
        deflection, mass = a.deflection / MM, a.mass * 1e3
        if epigraph:
            e = x[n]
            g += [a.force_error / spec.targets.force_error - e, a.position_error / spec.targets.position_error - e]
            f, secondary = e, deflection
        elif spec.objective == "deflection":
            f, secondary = deflection, mass
        else:
            f, secondary = mass, deflection
        # The tie rule (MODEL.md 5) as a second stage: the secondary objective with the
        # primary capped inside the tie band. With a huge cap the constraint is idle.
        g.append(f / par[3] - 1)
        self.epigraph = epigraph
        self.n_constraints = len(g)
        gv = ca.vertcat(*g)
        self.nlp = {"x": x, "p": par, "f": f, "g": gv}
        self.nlp_secondary = {"x": x, "p": par, "f": secondary, "g": gv}
        self.functions = ca.Function("fg", [x, par], [f, ca.gradient(f, x), gv, ca.jacobian(gv, x)])
        self._ipopt = {}

    # variables --------------------------------------------------------------
    def _variables(self):
        spec, fam = self.spec, self.family
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
            add("depth", lim.min_pocket_depth, max(lim.min_pocket_depth, lim.max_pocket_fraction * size_hi))
        elif fam.feature == "hole":
            add("hole", lim.min_wall, max(lim.min_wall, size_hi - 2 * lim.min_wall))
        for i in range(spec.stations):
            add(f"station_{i + 1}", lim.clamp_clearance, spec.load.position_min)
        if lo and any(a > b for a, b in zip(lo, hi)):
            bad = names[[a > b for a, b in zip(lo, hi)].index(True)]
            raise SpecError(f"limits: the bounds leave no room for {bad}; check limits.width and limits.height")
        return names, np.array(lo), np.array(hi)

    def geometry(self, v) -> Geometry:
        """A Geometry from variable values in SI (floats, arrays or casadi)."""
        spec, fam = self.spec, self.family
        named = dict(zip(self.names, v))
        lp, wp = spec.pocket_size()
        if "side" in named:
            named["width"] = named["height"] = named["side"]
        stations = tuple(named[f"station_{i + 1}"] for i in range(spec.stations))
        return Geometry(section=fam.section, feature=fam.feature, stations=stations, length=spec.free_length,
                        width=named.get("width"), height=named.get("height"), diameter=named.get("diameter"),
                        wall=named.get("wall"), depth=named.get("depth", 0.0), hole=named.get("hole", 0.0),
                        pocket_length=lp, pocket_width=wp, gauge_length=spec.gauge.length, axes=spec.axes)

    def design(self, x, material) -> Design:
        return Design(material, self.geometry([float(v) * MM for v in x[: len(self.names)]]))

    def bounds(self):
        lo, hi = list(self.lower), list(self.upper)
        if self.epigraph:
            lo.append(0.0)
            hi.append(EPIGRAPH_UPPER)
        return np.array(lo), np.array(hi)

    # start points -----------------------------------------------------------
    def starts(self) -> list[np.ndarray]:
        """Deterministic start points: sections at 35 % and 70 % of their range, stations spread
        evenly over the room between the clamp and the load region."""
        spec, lim = self.spec, self.spec.limits
        out = []
        for frac in (0.35, 0.7):
            v = {}
            for name, a, b in zip(self.names, self.lower, self.upper):
                share = {"depth": 0.3, "hole": 0.5, "wall": 0.2}.get(name, frac)
                v[name] = a + share * (b - a)
            if self.family.feature == "hole":
                half = v["hole"] / 2
            elif self.family.feature == "pocket":
                half = spec.pocket_size()[0] / MM / 2
            else:
                half = spec.gauge.length / MM / 2
            first = lim.clamp_clearance / MM + half
            last = max((spec.load.position_min - lim.load_clearance) / MM - half, first + 1.0)
            for i, d in enumerate(np.linspace(first, last, spec.stations)):
                v[f"station_{i + 1}"] = d
            x = np.clip([v[n] for n in self.names], self.lower, self.upper)
            out.append(np.append(x, 1.0) if self.epigraph else x)
        return out

    # solvers ----------------------------------------------------------------
    def ipopt(self, stage: str = "primary"):
        if stage not in self._ipopt:
            import casadi as ca

            opts = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                    "ipopt.tol": IPOPT_TOLERANCE, "ipopt.constr_viol_tol": 1e-9,
                    "ipopt.max_iter": IPOPT_MAX_ITER, "ipopt.mu_strategy": "adaptive", "error_on_fail": False}
            nlp = self.nlp if stage == "primary" else self.nlp_secondary
            self._ipopt[stage] = ca.nlpsol(f"fpd_{self.family.section}_{self.family.feature}_{stage}", "ipopt",
                                           nlp, opts)
        return self._ipopt[stage]

    def solve(self, method: str, params, x0, stage: str = "primary", margin: float = 0.0) -> Solve:
        """One run; ``margin`` (IPOPT only) tightens every constraint to ``g <= -margin``."""
        lo, hi = self.bounds()
        if method == "ipopt":
            solver = self.ipopt(stage)
            try:
                sol = solver(x0=x0, p=params, lbx=lo, ubx=hi, lbg=-np.inf, ubg=-margin)
            except RuntimeError as exc:
                return Solve(np.asarray(x0, dtype=float), False, f"IPOPT raised: {exc}", 0, method)
            stats = solver.stats()
            evals = int(stats.get("iter_count", 0))
            return Solve(np.asarray(sol["x"]).ravel(), bool(stats.get("success")), str(stats.get("return_status")),
                         evals, method)
        if method == "grid":
            return grid_solve(self, params)
        return nlopt_solve(self, method, params, x0)


# --------------------------------------------------------------------------- nlopt adapter

_NLOPT_ALGORITHMS = {"slsqp": "LD_SLSQP", "mma": "LD_MMA", "ccsaq": "LD_CCSAQ", "cobyla": "LN_COBYLA",
                     "isres": "GN_ISRES", "direct": "GN_DIRECT_L"}


def nlopt_solve(problem: FamilyProblem, method: str, params, x0) -> Solve:
    """One nlopt run behind the same interface; DIRECT, which takes no constraints, runs in AUGLAG."""
    import nlopt

    lo, hi = problem.bounds()
    if problem.epigraph:  # a finite box for global methods: the error ratio stays below 1e3
        hi = hi.copy()
        hi[-1] = 1e3
    n = problem.size
    fn = problem.functions
    counter = {"n": 0}

    # Global methods sample impossible points of the box (a flat deeper than the radius, two
    # stations at one place): the model gives NaN or inf there, passed on as a large penalty.
    def objective(x, grad):
        counter["n"] += 1
        f, df, _, _ = fn(x, params)
        if grad.size > 0:
            grad[:] = np.nan_to_num(np.asarray(df).ravel(), nan=0.0)
        return float(_finite(f).item())  # a 1x1 DM: float() of a 2-D array fails on numpy >= 2.4

    def constraints(result, x, grad):
        _, _, g, dg = fn(x, params)
        result[:] = _finite(np.asarray(g).ravel())
        if grad.size > 0:
            grad[:, :] = np.nan_to_num(np.asarray(dg), nan=0.0)

    algorithm = getattr(nlopt, _NLOPT_ALGORITHMS[method])
    if method == "direct":
        opt = nlopt.opt(nlopt.AUGLAG, n)
        local = nlopt.opt(algorithm, n)
        local.set_maxeval(NLOPT_MAX_EVAL[method] // 10)
        local.set_xtol_rel(1e-6)
        opt.set_local_optimizer(local)
    else:
        opt = nlopt.opt(algorithm, n)
    opt.set_lower_bounds(lo)
    opt.set_upper_bounds(hi)
    opt.set_min_objective(objective)
    opt.add_inequality_mconstraint(constraints, np.full(problem.n_constraints, 1e-10))
    opt.set_xtol_rel(NLOPT_XTOL)
    opt.set_maxeval(NLOPT_MAX_EVAL[method])
    opt.set_maxtime(NLOPT_SAFETY_SECONDS)
    if method in ("mma", "ccsaq"):
        opt.set_param("inner_maxeval", CCSA_INNER_MAX_EVAL)
        opt.set_param("dual_maxeval", CCSA_DUAL_MAX_EVAL)
    if method == "isres":
        opt.set_population(20 * (n + 1))
        seed = 12345
        nlopt.srand(seed)
    x_start = np.clip(np.asarray(x0, dtype=float), lo, hi)
    try:
        x = opt.optimize(x_start)
        code = opt.last_optimize_result()
        return Solve(np.asarray(x), code > 0, _nlopt_message(code), counter["n"], method)
    except Exception as exc:  # nlopt's own exception types do not derive from RuntimeError
        # RoundoffLimited, forced stops and failures: the run is recorded as failed, never raised.
        return Solve(x_start, False, f"nlopt {type(exc).__name__}: {exc}", counter["n"], method)


def _finite(values):
    return np.nan_to_num(np.asarray(values, dtype=float), nan=NAN_PENALTY, posinf=NAN_PENALTY, neginf=-NAN_PENALTY)


def _nlopt_message(code: int) -> str:
    return {1: "success", 2: "stopval reached", 3: "ftol reached", 4: "xtol reached", 5: "maxeval reached",
            6: "maxtime reached"}.get(code, f"nlopt result {code}")


# --------------------------------------------------------------------------- grid search

def grid_solve(problem: FamilyProblem, params) -> Solve:
    """A plain grid over the section variables with stations at their extremes, vectorised."""
    names = problem.names
    axes = []
    station_idx = [i for i, nme in enumerate(names) if nme.startswith("station_")]
    for i, nme in enumerate(names):
        if i in station_idx:
            axes.append(None)
        else:
            axes.append(np.linspace(problem.lower[i], problem.upper[i], GRID_LEVELS))
    section_axes = [a for a in axes if a is not None]
    mesh = [m.ravel() for m in np.meshgrid(*section_axes, indexing="ij")]
    x = np.empty((len(mesh[0]), len(names)))
    j = 0
    for i in range(len(names)):
        if i not in station_idx:
            x[:, i] = mesh[j]
            j += 1
    x[:, station_idx] = _spread_stations(problem, x)
    material = MaterialParams(params[0] * 1e9, params[1] * 1e6, params[2])
    g = problem.geometry([x[:, i] * MM for i in range(len(names))])
    with np.errstate(invalid="ignore", divide="ignore"):  # impossible grid points give NaN: infeasible
        a = model.analyse(g, material, problem.spec)
        lims = model.limits(g, a, material, problem.spec, include_targets=not problem.epigraph)
        viol = model.worst_normalised(lims, len(x))
    viol = np.where(np.isnan(viol), np.inf, viol)
    if problem.epigraph:
        f = np.maximum(a.force_error / problem.spec.targets.force_error,
                       a.position_error / problem.spec.targets.position_error)
    elif problem.spec.objective == "deflection":
        f = a.deflection / MM
    else:
        f = a.mass * 1e3
    f = np.nan_to_num(np.broadcast_to(np.asarray(f, dtype=float), (len(x),)), nan=np.inf)
    feasible = viol <= 0
    if feasible.any():
        best = int(np.argmin(np.where(feasible, f, np.inf)))
    else:  # the least violating of the points that are beams at all, if any are
        with np.errstate(invalid="ignore", divide="ignore"):
            beam = model.worst_normalised(model.section_limits(g, problem.spec), len(x)) <= 0
        best = int(np.argmin(np.where(beam, viol, np.inf) if beam.any() else viol))
    xb = x[best]
    if problem.epigraph:
        xb = np.append(xb, f[best])
    return Solve(xb, bool(feasible.any()), f"grid of {len(x)} designs", len(x), "grid")


def _spread_stations(problem: FamilyProblem, x):
    """Stations from the clamp-side limit to the load-side limit, evenly (vectorised)."""
    spec, lim = problem.spec, problem.spec.limits
    named = {n: x[:, i] for i, n in enumerate(problem.names)}
    if problem.family.feature == "hole":
        lf = named["hole"]
    elif problem.family.feature == "pocket":
        lf = np.full(len(x), spec.pocket_size()[0] / MM)
    else:
        lf = np.full(len(x), spec.gauge.length / MM)
    first = lim.clamp_clearance / MM + lf / 2
    last = (spec.load.position_min - lim.load_clearance) / MM - lf / 2
    t = np.linspace(0, 1, spec.stations)
    return first[:, None] + (last - first)[:, None] * t[None, :]


# --------------------------------------------------------------------------- rounding and checking

def round_and_check(design: Design, spec) -> Evaluation | None:
    """Round to 0.01 mm; if rounding broke a limit, try the neighbouring grid points.

    Every length is rounded down or up (inner stations to the nearest); all combinations are
    checked at once with the numeric model over numpy arrays, the best is chosen as ``pick``
    chooses, and that one design is evaluated again on its own and returned. None when no
    combination can be evaluated at all.
    """
    g = design.geometry
    fields_ = [f for f in ("width", "height", "diameter", "wall") if getattr(g, f) is not None]
    if g.axes == 2 and g.section == "rectangle":
        fields_.remove("height")  # a biaxial rectangle is square
    fields_ += {"pocket": ["depth"], "hole": ["hole"]}.get(g.feature, [])
    stations = [float(s) for s in g.stations]
    choices = [_floor_ceil(float(getattr(g, f))) for f in fields_]
    station_choices = [_floor_ceil(s) for s in stations]
    for i in range(1, len(stations) - 1):  # linear limits with slack: nearest is enough
        station_choices[i] = (round(stations[i] / ROUNDING) * ROUNDING,)
    combos = np.array(list(itertools.product(*choices, *station_choices)))
    named = {f: combos[:, i] for i, f in enumerate(fields_)}
    if g.axes == 2 and g.section == "rectangle":
        named["height"] = named["width"]
    st = combos[:, len(fields_):]
    trial = replace(g, stations=tuple(st[:, i] for i in range(st.shape[1])),
                    length=round(float(g.length) / ROUNDING) * ROUNDING, **named)
    params = design.material_params(spec)
    with np.errstate(all="ignore"):
        a = model.analyse(trial, params, spec)
        lims = model.limits(trial, a, params, spec)
        viol = model.worst_normalised(lims, len(combos))
        objective = np.broadcast_to(np.asarray(_objective_array(a, spec), dtype=float), (len(combos),))
        deflection = np.broadcast_to(np.asarray(a.deflection, dtype=float), (len(combos),))
        mass = np.broadcast_to(np.asarray(a.mass, dtype=float), (len(combos),))
    valid = np.isfinite(viol) & np.isfinite(objective) & np.all(np.diff(st, axis=1) > 0, axis=1)
    if not valid.any():
        return None
    feasible = valid & (viol <= FEASIBILITY_TOLERANCE)
    if feasible.any():
        lead = objective[feasible].min()
        band = feasible & (objective - lead <= TIE_TOLERANCE * abs(lead))
        idx = np.flatnonzero(band)
        best = idx[np.lexsort((objective[idx], mass[idx], deflection[idx]))[0]]
    else:
        best = int(np.argmin(np.where(valid, viol, np.inf)))
    chosen = replace(g, stations=tuple(float(v) for v in st[best]), length=float(trial.length),
                     **{f: float(v[best]) for f, v in named.items()})
    try:
        return evaluate(Design(design.material, chosen), spec)
    except InputError:
        return None


def pick(evaluations: list) -> Evaluation | None:
    """The best of several checked designs: the first by ``rank`` among the feasible ones,
    else the least violating. Ties are anchored on the best objective, never chained."""
    feasible = [ev for ev in evaluations if ev.feasible]
    if feasible:
        return rank(feasible)[0]
    return min(evaluations, key=lambda ev: (not buildable(ev), ev.worst_violation), default=None)


def buildable(ev: Evaluation) -> bool:
    """Whether the design is a beam at all (a pocket shallower than the wall, a hole narrower than
    the bar, ...), as ``designfile.validate`` judges it: a least-infeasible design that is not
    could not be plotted, exported or simulated from its design.json."""
    try:
        validate({"spec": {}, "design": ev.design.shape_dict()})
    except DesignFileError:
        return False
    return True


def _objective_array(a, spec):
    if spec.objective == "deflection":
        return a.deflection
    if spec.objective == "mass":
        return a.mass
    return np.maximum(a.force_error / spec.targets.force_error, a.position_error / spec.targets.position_error)


def _floor_ceil(v: float) -> tuple:
    lo = math.floor(v / ROUNDING + 1e-9) * ROUNDING
    hi = math.ceil(v / ROUNDING - 1e-9) * ROUNDING
    return (round(lo, 8),) if abs(hi - lo) < 1e-12 else (round(lo, 8), round(hi, 8))


def ranks_before(a: Evaluation, b: Evaluation) -> bool:
    """Lower objective first; within 0.1 % (a tie) lower deflection, then lower mass (MODEL.md 5)."""
    fa, fb = a.objective, b.objective
    if abs(fa - fb) > TIE_TOLERANCE * min(abs(fa), abs(fb)):
        return fa < fb
    return (float(a.analysis.deflection), float(a.analysis.mass)) < (float(b.analysis.deflection),
                                                                   float(b.analysis.mass))


def rank(evaluations: list) -> list:
    """Order feasible evaluations: repeatedly take the best objective, then among those within
    0.1 % of it the lowest deflection, then the lowest mass. Deterministic."""
    rest = sorted(evaluations, key=lambda ev: ev.objective)
    out = []
    while rest:
        lead = rest[0].objective
        ties = [ev for ev in rest if ev.objective - lead <= TIE_TOLERANCE * abs(lead)]
        pick = min(ties, key=lambda ev: (float(ev.analysis.deflection), float(ev.analysis.mass), ev.objective))
        out.append(pick)
        rest.remove(pick)
    return out


# --------------------------------------------------------------------------- the search

FALLBACK = {"ipopt": "slsqp"}  # every other method falls back to ipopt
# IPOPT's answers that are a verdict on the problem, not a failure of the solver: it converged
# to a point that minimises the constraint violation. When every start ends so, another method
# is not tried (on the bench suite such a fallback never found a feasible design).
IPOPT_INFEASIBLE = ("Infeasible_Problem_Detected",)


@dataclass
class Outcome:
    """The result of ``optimize``: complete when returned (STYLE.md habit 5)."""

    success: bool                     # a design meets every limit
    message: str
    record: dict                      # design.json
    best: Evaluation
    candidates: list
    seconds: float
    evaluations: int


NO_CAP = 1e12  # the primary-objective cap of a first-stage solve: never reached


def material_params(material, spec, cap: float = NO_CAP) -> list[float]:
    return [material.E / 1e9, material.allowable_stress(spec.limits.safety_factor, spec.limits.fatigue) / 1e6,
            material.density, cap]


def solve_candidate(problem: FamilyProblem, material, method: str) -> Candidate:
    """Solve one material x family from several starts; fall back to another method when no
    start gives a verified design. Every answer is rounded and checked."""
    spec = problem.spec
    params = material_params(material, spec)
    cand = Candidate(material.name, problem.family, None, "failed")
    starts = problem.starts()
    checked = []
    if method in ("grid", "isres", "direct"):
        starts = starts[:1]  # global methods do not depend on the start
    methods = [method, FALLBACK.get(method, "ipopt")]
    for m in dict.fromkeys(methods):
        verdicts = 0  # starts that ended in a verdict rather than a failure of the solver
        for i, x0 in enumerate(starts):
            s = problem.solve(m, params, x0)
            cand.solves.append(s)
            if m == "ipopt" and s.message in IPOPT_INFEASIBLE:
                verdicts += 1
            ev = round_and_check(problem.design(s.x, material), spec)
            if ev is None:
                cand.fallbacks.append(f"{m} start {i + 1}: the answer could not be evaluated ({s.message})")
                continue
            if not s.success:
                cand.fallbacks.append(f"{m} start {i + 1}: {s.message}")
            elif not ev.feasible and ev.violations and not (problem.epigraph and _only_targets(ev)):
                cand.fallbacks.append(f"{m} start {i + 1}: reported success but violates "
                                      + ", ".join(v.name for v in ev.violations))
                if m == "ipopt":
                    s, ev = _back_off(problem, params, material, s, ev, cand, f"{m} start {i + 1}")
            if m == "ipopt" and s.success and problem.epigraph and _only_targets(ev):
                verdicts += 1  # the least error this family reaches misses the targets
            checked.append(ev)
            cand.evaluation = pick(checked)
            if s.success and ev.feasible and not ALL_STARTS:
                break  # a verified answer: the other starts are kept for failures
        if cand.evaluation is not None and cand.evaluation.feasible:
            break
        if m != method or method == "grid":
            break
        if verdicts == len(starts):
            cand.fallbacks.append(f"{m}: every start ended in a verdict (locally infeasible, or the targets out of "
                                  "reach); no fallback")
            break
    if cand.evaluation is not None:
        cand.status = "optimal" if cand.evaluation.feasible else "infeasible"
    return cand


def _back_off(problem: FamilyProblem, params, material, s: Solve, ev: Evaluation, cand: Candidate, where: str):
    """Rounding broke a limit: re-solve from the answer with the constraints tightened by each of
    ROUNDING_MARGINS in turn, from the first as large as the violation rounding caused; the first
    answer whose rounded design breaks no limit of the NLP replaces it (under the error objective
    it may still miss the targets: that is a verdict)."""
    broken = max(float(v.normalised) for v in ev.violations if not (problem.epigraph and v.name in TARGET_LIMITS))
    # a margin smaller than the violation rounding caused seldom survives the next rounding
    margins = [m for m in ROUNDING_MARGINS if m >= broken] or ROUNDING_MARGINS[-1:]
    for margin in margins:
        s2 = problem.solve("ipopt", params, s.x, margin=margin)
        cand.solves.append(s2)
        ev2 = round_and_check(problem.design(s2.x, material), problem.spec) if s2.success else None
        if ev2 is not None and (ev2.feasible or (problem.epigraph and _only_targets(ev2))):
            cand.fallbacks.append(f"{where}: re-solved with every limit tightened by {margin:.0e}; "
                                  "the rounded design " + ("meets every limit" if ev2.feasible else
                                                           "misses only the accuracy targets"))
            return s2, ev2
    return s, ev


TARGET_LIMITS = ("force_error", "position_error")


def _only_targets(ev: Evaluation) -> bool:
    return all(v.name in TARGET_LIMITS for v in ev.violations)


def optimize(spec, method: str = "ipopt", progress: bool = False, materials=None,
             tie_break: bool = True) -> Outcome:
    """Search every allowed material and section family; return the verified best design."""
    from designer.result.record import build_record

    if method not in METHODS:
        raise SpecError(f"--method: {method!r} is not allowed; must be {describe_allowed(METHODS)}")
    t0 = time.perf_counter()
    mats = [catalogue.material(m, "search.materials") for m in (materials or spec.search.materials)]
    fams = families(spec)
    candidates: list[Candidate] = []
    problems: dict[Family, FamilyProblem] = {}
    bar = _progress(len(mats) * len(fams)) if progress else None
    try:
        for fam in fams:
            problem = FamilyProblem(spec, fam)
            problems[fam] = problem
            for mat in mats:
                candidates.append(solve_candidate(problem, mat, method))
                if bar:
                    bar.advance()
    finally:
        if bar:
            bar.stop()
    if method == "ipopt" and tie_break:  # the other methods are compared as they are (``bench``)
        break_ties(candidates, problems)
    seconds = time.perf_counter() - t0
    evaluations = sum(s.evaluations for c in candidates for s in c.solves)
    feasible = rank([c.evaluation for c in candidates if c.evaluation is not None and c.evaluation.feasible])
    order = {id(ev): i for i, ev in enumerate(feasible)}

    def cand_key(c):
        if c.evaluation is None:
            return (2, True, math.inf, 0)
        if c.evaluation.feasible:
            return (0, False, order[id(c.evaluation)], 0)
        return (1, not buildable(c.evaluation), c.evaluation.worst_violation, c.evaluation.objective)

    candidates.sort(key=cand_key)
    solver = {"method": method, "seconds": seconds, "evaluations": evaluations,
              "solves": sum(len(c.solves) for c in candidates),
              "fallbacks": [f"{c.material} {c.family.label}: {f}" for c in candidates for f in c.fallbacks]}
    if not any(c.evaluation is not None for c in candidates):
        raise SolverError("no solver returned a design that could be evaluated; try another --method")
    best = candidates[0].evaluation
    if best.feasible:
        status, messages = "optimal", []
        message = f"{best.design.label()} meets every limit"
    else:
        status, messages = "infeasible", diagnose(spec, best, candidates)
        message = messages[0]
    record = build_record(status, spec, best, [c.record() for c in candidates], solver, messages)
    return Outcome(best.feasible, message, record, best, candidates, seconds, evaluations)


def _start_from(problem: FamilyProblem, ev: Evaluation):
    """The NLP's variables (mm) at a checked design."""
    g = ev.design.geometry
    values = {"width": g.width, "height": g.height, "side": g.width, "diameter": g.diameter, "wall": g.wall,
              "depth": g.depth, "hole": g.hole}
    values.update({f"station_{i + 1}": s for i, s in enumerate(g.stations)})
    x = np.clip([float(values[n]) / MM for n in problem.names], problem.lower, problem.upper)
    return np.append(x, ev.objective) if problem.epigraph else x


def break_ties(candidates: list, problems: dict) -> None:
    """The tie rule as a second stage (MODEL.md section 5).

    Near the optimum the objective is often flat (a strain-limited design has a sensitivity
    that does not depend on the material), so many designs lie within 0.1 % of the best. Each
    candidate inside that band is re-solved for the secondary objective (deflection, or mass
    when deflection is the objective) with its primary objective capped inside the band; the
    answer is kept only if it checks out and ranks before the candidate's first answer.
    """
    feasible = [c for c in candidates if c.evaluation is not None and c.evaluation.feasible]
    if not feasible:
        return
    lead = min(c.evaluation.objective for c in feasible)
    cap = lead * (1 + TIE_TOLERANCE / 2)
    for cand in feasible:
        if cand.evaluation.objective > lead * (1 + TIE_TOLERANCE):
            continue
        problem = problems[cand.family]
        material = cand.evaluation.design.material
        x0 = _start_from(problem, cand.evaluation)
        if problem.epigraph:
            x0[-1] = min(x0[-1], cap)
        # the NLP's primary objective is in mm (deflection) or g (mass), Evaluation.objective in SI
        nlp_cap = cap * {"deflection": 1 / MM, "mass": 1e3}.get(problem.spec.objective, 1.0)
        s = problem.solve("ipopt", material_params(material, problem.spec, nlp_cap), x0, stage="secondary")
        cand.solves.append(s)
        ev = round_and_check(problem.design(s.x, material), problem.spec)
        if ev is not None and ev.feasible and ev.objective <= lead * (1 + TIE_TOLERANCE) and \
                ranks_before(ev, cand.evaluation):
            cand.evaluation = ev


def _progress(total: int):
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    progress = Progress(TextColumn("optimising"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                        TimeElapsedColumn(), transient=True)
    task = progress.add_task("search", total=total)
    progress.start()

    class Bar:
        def advance(self):
            progress.advance(task)

        def stop(self):
            progress.stop()

    return Bar()


# --------------------------------------------------------------------------- infeasibility in user terms

def minimum_room(spec) -> float:
    """The smallest x_min that leaves room for the stations (MODEL.md section 1 geometry rules)."""
    lim = spec.limits
    if spec.search.feature == "pocket":
        lf = spec.pocket_size()[0]
    elif spec.search.feature == "hole":
        lf = lim.min_wall
    else:
        lf = spec.gauge.length
    n = spec.stations
    return lim.clamp_clearance + n * lf + (n - 1) * lim.gauge_gap + lim.load_clearance


def diagnose(spec, best: Evaluation, candidates) -> list[str]:
    """Name the limits in conflict and what would resolve them, in the spec's own terms."""
    mm = 1e3
    out = []
    room = minimum_room(spec)
    if spec.load.position_min < room - 1e-9:
        out.append(f"no room for {spec.stations} gauge stations before the load region: load.position[0] is "
                   f"{spec.load.position_min * mm:.4g} mm but the clamp clearance, {spec.stations} features of "
                   f"their length, the gauge gaps and the load clearance need at least {room * mm:.4g} mm; "
                   "move the load region out, use fewer stations, a smaller gauge or smaller margins")
    violated = {v.name: v for v in best.violations}
    label = f"{best.design.label()} (the least infeasible design found)"
    head = f"no design meets every limit; closest: {label}, violating " + ", ".join(violated) if violated else \
        f"no design meets every limit; closest: {label}"
    out.insert(0, head)
    a = best.analysis
    sv = spec.sigma_v
    if "force_error" in violated or "position_error" in violated:
        e = best.error_ratio
        binding = [lim.name for lim in best.limits if lim.record()["active"]
                   and lim.name not in ("force_error", "position_error")]
        out.append(f"the accuracy targets are out of reach: the best error ratio is {e:.3g} (1 = on target)"
                   + (f" with {', '.join(binding)} binding" if binding else "")
                   + f"; they would be met with electronics noise of at most {sv / e * 1e3:.3g} mV at the output "
                   f"(now {sv * 1e3:.3g} mV), or load.force[0] of at least {spec.load.force_min * e:.4g} N "
                   f"(now {spec.load.force_min:.4g} N), or targets of force_error >= "
                   f"{float(a.force_error) * 100:.3g} % and position_error >= {float(a.position_error) * mm:.3g} mm")
        if spec.limits.max_deflection is not None and "deflection" in binding:
            out.append(f"the deflection limit binds: limits.max_deflection = {spec.limits.max_deflection * mm:.4g} mm; "
                       "a larger allowed deflection gives a more sensitive beam")
    for name in ("stress_root", "stress_feature"):
        if name in violated:
            v = violated[name]
            ratio = float(v.value) / float(v.limit)
            out.append(f"{name}: {float(v.value) / 1e6:.4g} MPa exceeds the allowable {float(v.limit) / 1e6:.4g} MPa "
                       f"even at the largest section allowed; lower load.force[1] to {spec.load.force_max / ratio:.4g} N, "
                       "enlarge limits.width/limits.height, choose a stronger material or a lower safety factor")
            break
    if "gauge_strain" in violated:
        v = violated["gauge_strain"]
        out.append(f"gauge_strain: {float(v.value) * 1e6:.0f} µε exceeds the gauge's {float(v.limit) * 1e6:.0f} µε; "
                   f"lower load.force[1] to {spec.load.force_max * float(v.limit) / float(v.value):.4g} N or enlarge the section")
    if "min_signal_snr" in violated:
        v = violated["min_signal_snr"]
        ratio = float(v.limit) / float(v.value)
        out.append(f"min_signal_snr: the smallest signal is {float(v.value):.3g} noise levels, below {float(v.limit):.3g}; "
                   f"lower the noise to {sv / ratio * 1e3:.3g} mV or raise load.force[0] to {spec.load.force_min * ratio:.4g} N")
    if "deflection" in violated:
        v = violated["deflection"]
        out.append(f"deflection: {float(v.value) * mm:.4g} mm exceeds limits.max_deflection = {float(v.limit) * mm:.4g} mm; "
                   f"allow at least {float(v.value) * mm:.4g} mm, or enlarge limits.width/limits.height")
    if "natural_frequency" in violated:
        v = violated["natural_frequency"]
        out.append(f"natural_frequency: {float(v.value):.4g} Hz is below limits.min_frequency = {float(v.limit):.4g} Hz; "
                   f"lower it to {float(v.value):.4g} Hz or shorten the beam")
    return out
