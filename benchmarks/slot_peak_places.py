"""Where does a slot's 3-D peak stress sit on the study's slots that the slot K_t fit reads worst?

The slot K_t fit (docs/model.md §7) scatters by about 4 % RMS about the study's slots and ships
shifted to its safe side until no left-out slot reads more than 5 % under its 3-D K_t; the shift is
set by its few worst slots. This check takes the study's slots of the fit's domain whose left-out
prediction (the shipped form fitted without them) reads lowest and highest against their 3-D K_t,
solves each again (``verify``'s 3-D check, normal mesh) and says where its peak sits: on the floor
radius (over or beside the wire channel, which enters the clamp-side end wall, or out by the side
wall), or on the top face at the slot's edge (a thin side wall's top, or the rim of a slot in a
wide bar), and at which end of the slot (the check's peak, which sits at the near slot, where the
moment is larger). Run by hand (one to two minutes a slot on 2 cores):

    python benchmarks/slot_peak_places.py [--count 12] [--study materials/corrections_study.csv]

With ``--narrower``, instead: two of the study's slots, in a thin wide bar and in a tall one, solved
again 4 mm wide instead of the study's 5.5 mm, and with other wire channels, against the shipped
model's K_t (the study cannot tell a slot's own width from its bar's: they are all 5.5 mm wide).

Its figures: benchmarks/slot_peak_places.md.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def left_out_errors(path: Path) -> list[tuple[float, dict]]:
    """``(left-out error, row)`` of every slot row of the K_t fit's domain, the error
    (prediction - 3-D) / 3-D of the shipped table's form (today fit_forms.SLOT_KT_DEEP) fitted
    without the row, before its shift, lowest first."""
    from designer.checks import fit_forms, fits, study
    from designer.model import corrections

    family = "rectangle-pocket"
    box = fit_forms.FIT_DOMAINS[family]["stress"]
    rows = [r for r in fits.with_nearness(study.read_csv(path))
            if r["family"] == family and math.isfinite(r.get("stress_ratio", math.nan))
            and all(lo <= r.get(k, math.nan) <= hi for k, (lo, hi) in box.items())]
    shipped = corrections.load().fits[family]["stress"]
    form = fit_forms.Terms(shipped.variables, shipped.exponents)
    _, left_out = fits.fit_terms(rows, form, lambda r: r["stress_ratio"],
                                 weight=lambda r: fits.error_weight("stress", r), box=box, quantity="stress")
    errors = [((p - r["stress_ratio"]) / r["stress_ratio"], r) for p, r in zip(left_out, rows)]
    return sorted(errors, key=lambda t: t[0])


def matching_case(row: dict, cases: list) -> object | None:
    """The study case whose parameters are the row's (``study --refresh``'s match)."""
    for case, params in cases:
        if all(math.isclose(row.get(k, math.nan), v, rel_tol=1e-5, abs_tol=1e-9) for k, v in params.items()):
            return case
    return None


def place(case, peak) -> str:
    """Where ``peak`` sits on ``case``'s near slot, in words."""
    from designer.model import sections

    x, y, z = peak.location
    near = case.stations()[0]
    start, end = near - case.pocket_length / 2, near + case.pocket_length / 2
    channel, _ = sections.default_channel("rectangle", case.depth, case.pocket_width)
    along = ("clamp-side end" if x < start + 0.25 * case.pocket_length
             else "load-side end" if x > end - 0.25 * case.pocket_length else "along the slot")
    if peak.on_floor_radius:
        side = ("over the wire channel" if abs(y) < channel / 2
                else "beside the channel" if abs(y) < (channel + case.pocket_width) / 4 else "out by the side wall")
        return f"floor radius, {side}, {along}"
    near_to = peak.element_size     # within a mesh edge of a face
    if abs(abs(z) - case.height / 2) < near_to and abs(y) >= case.pocket_width / 2 - near_to:
        thin = (case.width - case.pocket_width) / 2 < case.height
        return f"top face at the slot's edge ({'thin side wall' if thin else 'rim in a wide bar'}), {along}"
    if abs(z) < case.height / 2 - case.depth + near_to and abs(y) < channel / 2 + near_to:
        return f"in the wire channel, {along}"
    return f"{peak.where}, {along}"


def at(case, peak) -> str:
    """The peak's place from the near slot's clamp-side end, across from the mid-plane and up
    from the floor, in mm."""
    x, y, z = peak.location
    start = case.stations()[0] - case.pocket_length / 2
    return f"{(x - start) * 1e3:.2f}, {abs(y) * 1e3:.2f}, {(abs(z) - case.height / 2 + case.depth) * 1e3:+.3f}"


def nominal_stress(result, spec) -> float:
    """The plain beam model's stress at the near slot's clamp-side edge (``study.run_case``'s)."""
    from designer import model
    from designer.model import corrections

    design = result.evaluation.design
    raw = model.analyse(design.geometry, design.material_params(spec), spec, table=corrections.Corrections({}))
    start = design.geometry.reduced_spans[0][0]
    return spec.load.force_max * (spec.load.position_max - start) * float(raw.props.y_e) / float(raw.props.I_s)


# --narrower: two study slots solved again 4 mm wide instead of 5.5 mm, and with other wire channels
# (the study's slots are all 5.5 mm wide with a 1.5 mm channel): a thin, wide bar and a tall one,
# by height, width and slot depth in mm, each with the slot widths and channel widths (mm) to try.
NARROWER = (((2.37, 15.66, 0.42), ((5.5, None), (5.5, 2.06), (4.0, None), (4.0, 1.1))),
            ((7.94, 13.95, 1.00), ((5.5, None), (4.0, None))))


def narrower(mesh: str) -> None:
    """The NARROWER slots' 3-D K_t against the shipped model's (its shift included)."""
    import dataclasses

    from designer.checks import fits, study
    from designer.model import corrections

    shipped = corrections.load().fits["rectangle-pocket"]["stress"]
    print("| h (mm) | b (mm) | depth / h | slot width (mm) | channel (mm) | 3-D K_t | model K_t | 3-D / model |")
    print("|---:|---:|---:|---:|---|---:|---:|---:|")
    for (h, b, p), tries in NARROWER:
        case = next(c for c in study.cases(["rectangle-pocket"]) if abs(c.height * 1e3 - h) < 0.005
                    and abs(c.width * 1e3 - b) < 0.005 and abs(c.depth * 1e3 - p) < 0.005)
        for width, channel in tries:
            trial = dataclasses.replace(case, pocket_width=width * 1e-3,
                                        channel=(channel * 1e-3, round(case.depth / 2, 6)) if channel else ())
            row = study.run_case(trial, mesh)
            model = float(shipped(fits.with_nearness([{**row.parameters, "family": trial.family}])[0]))
            said = f"{channel:.2f} x {case.depth / 2 * 1e3:.2f}" if channel else "default"
            print(f"| {h:.2f} | {b:.2f} | {case.depth / case.height:.3f} | {width:.1f} | {said} | {row.stress_ratio:.3f} | "
                  f"{model:.3f} | {row.stress_ratio / model:.3f} |", flush=True)


def main(argv=None) -> int:
    from designer.checks import study
    from designer.checks.fea import verify_design
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=12, help="slots read lowest, and as many read highest")
    parser.add_argument("--study", type=Path, default=ROOT / "materials" / "corrections_study.csv")
    parser.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    parser.add_argument("--narrower", action="store_true", help="instead: two slots solved again narrower (NARROWER)")
    args = parser.parse_args(argv)
    if args.narrower:
        start = time.perf_counter()
        narrower(args.mesh)
        print(f"check took {time.perf_counter() - start:.0f} s", file=sys.stderr)
        return 0
    errors = left_out_errors(args.study)
    picked = errors[:args.count] + errors[-args.count:]
    cases = study.cases_with_parameters(["rectangle-pocket"])
    print("| left-out error | 3-D K_t (study) | 3-D K_t (now) | where the peak sits | h (mm) | b (mm) | depth / h "
          "| notch_ratio | side walls / h | slot width / h | clamp_near | peak's mesh change | peak at (mm) |")
    print("|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    start = time.perf_counter()
    for error, row in picked:
        case = matching_case(row, cases)
        if case is None:
            print(f"| {error:+.3f} | {row['stress_ratio']:.3f} | no case matches the row |", flush=True)
            continue
        spec = parse_spec_text(case.spec_text(), source=case.family)
        result = evaluate_fixed(spec)
        check = verify_design(result.record, mesh=args.mesh)
        near_peak = check.stress_stations_fea[0] / nominal_stress(result, spec)
        print(f"| {error:+.3f} | {row['stress_ratio']:.3f} | {near_peak:.3f} | {place(case, check.stress_peak)} | "
              f"{case.height * 1e3:.2f} | {case.width * 1e3:.2f} | {row['depth_ratio']:.3f} | {row['notch_ratio']:.2f} | "
              f"{row['side_wall_ratio']:.2f} | {case.pocket_width / case.height:.2f} | {row['clamp_near']:.2f} | "
              f"{check.stress_change:.3f} | {at(case, check.stress_peak)} |", flush=True)
    print(f"check took {time.perf_counter() - start:.0f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
