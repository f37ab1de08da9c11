"""Why a spec is infeasible, in the spec's own terms: the limits in conflict and what would resolve them."""

from __future__ import annotations

from designer import model
from designer.model import corrections, domain, grooves
from designer.result.evaluation import ROUNDING, Evaluation


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


def diagnose(spec, best: Evaluation, candidates) -> list[str]:
    """Name the limits in conflict and what would resolve them, in the spec's own terms."""
    mm = 1e3
    out = []
    if crowded := no_room(spec):
        out.append(crowded)
    violated = {v.name: v for v in best.violations}
    label = f"{best.design.label()} (the least infeasible design found)"
    head = f"no design meets every limit; closest: {label}, violating " + ", ".join(violated) if violated else \
        f"no design meets every limit; closest: {label}"
    out.insert(0, head)
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
    where, larger = _section_room(spec, best.design.geometry)   # for the stress, strain and deflection advice
    if "force_error" in violated or "position_error" in violated:
        e = best.error_ratio
        targets = {lim.name: lim for lim in best.limits if lim.name in ("force_error", "position_error")}
        # how far the errors must fall, and the room the targets keep for the 3-D strain
        # (docs/model.md §4): met at e = 1/(1 + u)
        need = max(float(lim.value) / float(lim.limit) for lim in targets.values())
        room = float(targets["force_error"].part_limit) / float(targets["force_error"].limit)
        binding = [lim.name for lim in best.limits if lim.record()["active"]
                   and lim.name not in ("force_error", "position_error")]
        out.append(f"the accuracy targets are out of reach: the best error ratio is {e:.3g} (1 = on target"
                   + (f"; met at {1 / room:.3g}, which keeps room for the model's gauge-strain uncertainty"
                      if room > 1 + 1e-12 else "") + ")"
                   + (f" with {', '.join(binding)} binding" if binding else "")
                   + f"; they would be met with electronics noise of at most {sv / need * 1e3:.3g} mV at the output "
                   f"(now {sv * 1e3:.3g} mV), "
                   + (f"or load.force[0] of at least {spec.load.force_min * need:.4g} N (now {spec.load.force_min:.4g} "
                      f"N), " if spec.load.force_min * need <= spec.load.force_max else "")
                   + f"or targets of force_error >= {float(a.force_error) * room * 100:.3g} % and position_error >= "
                   f"{float(a.position_error) * room * mm:.3g} mm"
                   + _largest_term(spec, a))
        if spec.limits.max_deflection is not None and "deflection" in binding:
            out.append(f"the deflection limit binds: limits.max_deflection = {spec.limits.max_deflection * mm:.4g} mm; "
                       "a larger allowed deflection gives a more sensitive beam")
    for name in ("stress_root", "stress_feature"):
        if name in violated:
            v = violated[name]
            ratio = float(v.value) / float(v.limit)
            out.append(f"{name}: {float(v.value) / 1e6:.4g} MPa exceeds the allowable {float(v.limit) / 1e6:.4g} MPa "
                       f"{where}; lower load.force[1] to {spec.load.force_max / ratio:.4g} N, "
                       + (f"enlarge {larger}, " if larger else "")
                       + "choose a stronger material or a lower safety factor")
            break
    if "gauge_strain" in violated:
        v = violated["gauge_strain"]
        out.append(f"gauge_strain: {float(v.value) * 1e6:.0f} µε exceeds the gauge's {float(v.limit) * 1e6:.0f} µε "
                   f"{where}; lower load.force[1] to {spec.load.force_max * float(v.limit) / float(v.value):.4g} N"
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
            noise, now = _apart(sv / ratio * 1e3, sv * 1e3)
            out.append(f"min_signal_snr: the smallest signal is {snr} noise levels, below {least}; "
                       f"lower the noise to {noise} mV (now {now} mV)"
                       + (f" or raise load.force[0] to {spec.load.force_min * ratio:.4g} N"
                          if spec.load.force_min * ratio <= spec.load.force_max else ""))
    # room by the gauge gaps alone, whatever the section, but not by this design's own rules (the
    # webs between pockets, the fits' least pocket length): how far its stations reach, past what
    clearances = (("load_clearance", "their features and limits.load_clearance", "load.position[0] =",
                   "a load region", lambda: spec.load.position_min),
                  ("groove_clearance", "their features, limits.load_clearance and half a groove's width",
                   "the load groove at", "cad.groove_positions", lambda: min(grooves.positions(spec))))
    for name, reach, past, move, edge in clearances:
        if name in violated and not no_room(spec):
            v = violated[name]
            # the limit is the room left before the edge, at least the clearance: the stations reach
            # the edge less that room, plus the clearance (and half a groove)
            where = edge()
            reached = where - float(v.value) + float(v.limit)
            out.append(f"{name}: the closest design's stations, {reach} reach {reached * mm:.4g} mm, past "
                       f"{past} {where * mm:.4g} mm; {move} from {reached * mm:.4g} mm out, fewer "
                       "stations, a smaller gauge or smaller margins would leave them room")
    if "deflection" in violated:
        v = violated["deflection"]
        out.append(f"deflection: {float(v.value) * mm:.4g} mm exceeds limits.max_deflection = "
                   f"{float(v.limit) * mm:.4g} mm {where}; allow at least {float(v.value) * mm:.4g} mm"
                   + (f", or enlarge {larger}" if larger else ""))
    if "domain_lp_grid_max" in violated:
        out.append(_long_pockets(spec, violated["domain_lp_grid_max"], best.design.geometry))
    hull = [name for name in violated if name.startswith(f"domain_{domain.NOTCH_HULL}_")]
    if hull:
        out.append(_sharp_pockets(best.design.geometry, hull))
    if "natural_frequency" in violated:
        v = violated["natural_frequency"]
        out.append(f"natural_frequency: {float(v.value):.4g} Hz is below limits.min_frequency = {float(v.limit):.4g} Hz; "
                   f"lower it to {float(v.value):.4g} Hz or shorten the beam")
    return out


def _section_room(spec, g) -> tuple[str, str]:
    """Where the closest design's section stands against the largest limits.width and limits.height
    allow, in words, and the keys to enlarge: those whose largest it reaches (within the 0.01 mm
    grid); none when the section is below every largest."""
    mm, lim = 1e3, spec.limits
    if g.section == "rectangle" and g.axes == 1:
        sizes = {"limits.width": (float(g.width), lim.width[1]), "limits.height": (float(g.height), lim.height[1])}
        shape = f"{float(g.width) * mm:.4g} × {float(g.height) * mm:.4g} mm"
    else:   # one size within both ranges: a square's side, a diameter
        top = min(lim.width[1], lim.height[1])
        size = float(g.width if g.section == "rectangle" else g.diameter)
        sizes = {key: (size, top) for key, most in (("limits.width", lim.width[1]), ("limits.height", lim.height[1]))
                 if most <= top}
        shape = f"{size * mm:.4g} mm square" if g.section == "rectangle" else f"Ø{size * mm:.4g} mm"
    at = [key for key, (size, most) in sizes.items() if size >= most - ROUNDING - 1e-9]
    if len(at) == len(sizes):
        return "even at the largest section allowed", " and ".join(at)
    below = ", ".join(f"{key} allows up to {most * mm:.4g} mm" for key, (size, most) in sizes.items() if key not in at)
    return f"at the closest design's {shape} section ({below})", " and ".join(at)


def _apart(a: float, b: float) -> tuple[str, str]:
    """``a`` and ``b`` written with as few significant digits (3 at least) as tell them apart."""
    for digits in range(3, 8):
        if f"{a:.{digits}g}" != f"{b:.{digits}g}":
            break
    return f"{a:.{digits}g}", f"{b:.{digits}g}"


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


def _long_pockets(spec, limit, g) -> str:
    """Why the pockets are more gauge grids long than the pocket study's, and what would shorten
    them: the gauge's backing and margins (the spec's rule), or the length the corrections need on
    a large section (their domain's least ``length_ratio`` times its size)."""
    from designer.model import corrections
    from designer.model.domain import domain_box, lp_grid_top

    mm, most = 1e3, lp_grid_top(corrections.family(g))
    rule, grid = spec.pocket_size()[0], g.grid_length
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
