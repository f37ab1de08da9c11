"""Why a spec is infeasible, in the spec's own terms: the limits in conflict and what would resolve them."""

from __future__ import annotations

import math

from designer import model
from designer.model import corrections, domain, grooves
from designer.model.limits import shallowest_pocket
from designer.model.sections import flat_depth
from designer.result.evaluation import ROUNDING, Evaluation

# The stress limits (docs/model.md §4), and the limits whose value grows in proportion to the
# largest force, load.force[1] (stress, strain, the bridge's full-scale output, the deflection).
STRENGTH_LIMITS = ("stress_root", "stress_feature", "fatigue_feature")
LOAD_LIMITS = (*STRENGTH_LIMITS, "gauge_strain", "adc_range", "deflection")
# The error budget's terms in proportion to the noise (model.budget.contributions)
NOISE_TERMS = ("noise", "calibration fit")
# What the 3-D study's parameters measure (docs/model.md §7), for a design outside its study
# (``_outside_study``); {size}: the section's size in the load direction, {depth}: what a pocket's
# depth is measured against
PARAMETERS = {
    "length_ratio": "the feature's length along the beam over {size}",
    "width_ratio": "the width over {size}",
    "grid_ratio": "the gauge's grid length over {size}",
    "depth_ratio": "the pocket's depth over {depth}",
    "radius_ratio": "the pocket's floor radius over its depth",
    "notch_ratio": "the root of the pocket's depth over its floor radius",
    "pocket_width_ratio": "the slot's width over the bar's",
    "side_wall_ratio": "the width its slot leaves, both side walls, over {size}",
    "plan_notch": "the root of the slot's depth over its corner radius in plan, the end mill's",
    "shoulder_ratio": "the height of the flat's end wall that its wire channel leaves, over the flat's depth",
    "shoulder_notch": "the root of that end wall's height over the floor radius",
    "hole_ratio": "the hole's diameter over {size}",
    "wall_ratio": "the tube's wall over its diameter",
    "clamp_near": "exp(-3 u), its first feature's end u sizes from the clamp",
    "gap_slow": "exp(-3.7 g), the gauge grid's ends g sizes inside the pocket's",
    "slenderness": "the beam's length over {size}",
}


def no_room(spec) -> str:
    """Why the stations cannot fit before the load region and the load grooves (the geometry rules
    of docs/model.md section 1, ``model.minimum_room``), whatever the section, led by the key to
    change; '' when they can."""
    need, end = model.minimum_room(spec), grooves.stations_end(spec)
    if not end < need - 1e-9:
        return ""
    needs = (f"the clamp clearance, {spec.stations} features of their length and the gauge gaps need "
             f"{need * 1e3:.4g} mm from the clamp face")
    fix = "use fewer stations, a smaller gauge or smaller margins"
    if need <= spec.load.position_min - spec.limits.load_clearance + 1e-9:   # room but for a groove
        first = min(grooves.positions(spec)) * 1e3
        past = (need + spec.limits.load_clearance + grooves.WIDTH / 2) * 1e3
        key, which, move = (("cad.groove_positions", "load groove at", f"move the grooves out past {past:.4g} mm")
                            if spec.cad.groove_positions else
                            ("cad.load_grooves", "default load groove at load.position[0] =",
                             f"give cad.groove_positions past {past:.4g} mm"))
        return (f"{key}: no room for {spec.stations} gauge stations before the {which} {first:.4g} mm: {needs}, "
                f"and limits.load_clearance before the groove's edge leaves {end * 1e3:.4g} mm; {move}, or {fix}")
    return (f"load.position: no room for {spec.stations} gauge stations before the load region: {needs}, and "
            f"limits.load_clearance {spec.limits.load_clearance * 1e3:.4g} mm more: load.position[0] is "
            f"{spec.load.position_min * 1e3:.4g} mm but must be at least "
            f"{(need + spec.limits.load_clearance) * 1e3:.4g} mm; move the load region out, or {fix}")


def diagnose(spec, best: Evaluation, candidates, farther=None, looser=None, plain=None) -> list[str]:
    """Name the limits in conflict and what would resolve them, in the spec's own terms.
    ``farther``: a load region's start and the design that meets every limit from there, when the
    room before the load region holds ``best``; ``looser``: ``{limit: (level, design)}``, a level of
    the deflection or frequency limit ``best`` breaks under which the design meets every limit
    (``remedies.looser``); ``plain``: the best design without a feature when it meets every limit
    (``remedies.plain``)."""
    looser = looser or {}
    mm = 1e3
    out = []
    if crowded := no_room(spec):
        out.append(crowded)
    violated = {v.name: v for v in best.violations}
    label = f"{best.design.label()} (the least infeasible design found)"
    head = f"no design meets every limit; closest: {label}, violating " + ", ".join(violated) if violated else \
        f"no design meets every limit; closest: {label}"
    out.insert(0, head)
    if crowded:
        # no section has room for the stations: the closest design's figures are of stations that do
        # not fit (the least force or noise they name resolves nothing; 030-infeasible-room's signal
        # was 4e-14 noise levels, its noise advice 5e-18 mV)
        return out
    if (not_a_beam := model.unbuildable(best.design.geometry)) is not None:
        # its figures are not a sensor's (a slot wider than its bar reads a negative sensitivity):
        # the messages below would reason from them
        out.append(_not_a_beam(spec, *not_a_beam))
        return out
    check = best.tolerance
    if check is not None:
        at = [f"{lim.name} at {corner}" for lim, corner in zip(check.limits, check.corners)
              if float(lim.normalised) > model.FEASIBILITY_TOLERANCE]
        if at:
            sizes = ", ".join(f"{name} ±{dev * mm:.3g} mm" for name, dev in check.deviations)
            out.append(f"at the corners of its tolerances ({spec.tolerances.label()}: {sizes}) it breaks "
                       + ", ".join(at) + "; a finer tolerances.class, or tolerances.section and tolerances.feature "
                       "of your own, leave the design more room (the figures below are at those corners)")
    a = best.analysis
    sv = spec.sigma_v
    where, larger, shape = _section_room(spec, best.design.geometry)   # for the stress, strain and deflection advice
    for name in ("gauge_face", "gauge_face_side"):
        if name in violated:   # the gauge overhangs its face: no reading of this design is the model's
            v, wide = violated[name], spec.gauge.width * mm
            out.append(f"{name}: the gauge's backing, {wide:.4g} mm wide (gauge.width), overhangs the "
                       f"{float(v.value) * mm:.4g} mm face it is bonded to {where}; choose a narrower gauge or "
                       + (f"enlarge {larger} to at least {wide:.4g} mm" if larger else
                          f"a section at least {wide:.4g} mm across"))
    if "pocket_side_wall" in violated:   # a slot leaving its bar's sides thinner than the least wall
        out.append(_thin_side_walls(spec, best.design.geometry, violated["pocket_side_wall"]))
    if "flat_chord" in violated:   # a flat on a round bar or tube narrower than its pocket
        out.append(_narrow_flat(spec, best.design.geometry, violated["flat_chord"], where, larger))
    if "force_error" in violated or "position_error" in violated:
        e = best.error_ratio
        targets = {lim.name: lim for lim in best.limits if lim.name in model.TARGET_LIMITS}
        # how far the errors must fall, and the room the targets keep for the 3-D strain
        # (docs/model.md §4): met at e = 1/(1 + u)
        need = max(float(lim.value) / float(lim.limit) for lim in targets.values())
        room = float(targets["force_error"].part_limit) / float(targets["force_error"].limit)
        binding = [lim.name for lim in best.limits if lim.record()["active"]
                   and lim.name not in model.TARGET_LIMITS]
        quiet = _quieter(spec, a, targets, need)
        others = [name for name in violated if name not in model.TARGET_LIMITS]
        ways = ([f"electronics noise of at most {_down(quiet * 1e3, 3)} mV at the output (now {sv * 1e3:.3g} mV)"]
                if quiet is not None else [])
        if spec.load.force_min * need <= spec.load.force_max and not a.budget:
            # (with an error budget the other terms do not fall as 1/F_min: no least force is named)
            ways.append(f"load.force[0] of at least {_up(spec.load.force_min * need)} N (now "
                        f"{spec.load.force_min:.4g} N)")
        ways.append(f"targets of force_error >= {float(a.force_error) * room * 100:.3g} % and position_error >= "
                    f"{float(a.position_error) * room * mm:.3g} mm")
        out.append(f"the accuracy targets are out of reach: the best error ratio is {e:.3g} (1 = on target"
                   + (f"; met at {1 / room:.3g}, which keeps room for the model's gauge-strain uncertainty"
                      if room > 1 + 1e-12 else "") + ")"
                   + (f" with {', '.join(binding)} binding" if binding else "")
                   + "; they would be met with " + ", or ".join(ways)
                   + (f"; any of these meets the targets only: {', '.join(others)} "
                      f"{'stays' if len(others) == 1 else 'stay'} broken" if others else "")
                   + ("; no electronics noise alone would meet them (the error budget's other terms exceed them at "
                      "some load)" if quiet is None else "")
                   + _largest_term(spec, a))
        if spec.limits.max_deflection is not None and "deflection" in binding:
            out.append(f"the deflection limit binds: limits.max_deflection = {spec.limits.max_deflection * mm:.4g} mm; "
                       "a larger allowed deflection gives a more sensitive beam")
    # the section below its largest, with the signal broken too: the closest design's least worst
    # violation balances them (a larger section lowers the stress, the strain and the signal alike)
    held = (", which the signal holds there: a larger section lowers {} and the signal (min_signal_snr) alike"
            if "min_signal_snr" in violated and where.startswith("at the closest") else "")
    strength = [v for v in best.violations if v.name in STRENGTH_LIMITS]
    if strength:   # the worst of them (each at its worst, nominal or at a corner)
        v = max(strength, key=lambda v: float(v.value) / float(v.limit))
        ratio = float(v.value) / float(v.limit)
        rating = _rating(v)
        room = ("" if rating is None else
                f" ({rating / 1e6:.4g} MPa less the room kept for the model's stress uncertainty)")
        out.append(f"{v.name}: {float(v.value) / 1e6:.4g} MPa exceeds the allowable {float(v.limit) / 1e6:.4g} MPa"
                   f"{room} {where}{held.format('the stress')}; lower load.force[1] to "
                   f"{_down(spec.load.force_max / ratio)} N, "
                   + (f"enlarge {larger}, " if larger else "")
                   + "choose a stronger material or a lower safety factor")
    if "gauge_strain" in violated:
        v = violated["gauge_strain"]
        rating, limit = _rating(v), f"{float(v.limit) * 1e6:.0f} µε"
        room = (f"the gauge's {limit}" if rating is None else f"{limit}, the gauge's {rating * 1e6:.0f} µε less the "
                "room kept for the model's gauge-strain uncertainty,")
        out.append(f"gauge_strain: {float(v.value) * 1e6:.0f} µε exceeds {room} {where}{held.format('the strain')}; "
                   "lower load.force[1] to "
                   f"{_down(spec.load.force_max * float(v.limit) / float(v.value))} N"
                   + (f", enlarge {larger}" if larger else "") + " or choose a stiffer material")
    if "min_signal_snr" in violated:
        v = violated["min_signal_snr"]
        if not float(v.value) > 0:  # a station at or past the nearest load: no moment there for that load
            out.append(f"min_signal_snr: a bridge gets no signal from a load at load.position[0] = "
                       f"{spec.load.position_min * mm:.4g} mm: even the best design found cannot place its "
                       f"{len(best.design.geometry.stations)} stations before it; use fewer stations or a load "
                       "range farther from the clamp")
        else:
            ratio = float(v.limit) / float(v.value)
            snr, least = _apart(float(v.value), float(v.limit))
            noise, now = _apart(sv / ratio * 1e3, sv * 1e3, math.floor)
            force, least_now = _apart(spec.load.force_min * ratio, spec.load.force_min, math.ceil, 4)
            out.append(f"min_signal_snr: the smallest signal is {snr} noise levels, below {least}; "
                       f"lower the noise to {noise} mV (now {now} mV)"
                       + (f" or raise load.force[0] to {force} N (now {least_now} N)"
                          if spec.load.force_min * ratio <= spec.load.force_max else ""))
    # room by the gauge gaps alone, whatever the section, but not by this design's own rules (the
    # webs between pockets, the fits' least pocket length): how far its stations reach, past what
    clearances = (("load_clearance", "their features and limits.load_clearance", "load.position[0] =",
                   "a load region", lambda: spec.load.position_min),
                  ("groove_clearance", "their features, limits.load_clearance and half a groove's width",
                   "the load groove at", "cad.groove_positions", lambda: min(grooves.positions(spec))))
    duty = any(name in model.DUTY_LIMITS for name in violated)
    # a larger section lowers the stress and the strain, and with them the signal: it helps the
    # duty's limits but the targets (the errors grow as the strain falls)
    bearing = any(name in model.DUTY_LIMITS and name not in model.TARGET_LIMITS for name in violated)
    for name, reach, past, move, edge in clearances:
        if name in violated:
            v = violated[name]
            # the limit is the room left before the edge, at least the clearance: the stations reach
            # the edge less that room, plus the clearance (and half a groove)
            at = edge()
            reached = at - float(v.value) + float(v.limit)
            out.append(f"{name}: the closest design's stations, {reach} reach {reached * mm:.4g} mm, past "
                       f"{past} {at * mm:.4g} mm; {move} from {reached * mm:.4g} mm out, fewer "
                       "stations, a smaller gauge or smaller margins would leave them room")
        elif duty and where.startswith("at the closest") and _binds(best, name):
            # the closest design meets the geometry's rules (``search.closest``), its section below
            # the largest allowed: the room before the load region, which the gaps between its
            # features (a size apart, in proportion) fill, holds it
            found = (f" (from load.position[0] = {farther[0] * mm:.4g} mm, a {farther[1].design.label()} "
                     f"{_shape(farther[1].design.geometry)} meets every limit)"
                     if farther is not None and name == "load_clearance" else "")
            head = f"{name} binds: the closest design's stations, {reach} reach {past} {edge() * mm:.4g} mm"
            ways = f"{move} farther out{found}, fewer stations, a smaller gauge or smaller margins"
            out.append(f"{head}, and the gaps between its features grow with the section: that holds it at {shape}; "
                       f"{ways} would allow a larger one" if bearing else
                       # only the targets missed: the bridges farther apart tell force and position better
                       # (sigma_F falls as 1 / (d_N - d_1) on two bridges, sigma_x about so)
                       f"{head}; {ways} would let the stations lie farther apart, which lowers both errors")
    if "deflection" in violated:
        v = violated["deflection"]
        out.append(f"deflection: {float(v.value) * mm:.4g} mm exceeds limits.max_deflection = "
                   f"{float(v.limit) * mm:.4g} mm {where}; allow at least {float(v.value) * mm:.4g} mm"
                   + (f", or enlarge {larger}" if larger else "")
                   + _looser(looser.get("deflection"), "limits.max_deflection", _up, mm, "mm"))
    if "domain_lp_grid_max" in violated:
        out.append(_long_pockets(spec, violated["domain_lp_grid_max"], best.design.geometry))
    elif bearing and _binds(best, "domain_lp_grid_max"):
        # the closest design meets the geometry's rules (``search.closest``): the pocket study's
        # longest pockets may be what holds its section (and so its stress and strain) back
        held = next(lim for lim in best.limits if lim.name == "domain_lp_grid_max")
        out.append(_long_pockets(spec, held, best.design.geometry, binding=True))
    hull = [name for name in violated if name.startswith(f"domain_{domain.NOTCH_HULL}_")]
    if hull:
        out.append(_sharp_pockets(best.design.geometry, hull))
    out += [_outside_study(spec, best.design.geometry, violated[name]) for name in violated
            if name.startswith("domain_") and name != "domain_lp_grid_max" and name not in hull]
    if "natural_frequency" in violated:
        v = violated["natural_frequency"]
        out.append(f"natural_frequency: {float(v.value):.4g} Hz is below limits.min_frequency = "
                   f"{float(v.limit):.4g} Hz; lower it to {float(v.value):.4g} Hz or shorten the beam"
                   + _looser(looser.get("natural_frequency"), "limits.min_frequency", _down, 1.0, "Hz"))
    if violated and all(name in LOAD_LIMITS for name in violated) and len(violated) > 1:
        # each grows as the largest force: at F_max / (1 + the worst violation) this design meets them all
        ratio = max(float(v.value) / float(v.limit) for v in best.violations)
        out.append(f"every limit it breaks grows with the largest force: at load.force[1] = "
                   f"{_down(spec.load.force_max / ratio)} N (now {spec.load.force_max:.4g} N) this design meets "
                   "every limit")
    if plain is not None:
        d = plain.design
        sizes = _shape(d.geometry) if d.stock is None else f"({d.stock.label})"
        bare = "not recessed in pockets" if spec.search.feature == "pocket" else "without holes"
        out.append(f"with search.feature: none (the gauges bonded on the bar's own faces, {bare}) "
                   f"a {d.label()} {sizes} meets every limit")
    return out


def _narrow_flat(spec, g, v, where: str, larger: str) -> str:
    """The advice for a flat narrower than its pocket: the least bar that holds one (``_least_bar``)
    when the section is below it; else the depth that would, and a tube's wall that does not
    leave it (``flat_wall``)."""
    mm, step, width, D = 1e3, spec.cad.depth_step, float(v.limit), float(g.diameter)
    head = (f"flat_chord: the closest design's flat is {float(v.value) * mm:.4g} mm wide, narrower than its "
            f"{width * mm:.4g} mm pocket (the gauge's backing with limits.pocket_margin, or cad.corner_radius, "
            f"round it) {where}; ")
    least = _least_bar(spec, width)
    if D < least - 1e-9:
        return (head + f"a flat that wide, on its depth's grid and within limits.max_pocket_fraction = "
                f"{spec.limits.max_pocket_fraction:g}, takes a bar of at least {least * mm:.4g} mm; choose a narrower "
                "gauge or smaller margins" + (f", or enlarge {larger}" if larger else ""))
    deep = math.ceil(flat_depth(D / 2, width) / step - 1e-9) * step
    text = head + f"on its Ø{D * mm:.4g} mm section a flat {deep * mm:.4g} mm deep holds it"
    if g.section == "tube" and deep > float(g.wall) - spec.limits.min_wall:
        text += (f", which its {float(g.wall) * mm:.4g} mm wall less limits.min_wall = {spec.limits.min_wall * mm:.4g} "
                 "mm does not leave (flat_wall): a thicker wall")
    return text + ", a narrower gauge or smaller margins would"


def _least_bar(spec, width: float) -> float:
    """The least diameter (m, up to the 0.01 mm grid) on which a flat is ``width`` wide: a flat
    ``p`` deep is ``2 sqrt(p (D - p))`` wide, so ``D >= p + width^2 / (4 p)``, and ``p <= f D``
    (``limits.max_pocket_fraction``), with ``p`` a multiple of ``cad.depth_step`` no shallower
    than the least depth; the deeper flats need more diameter beyond ``p = width / 2``."""
    step, f = spec.cad.depth_step, spec.limits.max_pocket_fraction
    first = math.ceil(shallowest_pocket(spec) / step - 1e-9)
    last = max(first, math.ceil(width / 2 / step))
    least = min(max(p / f, p + width * width / (4 * p)) for p in (k * step for k in range(first, last + 1)))
    return math.ceil(least / ROUNDING - 1e-9) * ROUNDING


def _rating(v) -> float | None:
    """The rating a limit is kept inside of (``Limit.rating``: the gauge's strain, the material's
    allowable stress, less the room for the model's own uncertainty; docs/model.md §4, §7), or None
    for a limit at its rating."""
    if v.rating is None or abs(float(v.rating) - float(v.limit)) <= 1e-9 * abs(float(v.rating)):
        return None
    return float(v.rating)


def _looser(found, key: str, rounded, unit_scale: float, unit: str) -> str:
    """``; with KEY = level a <design> meets every limit`` for a ``remedies.looser`` answer (the level
    rounded the looser way, ``rounded``, so that the design meets it too), '' without one."""
    if found is None:
        return ""
    level, ev = found
    return (f"; with {key} = {rounded(level * unit_scale, 3)} {unit} a {ev.design.label()} "
            f"{_shape(ev.design.geometry)} meets every limit")


def _binds(best: Evaluation, name: str) -> bool:
    """Whether the limit ``name`` binds ``best`` at its nominal sizes (within ACTIVE_TOLERANCE)."""
    return any(lim.name == name and lim.record()["active"] for lim in best.limits)


def _down(value: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits, rounded down: a largest force or noise the advice
    names must not exceed the one it was worked out for."""
    return _rounded(value, digits, math.floor)


def _up(value: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits, rounded up (a least force the advice names)."""
    return _rounded(value, digits, math.ceil)


def _rounded(value: float, digits: int, way) -> str:
    text = f"{value:.{digits}g}"
    if (float(text) <= value) if way is math.floor else (float(text) >= value):
        return text
    step = 10.0 ** (math.floor(math.log10(abs(value))) - digits + 1)
    return f"{way(value / step) * step:.{digits}g}"


def _section_room(spec, g) -> tuple[str, str, str]:
    """Where the closest design's section stands against the largest limits.width and limits.height
    allow, in words, the keys to enlarge (those whose largest it reaches, within the 0.01 mm
    grid; none when the section is below every largest), and the section's sizes (``_shape``)."""
    mm, lim, shape = 1e3, spec.limits, _shape(g)
    if g.section == "rectangle" and g.axes == 1:
        sizes = {"limits.width": (float(g.width), lim.width[1]), "limits.height": (float(g.height), lim.height[1])}
    else:   # one size within both ranges: a square's side, a diameter
        keys, top = _size_bound(spec, g)
        sizes = {key: (float(g.size), top) for key in keys}
    at = [key for key, (size, most) in sizes.items() if size >= most - ROUNDING - 1e-9]
    if len(at) == len(sizes):
        return "even at the largest section allowed", " and ".join(at), shape
    below = ", ".join(f"{key} allows up to {most * mm:.4g} mm" for key, (size, most) in sizes.items() if key not in at)
    return f"at the closest design's {shape} section ({below})", " and ".join(at), shape


def _size_bound(spec, g) -> tuple[tuple[str, ...], float]:
    """The keys that bound the section's size in the load direction (``g.size``) and its largest
    allowed: a single-axis rectangle's height; else one size within both ranges (a square's side, a
    diameter), bounded by the smaller of the two largest."""
    lim = spec.limits
    if g.section == "rectangle" and g.axes == 1:
        return ("limits.height",), lim.height[1]
    top = min(lim.width[1], lim.height[1])
    return tuple(key for key, most in (("limits.width", lim.width[1]), ("limits.height", lim.height[1]))
                 if most <= top), top


def _shape(g) -> str:
    """A section's sizes in words: ``b × h mm``, ``a mm square`` (a biaxial square), ``ØD mm``."""
    mm = 1e3
    if g.section == "rectangle":
        return f"{float(g.width) * mm:.4g} × {float(g.height) * mm:.4g} mm" if g.axes == 1 else \
            f"{float(g.width) * mm:.4g} mm square"
    return f"Ø{float(g.diameter) * mm:.4g} mm"


def _apart(a: float, b: float, way=None, least: int = 3) -> tuple[str, str]:
    """``a`` and ``b`` written with as few significant digits (``least`` at least) as tell them apart; ``a``
    rounded ``way`` (``math.floor``, ``math.ceil``) when given: a largest noise or a least force
    named must not pass the one it was worked out for."""
    for digits in range(least, 8):
        first = f"{a:.{digits}g}" if way is None else _rounded(a, digits, way)
        if first != f"{b:.{digits}g}":
            break
    return first, f"{b:.{digits}g}"


def _quieter(spec, a, targets: dict, need: float) -> float | None:
    """The noise at the amplifier output (V) at which ``a``'s design meets the accuracy targets
    (``targets``: their limits), None when no noise would. Without an error budget the errors are
    in proportion to the noise: now's over ``need``. With one, only its noise and calibration-fit
    terms are (docs/model.md §13): at each of the budget's loads, u² = s² N + O must stay within
    the target's square, N the variance of those terms and O of the others, for the scale s."""
    if not a.budget:
        return spec.sigma_v / need
    limits = {"force_var": float(targets["force_error"].limit), "position_var": float(targets["position_error"].limit)}
    scale = math.inf
    for _, _, terms in a.budget:
        for kind, limit in limits.items():
            noisy = sum(float(getattr(t, kind)) for t in terms if t.name in NOISE_TERMS)
            rest = sum(float(getattr(t, kind)) for t in terms if t.name not in NOISE_TERMS)
            if rest >= limit * limit:
                return None
            if noisy > 0:
                scale = min(scale, (limit * limit - rest) / noisy)
    return spec.sigma_v * math.sqrt(scale) if math.isfinite(scale) else None


def _largest_term(spec, a) -> str:
    """With an error budget (``environment``), its largest term at the worst load (F_min, x_max)
    and what removes it where the spec can: '' without a budget."""
    if not a.budget:
        return ""
    worst = max(a.budget, key=lambda point: (-point[0], point[1]))[2]   # F_min, x_max
    total = sum(float(t.force_var) for t in worst)
    top = max(worst, key=lambda t: float(t.force_var))
    if not total > 0:
        return ""
    out = f"; the error budget's largest term at F_min, x_max is {top.name} ({float(top.force_var) / total:.0%} " \
          "of the force error's variance)"
    if top.name.startswith("zero drift") and spec.environment is not None and not spec.environment.tare:
        out += ": environment.tare (offsets measured again, unloaded, at the operating temperature) removes it"
    return out


def _thin_side_walls(spec, g, v) -> str:
    """A slot as wide as the gauge and its margins leaves the closest design's bar thinner sides than
    limits.min_wall: the least bar width that keeps them, against the widest limits.width allows."""
    mm, least_wall, top = 1e3, spec.limits.min_wall, spec.limits.width[1]
    need = math.ceil((float(g.pocket_width) + 2 * least_wall) / ROUNDING - 1e-9) * ROUNDING
    return (f"pocket_side_wall: the slot, {float(g.pocket_width) * mm:.4g} mm wide (the gauge's width and "
            "limits.pocket_margin, or cad.corner_radius, where larger, on each side), leaves walls of "
            f"{float(v.value) * mm:.4g} mm on the closest design's {float(g.width) * mm:.4g} mm wide bar, under "
            f"limits.min_wall = {least_wall * mm:.4g} mm; a bar at least {need * mm:.4g} mm wide"
            + (f", which limits.width (up to {top * mm:.4g} mm) does not allow" if need > top + 1e-12 else "")
            + ", a narrower gauge, a smaller pocket_margin or limits.min_wall, or search.feature: none would keep "
            "them")


def _not_a_beam(spec, key: str, reason: str) -> str:
    """Why the least infeasible design is no beam at all (``model.unbuildable``'s rule) and, for a
    slot wider than the widest bar allowed, what would let one fit."""
    mm = 1e3
    out = (f"design.{key}: {reason}: no design the search found is a beam with this feature, so the "
           "closest one's figures are not a sensor's")
    if key == "feature.width":
        out += (f"; a slot is the gauge's width and limits.pocket_margin (or cad.corner_radius, where larger) on "
                f"each side, "
                f"{spec.pocket_size()[1] * mm:.4g} mm, and limits.width allows a bar at most "
                f"{spec.limits.width[1] * mm:.4g} mm wide: a narrower gauge, a smaller pocket_margin, a wider "
                "limits.width, or search.feature: none would make one")
    return out


def _long_pockets(spec, limit, g, binding: bool = False) -> str:
    """Why the pockets are more gauge grids long than the pocket study's, and what would shorten
    them: the gauge's backing and margins (the spec's rule), or the length the corrections need on
    a large section (their domain's least ``length_ratio`` times its size). ``binding``: they are
    as long as the study's longest, and so hold the section at its size."""
    from designer.model import corrections
    from designer.model.domain import domain_box, lp_grid_top

    mm, most = 1e3, lp_grid_top(corrections.family(g))
    rule, grid = spec.pocket_size()[0], g.grid_length
    if binding:
        least = domain_box(corrections.family(g), corrections.load()).get("length_ratio", (0.0,))[0]
        return (f"domain_lp_grid_max binds: its pockets are {float(limit.value):.3g} gauge grids long "
                f"({g.pocket_length * mm:.4g} mm over the gauge's {grid * mm:.3g} mm grid), the longest the 3-D "
                f"corrections were studied at (docs/model.md §7), and on this section they need a pocket at least "
                f"{least:.2g} times its size long (docs/model.md §1): that holds the section at its size; a gauge "
                "with a longer grid would allow a larger one")
    head = (f"domain_lp_grid_max: its pockets would be {float(limit.value):.3g} gauge grids long "
            f"({g.pocket_length * mm:.4g} mm over the gauge's {grid * mm:.3g} mm grid), where the 3-D corrections "
            f"were studied up to {most:g} (docs/model.md §7)")
    if rule > most * grid:
        margin = max(0.0, (most * grid - spec.gauge.length) / 2)
        return (head + f"; the gauge's {spec.gauge.length * mm:.3g} mm backing and limits.pocket_margin (or "
                f"cad.corner_radius, where larger) alone make "
                f"them {rule * mm:.4g} mm: a pocket_margin of at most {margin * mm:.3g} mm, a gauge with a longer "
                "grid for its backing, or search.feature: none (or hole on a rectangle) would be inside")
    least = domain_box(corrections.family(g), corrections.load()).get("length_ratio", (0.0,))[0]
    return (head + f"; the corrections need a pocket at least {least:.2g} times the section's size long on this "
            f"section (docs/model.md §1): a gauge with a grid of at least {g.pocket_length * mm / most:.3g} mm, "
            "search.feature: none (or hole on a rectangle), or a smaller section would be inside")


def _outside_study(spec, g, v) -> str:
    """A ``domain_<parameter>_min`` or ``_max`` limit that the closest design breaks: outside the box of
    its family's 3-D study its corrections are not trusted (docs/model.md §7). A gauge grid too long
    for the section (``grid_ratio``) is told the section size and the grid length that would do."""
    mm, name = 1e3, v.name
    parameter, side = name[len("domain_"):].rsplit("_", 1)
    scale, unit = (mm, " mm") if v.unit == "m" else (1.0, "")
    value, bound = (f"{x}{unit}" for x in _apart(float(v.value) * scale, float(v.limit) * scale))
    # (a bound on a station's distance from the clamp is a length: the ratio times the section's size)
    size = "the height" if g.section == "rectangle" and g.axes == 1 else \
        ("the side" if g.section == "rectangle" else "the diameter")
    meaning = PARAMETERS.get(parameter, "").format(size=size, depth="the wall" if g.section == "tube" else size)
    what = (f"the closest design's {parameter}" + (f" ({meaning})" if meaning else "") + " is" if v.unit != "m"
            else "at the closest design it is")
    text = (f"{name}: {what} {value}, {'above' if side == 'max' else 'below'} {bound}, the "
            f"{'largest' if side == 'max' else 'least'} of the 3-D study its {g.section} + {g.feature} corrections "
            "were fitted on (docs/model.md §7); outside it the model is not trusted")
    if parameter != "grid_ratio" or side != "max":
        return text
    # grid_ratio = grid_length / size: a larger section or a shorter grid brings it in
    size, ratio = float(g.size), float(v.limit)
    keys, top = _size_bound(spec, g)
    word = "high" if g.section == "rectangle" and g.axes == 1 else "across"
    need = math.ceil(g.grid_length / ratio / ROUNDING - 1e-9) * ROUNDING
    shortest = math.floor(ratio * size / ROUNDING * 10 + 1e-9) * ROUNDING / 10
    return (f"{text}: its gauge's {g.grid_length * mm:.4g} mm grid needs a section at least {need * mm:.4g} mm {word}"
            + (f", which {' and '.join(keys)} (up to {top * mm:.4g} mm) does not allow" if need > top + 1e-12 else "")
            + f", or on {size * mm:.4g} mm a gauge whose grid is at most {shortest * mm:.4g} mm long")


def _sharp_pockets(g, names) -> str:
    """The pockets sharper for their depth than the study's (``names``: the ``domain_notch_hull_<k>_max``
    they break) and the least corner radius inside: sqrt(p/r') = top at r' = r (sqrt(p/r)/top)^2,
    ``top`` the hull's notch at their depth (``domain.notch_top``)."""
    mm = 1e3
    params = corrections.parameters(g)
    vertices = corrections.load().fit(corrections.family(g), "stress").notch_top
    top = domain.notch_top(float(params["depth_ratio"]), vertices)
    head = (f"{', '.join(names)}: its pockets' floor radius R{g.floor_radius * mm:.3g} mm is sharper for their "
            f"{g.depth * mm:.3g} mm depth than the 3-D study's were (docs/model.md §7)")
    if top <= 0:    # far shallower than the study's shallowest pocket: no radius is inside
        return f"{head}; no corner radius is inside at that depth: the pockets are shallower than any studied"
    least = g.floor_radius * (float(params["notch_ratio"]) / top) ** 2
    return f"{head}; cad.corner_radius of at least {least * mm:.3g} mm would be inside"
