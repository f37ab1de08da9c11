"""Human-readable outputs of a design.json record: a Markdown report and a terminal table."""

from __future__ import annotations

import math

# How each limit's unit is shown: (SI unit) -> (label, factor)
_DISPLAY = {"V": ("mV", 1e3), "Pa": ("MPa", 1e-6), "m": ("mm", 1e3), "strain": ("µε", 1e6), "Hz": ("Hz", 1.0), "": ("", 1.0)}
_PERCENT_LIMITS = {"force_error"}


def display(value: float, unit: str, name: str = "") -> str:
    if name in _PERCENT_LIMITS:
        return f"{value * 100:.3g} %"
    label, factor = _DISPLAY.get(unit, (unit, 1.0))
    return f"{value * factor:.4g} {label}".strip()


def percent(fraction: float) -> str:
    """A signed percentage that never shows -0.00 %."""
    return f"{0.0 if abs(fraction) < 5e-5 else fraction:+.2%}"


def section_text(section: dict) -> str:
    mm = 1e3
    if section["kind"] == "rectangle":
        return f"rectangle {section['width'] * mm:.2f} × {section['height'] * mm:.2f} mm"
    if section["kind"] == "round":
        return f"round Ø{section['diameter'] * mm:.2f} mm"
    return f"tube Ø{section['diameter'] * mm:.2f} × {section['wall'] * mm:.2f} mm wall"


def feature_text(feature: dict, section: dict | None = None) -> str:
    """The feature as the drawing names it: a pocket (a slot) on a rectangle, flats on a round
    bar or tube (cut across the bar; their width at the surface is the chord the depth leaves)."""
    mm = 1e3
    if feature["kind"] == "pocket" and section is not None and section["kind"] in ("round", "tube"):
        from designer.model.sections import flat_half_chord

        depth = feature["depth"]
        chord = 2 * flat_half_chord(section["diameter"] / 2, depth)
        return (f"flat {feature['length'] * mm:.2f} mm long, {depth * mm:.2f} mm deep "
                f"({chord * mm:.2f} mm wide at the surface)")
    if feature["kind"] == "pocket":
        return (f"pocket {feature['length'] * mm:.2f} × {feature['width'] * mm:.2f} mm, "
                f"{feature['depth'] * mm:.2f} mm deep")
    if feature["kind"] == "hole":
        return f"through-hole Ø{feature['diameter'] * mm:.2f} mm"
    return "none (gauges on the plain surface)"


def summary_rows(record: dict) -> list[tuple[str, str]]:
    d, p = record["design"], record["predicted"]
    mm = 1e3
    rows = [
        ("status", record["status"]),
        ("material", d["material"]),
        ("section", section_text(d["section"])),
        ("feature", feature_text(d["feature"], d["section"])),
        ("free length", f"{d['length'] * mm:.2f} mm"),
        ("gauge stations", ", ".join(f"{x * mm:.2f}" for x in d["stations"]) + " mm from the clamp"),
        ("bridges", f"{d['bridge']}, {d['axes']} " + ("axes" if d["axes"] == 2 else "axis")),
        *error_rows(record),
        ("free-end deflection", f"{p['deflection'] * mm:.3g} mm ({p['deflection_ratio']:.2%} of the length)"),
        *stress_rows(record),
        ("gauge strain at F_max", ", ".join(f"{e * 1e6:.0f}" for e in p["gauge_strain"]) + " µε"),
        ("smallest signal / noise", f"{p['min_signal_snr']:.3g}"),
        ("sensitivity k", f"{p['sensitivity'][0] * 1e3:.4g} mV/(N·m)"),
        ("mass (free length)", f"{p['mass'] * 1e3:.4g} g"),
        ("first natural frequency", f"{p['natural_frequency']:.4g} Hz"),
    ]
    if p.get("front_end"):
        rows += front_end_rows(p["front_end"])
    longer = longer_pocket_text(record)
    if longer:
        rows[3] = ("feature", f"{rows[3][1]}; {longer}")
    if d["feature"].get("tool"):
        rows.insert(4, ("end mill", tool_text(d["feature"]["tool"], d["section"])))
    if grooves := groove_text(record):
        rows.insert(5 if d["feature"].get("tool") else 4, ("load grooves", grooves))
    if d.get("stock"):
        rows.insert(3, ("stock", d["stock"]["label"]))
    if record.get("stock"):
        rows.insert(4 if d.get("stock") else 3, ("continuous optimum", continuous_text(record["stock"])))
    tolerances = tolerance_text(record)
    if tolerances:
        rows.append(("tolerances", tolerances))
    if d.get("adjustment"):
        rows.append(("model factors (3-D / model)", factors_text(d["adjustment"])))
    rounds = record.get("verify_rounds")
    if rounds:
        rows.append(("3-D check", verify_verdict(record)))
    return rows


def longer_pocket_text(record: dict) -> str:
    """Why a pocket or flat is longer than the gauge's backing and margins (the spec's rule): a
    searched one because the 3-D corrections hold only for one that long on this section
    (docs/model.md §1), a fixed design's because it says so; "" where it is the rule's length."""
    d = record["design"]
    margin = record["spec"].get("limits", {}).get("pocket_margin")
    if d["feature"]["kind"] != "pocket" or not isinstance(margin, (int, float)):
        return ""
    corner = record["spec"].get("cad", {}).get("corner_radius")
    if isinstance(corner, (int, float)) and record.get("solver", {}).get("method", "none") != "none":
        margin = max(margin, corner)    # a search's pocket keeps the corner radius too (Spec.pocket_size)
    rule = d["gauge"]["length"] + 2 * margin
    if d["feature"]["length"] <= rule + 5e-6:     # within the 0.01 mm rounding
        return ""
    if record.get("solver", {}).get("method", "none") == "none":     # a fixed design's, as given
        return f"longer than the gauge's {rule * 1e3:.2f} mm pocket, as the design gives it"
    return (f"longer than the gauge's {rule * 1e3:.2f} mm pocket, as the 3-D corrections need on this section "
            "(docs/model.md §1)")


def groove_text(record: dict) -> str:
    """The load grooves as cut: ``3 × 0.5 mm wide, 0.30 mm deep, at 40, 75, 110 mm from the
    clamp``; "" without them. The default positions and depth as the CAD takes them (the depth
    rounded down to the 0.01 mm grid)."""
    from designer.model import grooves

    spec = record["spec"]
    cad = spec.get("cad") or {}
    if not cad.get("load_grooves"):
        return ""
    section = record["design"]["section"]
    at = cad.get("groove_positions") or grooves.default_positions(*spec["load"]["position"])
    smaller = min(section["width"], section["height"]) if section["kind"] == "rectangle" else section["diameter"]
    depth = cad.get("groove_depth") or grooves.cut_depth(smaller)
    return (f"{len(at)} × {grooves.WIDTH * 1e3:g} mm wide, {depth * 1e3:.2f} mm deep, at "
            f"{', '.join(f'{x * 1e3:.4g}' for x in sorted(at))} mm from the clamp")


def tool_text(tool: dict, section: dict) -> str:
    """The end mill that cuts the pockets or flats and how: ``Ø3 R0.2 mm (tool catalogue), slot
    corners its radius`` or ``..., across the bar``."""
    label = tool["label"].removeprefix("end mill ")
    listed = "" if tool.get("table") == "spec" else f" ({tool['table']})"
    how = "slot corners its radius" if section["kind"] == "rectangle" else "moved across the bar"
    return f"{label}{listed}, {how}; floors meet the walls in its corner radius"


def tolerance_text(record: dict) -> str:
    """The tolerance corners in a line: the checked class and whether every limit holds there, or
    (without ``tolerances:``) which limits break at the drawing's general tolerances; '' for neither."""
    checked = record.get("tolerances")
    tol = checked or record.get("general_tolerances")
    if not tol:
        return ""
    broken = [c for c in tol["constraints"] if not c["satisfied"]]
    # a corner that is no beam has no margin: where it is says what to change
    said = ", ".join(f"{c['name']} at {c.get('corner', 'a corner')}" if c["name"] == "corner_unbuildable"
                     else f"{c['name']} {c['margin']:+.1%}" for c in broken)
    if checked:
        return (f"{tol['label']}: every limit holds at its {tol['corners']} corners" if not broken
                else f"{tol['label']}: breaks {said}" + ("" if all(c["name"] == "corner_unbuildable" for c in broken)
                                                          else " at a corner"))
    return (f"not checked; at the drawing's {tol['label']} every limit holds" if not broken
            else f"not checked; at the drawing's {tol['label']}: {said} (report.md)")


def error_rows(record: dict) -> list[tuple[str, str]]:
    """The force and position errors: the noise's at (F_min, x_max), or with an environment the
    combined standard uncertainty of the whole budget, the largest over the region."""
    p, s = record["predicted"], record["spec"]
    mm = 1e3
    targets = s["targets"]
    b = p.get("budget")
    if b is None:
        return [("force error (1σ at F_min)", f"{p['force_error'] * 100:.3g} % of {s['load']['force'][0]:.4g} N "
                                              f"(target {targets['force_error'] * 100:.3g} %)"),
                ("position error (1σ at F_min, x_max)", f"{p['position_error'] * mm:.3g} mm "
                                                        f"(target {targets['position_error'] * mm:.3g} mm)")]
    f, x = b["force"], b["position"]
    oiml = [("as a force cell, OIML R 60", oiml_text(b))] if b.get("oiml_r60") else []
    return [
        ("force error (combined 1σ, worst)", f"{f['combined'] * 100:.3g} % at {f['at']['force']:.4g} N, "
                                             f"{f['at']['position'] * mm:.4g} mm (k = 2: {f['expanded'] * 100:.3g} %; "
                                             f"target {targets['force_error'] * 100:.3g} %; noise alone "
                                             f"{b['noise_only']['force_error'] * 100:.3g} %)"),
        ("position error (combined 1σ, worst)", f"{x['combined'] * mm:.3g} mm at {x['at']['force']:.4g} N, "
                                                f"{x['at']['position'] * mm:.4g} mm (k = 2: {x['expanded'] * mm:.3g} mm; "
                                                f"target {targets['position_error'] * mm:.3g} mm; noise alone "
                                                f"{b['noise_only']['position_error'] * mm:.3g} mm)"),
    ] + oiml


def budget_rows(budget: dict) -> list[tuple[str, ...]]:
    """The error budget as rows: term, kind, u(F)/F and its share, u(x) and its share."""
    rows = []
    for f, x in zip(budget["force"]["terms"], budget["position"]["terms"]):
        rows.append((f["name"], f["kind"], f"{f['u'] * 100:.3g} %", f"{f['share']:.0%}", f"{x['u'] * 1e3:.3g} mm",
                     f"{x['share']:.0%}"))
    f, x = budget["force"], budget["position"]
    rows.append(("combined (1σ)", "", f"{f['combined'] * 100:.3g} %", "100%", f"{x['combined'] * 1e3:.3g} mm", "100%"))
    rows.append((f"expanded (k = {budget['coverage_factor']})", "", f"{f['expanded'] * 100:.3g} %", "",
                 f"{x['expanded'] * 1e3:.3g} mm", ""))
    return rows


def oiml_text(budget: dict) -> str:
    """The OIML R 60 class and n_LC the budget allows as a force cell, and what stops the next step."""
    r = budget.get("oiml_r60")
    if r is None:
        return ""
    head = "no OIML R 60 class" if r["class"] is None else f"class {r['class']}, n_LC = {r['n_lc']}"
    return f"{head} ({r['limited_by']})"


BUDGET_COLUMNS = ("term", "kind", "u(F)/F", "share", "u(x)", "share")


def budget_caption(budget: dict) -> str:
    f, x = budget["force"]["at"], budget["position"]["at"]
    return (f"at the region's worst corners: force {f['force']:.4g} N at {f['position'] * 1e3:.4g} mm, "
            f"position {x['force']:.4g} N at {x['position'] * 1e3:.4g} mm; systematic terms bounded by a "
            "count as u = a/√3 (JCGM 100)")


def front_end_rows(fe: dict) -> list[tuple[str, str]]:
    """The front-end's setting, the full-load output in mV/V and counts, and its noise."""
    n = fe["noise"]
    setting = f"{fe['name']}, gain {fe['gain']:g}, {fe['rate']:g} Hz, {fe['bits']} bits"
    output = " / ".join(f"{v * 1e3:.3g}" for v in fe["output_per_volt"])
    counts = " / ".join(f"{c:,.0f}" for c in fe["output_counts"])
    half = 2 ** (fe["bits"] - 1)
    return [
        ("front-end", setting),
        ("output at F_max, x_max", f"{output} mV/V of ±{fe['full_scale_per_volt'] * 1e3:.3g} mV/V "
                                   f"({counts} counts of ±{half:,})"),
        ("noise (bridge output, RMS)", f"{n['total'] * 1e9:.3g} nV = {fe['noise_counts']:.3g} counts "
                                       f"(converter {n['converter'] * 1e9:.3g}, bridge Johnson "
                                       f"{n['johnson'] * 1e9:.2g}, quantisation {n['quantisation'] * 1e9:.2g} nV)"),
    ]


def objective_text(value: float, objective: str) -> str:
    """An objective's value in its own terms."""
    if objective == "deflection":
        return f"deflection {value * 1e3:.4g} mm"
    if objective == "mass":
        return f"mass {value * 1e3:.4g} g"
    return f"error ratio {value:.4g}"


def continuous_text(stock: dict) -> str:
    """The best design of continuous sizes beside the stock one, and what stock costs."""
    c = stock.get("continuous")
    if c is None:
        return "none of continuous sizes meets every limit"
    text = f"{objective_text(c['objective'], stock['objective'])}, {c['material']} {section_text(c['section'])}"
    if stock.get("cost") is not None:
        text += f": stock costs {stock['cost']:.1%} in {stock['objective']}"
    return text


def verify_verdict(record: dict) -> str:
    """The 3-D check's loop in a few words: passed at once, passed after correction, or failed."""
    rounds = record["verify_rounds"]
    passed = [r for r in rounds if r["passed"]]
    n = len(rounds)
    if passed and passed[0]["round"] == 0:
        return "every limit holds in 3-D"
    if passed:
        return f"every limit holds in 3-D after correction (round {passed[0]['round']})"
    return "FAILS in 3-D in round 0" if n == 1 else f"FAILS in 3-D in every round (0-{n - 1})"


def factors_text(adjustment: dict | None) -> str:
    if adjustment is None:
        return "plain model"
    strain = ", ".join(f"{f:.3f}" for f in adjustment["gauge_strain"])
    return (f"strain {strain}; deflection {adjustment['deflection']:.3f}; "
            f"K_t × {adjustment['stress_concentration']:.3f}")


def rounds_markdown(record: dict) -> list[str]:
    """The rounds of the 3-D check as a Markdown table (docs/spec.md §4, ``verify_rounds``)."""
    lines = ["## 3-D check", "", verify_verdict(record) + ".", "",
             "| round | model factors (3-D / model) | design | 3-D verdict | worst 3-D limit |",
             "|---|---|---|---|---|"]
    for r in record["verify_rounds"]:
        d = r.get("design")
        design = "–" if d is None else (f"{d['material']} {section_text(d['section'])}, "
                                        f"{feature_text(d['feature'], d['section'])}")
        if "stopped" in r:
            verdict = r["stopped"]
        else:
            verdict = "holds" if r["passed"] else "**fails**: " + ", ".join(r["failed"])
        worst = "–" if r.get("worst_limit") is None else f"{r['worst_limit']} {r['worst_ratio']:.3f}"
        lines.append(f"| {r['round']} | {factors_text(r['adjustment'])} | {design} | {verdict} | {worst} |")
    return lines + [""]


def stress_rows(record: dict) -> list[tuple]:
    """The stress limits as report rows, the binding one (the least margin) named."""
    by_name = {c["name"]: c for c in record["constraints"]}
    p = record["predicted"]
    rows = []
    labels = {"stress_root": "root stress (nominal) / allowable",
              "stress_feature": "feature stress, static (nominal) / yield allowable",
              "fatigue_feature": f"feature stress, fatigue (K_f {p.get('fatigue_factor', 1):.3g} × nominal; "
                                 f"K_t {p.get('stress_concentration', 1):.3g}) / fatigue allowable",
              "stress_groove": "groove stress, static (nominal) / yield allowable",
              "fatigue_groove": "groove stress, fatigue (K_f × nominal) / fatigue allowable"}
    c = p.get("direction_factor", 1.0)
    if c != 1.0 and p.get("stress_notch"):   # a biaxial sensor's features (docs/model.md §9)
        k_f, notch = p.get("fatigue_factor", 1), p["stress_notch"]
        plain = k_f * notch < p["stress_fatigue"] * (1 - 1e-6)
        labels["fatigue_feature"] = (
            f"feature stress, fatigue ({'the plain nominal, above ' if plain else ''}K_f {k_f:.3g} × the "
            f"notch's nominal {notch * 1e-6:.4g} MPa; K_t {p.get('stress_concentration', 1):.3g} × {c:g} for the "
            "worst load direction) / fatigue allowable")
    if "fatigue_groove" in by_name and "stress_groove" in by_name and by_name["stress_groove"]["value"] > 0:
        # both on the groove's nominal stress: their ratio is its K_f (docs/model.md §4)
        k_f = by_name["fatigue_groove"]["value"] / by_name["stress_groove"]["value"]
        labels["fatigue_groove"] = f"groove stress, fatigue (K_f {k_f:.3g} × nominal) / fatigue allowable"
    present = [n for n in labels if n in by_name]
    # "binds" where the design sits on a limit, at its nominal sizes or at its worst tolerance corner;
    # where none does, the least margin is named
    corners = {c["name"]: c for c in (record.get("tolerances") or {}).get("constraints", [])}
    flags = {}
    for name in present:
        at = corners.get(name)
        flags[name] = ("  (binds)" if by_name[name].get("active") else
                       f"  (binds at {at['corner']})" if at is not None and at.get("active") else "")
    if len(present) < 2:
        flags = dict.fromkeys(present, "")
    elif not any(flags.values()):
        flags[min(present, key=lambda n: by_name[n]["margin"])] = "  (least margin)"
    for name in present:
        c = by_name[name]
        rows.append((labels[name], f"{c['value'] * 1e-6:.4g} / {c['limit'] * 1e-6:.4g} MPa{flags[name]}"))
    if not present:  # an older record
        rows.append(("max stress / allowable", f"{p['max_stress'] * 1e-6:.4g} / {p['stress_allowable'] * 1e-6:.4g} MPa"))
    return rows


def tolerance_markdown(tol: dict) -> list[str]:
    """The design at the corners of its tolerances: each limit at its worst corner."""
    sizes = ", ".join(f"{name} ±{dev * 1e3:.3g} mm" for name, dev in tol["deviations"].items())
    low, high = tol["sensitivity_spread"]
    lines = ["## Tolerances", "",
             f"Built to {tol['label']}; {sizes}: each limit below was checked at all {tol['corners']} corners "
             "(every toleranced size at its nominal ± deviation); its worst corner is shown. "
             f"Across the corners the sensitivities k move by {low:+.1%} to {high:+.1%}, which each sensor's "
             "own calibration absorbs.", ""]
    return lines + corner_table(tol["constraints"])


def corner_table(constraints: list) -> list[str]:
    """Limits at their worst tolerance corners as a table of the report."""
    return (["| limit | worst corner | value | bound | margin | |", "|---|---|---|---|---|---|"]
            + [limit_row(c, c["corner"]) for c in constraints])


def general_tolerance_markdown(tol: dict) -> list[str]:
    """The design at the corners of the drawing's general tolerances, which were not checked."""
    broken = [c for c in tol["constraints"] if not c["satisfied"]]
    low, high = tol["sensitivity_spread"]
    lines = ["## Tolerances", "",
             f"Not checked (the spec's `tolerances: {{class: none}}`): the limits above are judged at the nominal "
             f"sizes. The drawing asks for the general tolerances of {tol['label']}; at their {tol['corners']} "
             "corners (every toleranced size at its nominal ± deviation) "
             + (f"{len(broken)} {'limits break' if len(broken) > 1 else 'limit breaks'}, each at its worst corner below. "
                f"Without `class: none` (the default is {tol['class']}) the search keeps every limit "
                "at every corner." if broken else "every limit holds.")
             + f" Across the corners the sensitivities k move by {low:+.1%} to {high:+.1%}.", ""]
    return lines + (corner_table(broken) if broken else [])


def limit_row(c: dict, *before) -> str:
    """A design.json constraint record as a row of the report's limit tables, after ``before``."""
    flag = "**violated**" if not c["satisfied"] else ("binds" if c["active"] else "")
    cells = [c["name"], *before, display(c["value"], c["unit"], c["name"]),
             f"{c['sense']} {display(c['limit'], c['unit'], c['name'])}", percent(c["margin"]), flag]
    return "| " + " | ".join(cells) + " |"


def binding_limits(record: dict) -> list[dict]:
    """The limits that bind or break: at the nominal sizes, then at their worst tolerance corner
    (each with ``corner``, e.g. ``D min, p max``)."""
    corners = (record.get("tolerances") or {}).get("constraints", [])
    return [c for c in record["constraints"] + corners if c["active"] or not c["satisfied"]]


def markdown(record: dict) -> str:
    s = record["spec"]
    lines = [f"# {s['name']}: force-and-position sensor design", ""]
    for msg in record.get("messages", []):
        lines += [f"> **{msg}**", ""]
    lines += ["## Design", "", "| | |", "|---|---|"]
    lines += [f"| {k} | {v} |" for k, v in summary_rows(record)]
    lines += ["", "## Limits", "",
              "Every limit was checked with the numeric model on the rounded design (0.01 mm).", "",
              "| limit | value | bound | margin | |", "|---|---|---|---|---|"]
    lines += [limit_row(c) for c in record["constraints"]]
    if record.get("tolerances"):
        lines += [""] + tolerance_markdown(record["tolerances"])
    elif record.get("general_tolerances"):
        lines += [""] + general_tolerance_markdown(record["general_tolerances"])
    budget = record["predicted"].get("budget")
    if budget is not None:
        lines += ["", "## Error budget", "", budget_caption(budget) + ".", "",
                  "| " + " | ".join(BUDGET_COLUMNS) + " |", "|---|---|---:|---:|---:|---:|"]
        lines += ["| " + " | ".join(row) + " |" for row in budget_rows(budget)]
    if record.get("verify_rounds"):
        lines += [""] + rounds_markdown(record)
    if record.get("candidates"):
        lines += ["", "## Candidates", "", candidate_order(record), "",
                  "| rank | material | section | status | objective | worst violation | deflection | mass |",
                  "|---|---|---|---|---|---|---|---|"]
        for i, c in enumerate(record["candidates"], 1):
            obj = _objective_cell(c)
            defl = "–" if c.get("deflection") is None else f"{c['deflection'] * 1e3:.3g} mm"
            mass = "–" if c.get("mass") is None else f"{c['mass'] * 1e3:.3g} g"
            status = c["status"] + (" (corrected in 3-D)" if c.get("adjustment") else "")
            section = c["section"] + (f" ({c['stock']})" if c.get("stock") else "")
            lines.append(f"| {i} | {c['material']} | {section} | {status} | {obj} | {_violation(c)} | {defl} "
                         f"| {mass} |")
        # a note may name its candidate already ("6061-T6 tube: no design of continuous sizes ...")
        notes = [f"- {note}" if note.startswith(f"{c['material']} {c['section']}:")
                 else f"- {c['material']} {c['section']}: {note}"
                 for c in record["candidates"] if (note := c.get("stock_note")) and c.get("objective") is None]
        if notes:
            lines += ["", "Without a stock design:", ""] + notes
    solver = record.get("solver", {})
    if solver.get("method") not in (None, "none"):
        lines += ["", "## Solver", "", f"method {solver['method']}, {solver.get('seconds', 0):.3g} s, "
                  f"{solver.get('evaluations', 0)} model evaluations."]
        if solver.get("fallbacks"):
            lines += ["", "Runs that gave no checked design at once, and what was done (each design above was "
                      "checked after rounding):", ""] + [f"- {f}" for f in solver["fallbacks"]]
    lines += ["", "## Model", "",
              "Euler–Bernoulli beam theory and closed-form section properties, with factors fitted to 3-D "
              "finite-element results for the features and the clamp (docs/model.md §7); noise is Gaussian "
              "and independent per channel; errors are 1σ by linear propagation (the mean absolute error is "
              "√(2/π)·σ ≈ 0.80 σ), of the noise alone or, with an environment, of the error budget "
              "(docs/model.md §13). Loads are perpendicular point loads; the deflection must stay small "
              "(below 10 % of the length) for the linear model to hold.", ""]
    for name, title in (("model_png", "3-D model"), ("drawing_png", "Drawing")):
        if record.get("files", {}).get(name):
            lines += [f"## {title}", "", f"![{title}]({record['files'][name]})", ""]
    for name in ("operating-region", "error-maps", "voltage-isolines", "candidates",
                 "tradeoff-deflection", "tradeoff-frequency"):
        if name + ".png" in record.get("files", {}).get("plots", []):
            lines += [f"![{name}]({name}.png)", ""]
    return "\n".join(lines)


def candidate_order(record: dict, shown: list | None = None) -> str:
    """How the candidates are ranked and the reported one picked (designer.search.run); the note
    on outranked candidates where one of ``shown`` (default: every candidate) is."""
    objective = record.get("spec", {}).get("objective", "error")
    if record.get("status") == "infeasible":
        return ("No candidate meets every limit. Each shows its closest design (where its sizes are free, "
                "solved again for the least violation with every rule of the geometry met); they are ranked: "
                "a beam first, then one within the sizes the spec allows, then the fewest of those rules "
                "broken, then by the worst violation, value/limit − 1, of "
                "the duty's limits (stress, strain, signal, deflection, frequency), then of the accuracy "
                "targets (failed solves at the end); the first, the least infeasible, is the reported design.")
    text = (f"Designs that meet every limit come first, ranked by the objective ({objective}; within "
            "0.1 % by lower deflection, then lower mass), then the others, the closest first: a beam, one "
            "within the sizes the spec allows, the fewest of the geometry's rules broken, then by the worst "
            "violation of the duty's limits, then of the accuracy targets; the first is the reported design.")
    if any(c.get("status") == "outranked" for c in (record.get("candidates", []) if shown is None else shown)):
        text += (" Outranked: its answer before rounding (IPOPT's optimum of continuous sizes, not a bound: "
                 "a design on the 0.01 mm grid or of stock may be a little better or worse, or may not exist) "
                 "already ranked it out of contention, so it was not rounded or no stock size was solved; "
                 "it is listed at that answer.")
    return text


def _objective_cell(c: dict) -> str:
    """A candidate's objective; for one outranked, its answer before rounding."""
    value = c.get("objective")
    if value is None and c.get("status") == "outranked" and c.get("continuous_objective") is not None:
        return f"{c['continuous_objective']:.4g} before rounding"
    return "–" if value is None or not math.isfinite(value) else f"{value:.4g}"


def _violation(c: dict) -> str:
    v = c.get("worst_violation")
    return "–" if v is None else ("none" if v <= 0 else f"{v:.3g}")


def print_summary(record: dict, console=None) -> None:
    from rich.console import Console
    from rich.table import Table

    console = console or Console()
    table = Table(title=f"{record['spec']['name']} — {record['status']}", show_header=False)
    table.add_column(style="bold")
    table.add_column()
    for k, v in summary_rows(record):
        table.add_row(k, v)
    console.print(table)
    budget = record["predicted"].get("budget")
    if budget is not None:
        bt = Table(title="error budget", caption=budget_caption(budget))
        for col in BUDGET_COLUMNS:
            bt.add_column(col, justify="left" if col in ("term", "kind") else "right")
        for row in budget_rows(budget):
            bt.add_row(*row)
        console.print(bt)
    binding = binding_limits(record)
    if binding:
        lim = Table(title="binding or violated limits")
        for col in ("limit", "value", "bound", "margin"):
            lim.add_column(col)
        for c in binding:
            lim.add_row(c["name"] + (f" at {c['corner']}" if "corner" in c else ""),
                        display(c["value"], c["unit"], c["name"]),
                        f"{c['sense']} {display(c['limit'], c['unit'], c['name'])}",
                        f"[{'red' if not c['satisfied'] else 'yellow'}]{percent(c['margin'])}[/]")
        console.print(lim)
    if record.get("candidates"):
        shown = record["candidates"][:6]
        more = len(record["candidates"]) - len(shown)
        cand = Table(title="the chosen candidate and the runners-up",
                     caption=candidate_order(record, shown) + (f" {more} more in report.md." if more else ""))
        for col in ("material", "section", "status", "objective", "worst violation", ""):
            cand.add_column(col)
        for i, c in enumerate(shown):
            obj = _objective_cell(c)
            cand.add_row(c["material"], c["section"], c["status"], obj, _violation(c), "chosen" if i == 0 else "")
        console.print(cand)
    for msg in record.get("messages", []):
        console.print(f"[yellow]{msg}[/]")
