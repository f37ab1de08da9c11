"""A slot's K_t of one form against a K_t of two places, on the 3-D study's slots.

A slot's 3-D peak sits on its floor radius or at its rim on the loaded outer face; the study
records both peaks of every slot (``study.Row.stress_floor`` and ``stress_face``, near and far:
``python -m designer.checks.peak_places``). This fits the slots' K_t both ways with the fitting
rules the table is made by (``fits.fit_table``):

- one form: the largest peak of the slot's zone (``stress_ratio``) over its forms (as it
  shipped before the two places);
- two places without the end mill: the floor radius's peak over the same forms, the rim's over
  polynomials in the slot's plan shape, depth, side walls and the bar's width (WITHOUT_PLAN), K_t
  the larger of the two, both shifted to the safe side together (``fits.shifted_pair``);
- two places as shipped (``fit_forms.FIT_FORMS``): the rim's over the depth, the slot's share of
  the width and ``plan_notch = sqrt(p/r_m)``, Neuber's variable of the slot's corner in plan, whose
  radius is the end mill's (``outputs.cad.mills``; the study records it), the floor radius's as
  above;
- the same with the floor radius's form the rule took when it judged a shifted fit on both sides
  of its left-out error (Neuber's shape with the clamp term, ``fit_forms.SLOT_KT_CLAMP``), not on
  its unsafe side (``fits.unsafe_error``);

and prints where the study's peaks sit, each fit's form, residuals and shift, and how the
study's 3-D peaks read against each K_t (3-D over model: below 0.90 the 3-D check calls the
model's peak too high; above 1/0.95 the model reads it more than the fits' 5 % rule under), near
features in-sample and far features, as the model takes K_t at every feature.

Run by hand:  python benchmarks/two_place_kt.py [--table materials/corrections_study.csv]
"""

from __future__ import annotations

import argparse
import math
import statistics
from pathlib import Path

from designer.checks import fit_forms, fits
from designer.checks.study_table import read_csv

ROOT = Path(__file__).resolve().parent.parent
FAMILY = "rectangle-pocket"
# The rim's forms without the end mill's radius (the second variant): the slot's plan shape, how
# much of the top layer it cuts and what its side walls carry.
WITHOUT_PLAN = [("depth_ratio", "length_ratio"), ("length_ratio", "side_wall_ratio"),
                ("depth_ratio", "side_wall_ratio"), ("depth_ratio", "length_ratio", "side_wall_ratio"),
                ("depth_ratio", "length_ratio", "pocket_width_ratio"), ("length_ratio", "width_ratio", "side_wall_ratio"),
                ("depth_ratio", "width_ratio", "side_wall_ratio"), ("depth_ratio", "length_ratio", "clamp_near"),
                ("length_ratio", "side_wall_ratio", "clamp_near")]
SAME = 0.999    # a place's peak within this share of the zone's is the zone's peak


def places(rows: list[dict], columns: tuple) -> dict:
    """How many of ``rows`` peak on the floor radius, on the outer face, or elsewhere in the zone
    (``columns``: the zone's, the floor's and the face's peak)."""
    zone, floor, face = columns
    out = {"floor radius": 0, "outer face": 0, "elsewhere": 0}
    for r in rows:
        top = r[zone]
        out["floor radius" if r[floor] >= SAME * top else "outer face" if r[face] >= SAME * top else "elsewhere"] += 1
    return out


def readings(rows: list[dict], predicted: list[float]) -> str:
    """3-D over model: least, median, largest, and how many below 0.90 and above 1/0.95."""
    ratios = [r["stress_ratio"] / p for r, p in zip(rows, predicted)]
    unsafe = 1 / (1 - fits.FIT_ACCEPT["stress"])
    return (f"{min(ratios):.3f} | {statistics.median(ratios):.3f} | {max(ratios):.3f} | "
            f"{sum(v < 0.90 for v in ratios)} of {len(ratios)} | {sum(v > unsafe * (1 + 1e-9) for v in ratios)}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--table", type=Path, default=ROOT / "materials" / "corrections_study.csv")
    args = p.parse_args(argv)
    raw = read_csv(args.table)
    rows = [r for r in fits.with_nearness(raw) if r["family"] == FAMILY]
    recorded = [r for r in rows if math.isfinite(r.get("stress_floor", math.nan))]
    print(f"{len(recorded)} of the study's {len(rows)} slots record both places.\n")
    box = fit_forms.FIT_DOMAINS[FAMILY]["stress"]
    near = [r for r in recorded if fits._in_domain(r, box)]
    far = [{**r, "stress_ratio": r["stress_far"], fits.FACE: r["stress_face_far"], "stress_floor": r["stress_floor_far"]}
           for r in fits.far_features(recorded, FAMILY)]
    print("| features (K_t's domain) | on the floor radius | on the outer face | elsewhere |\n|---|---:|---:|---:|")
    for name, data, columns in (("near", near, ("stress_ratio", "stress_floor", fits.FACE)),
                                ("far", [r for r in far if fits._in_domain(r, box)], ("stress_ratio", "stress_floor", fits.FACE))):
        count = places(data, columns)
        print(f"| {name} ({len(data)}) | {count['floor radius']} | {count['outer face']} | {count['elsewhere']} |")

    slots = fit_forms.FIT_FORMS[FAMILY]
    one = {q: forms for q, forms in slots.items() if q != fits.FACE}
    variants = {"one form": one, "two places": {**one, fits.FACE: WITHOUT_PLAN}, "two places, r_m": slots,
                "r_m, floor judged on both sides": {**slots, "stress": [fit_forms.SLOT_KT_CLAMP]}}
    print("\n| K_t | fit | terms | variables | RMS | left-out max | shift |\n|---|---|---:|---|---:|---:|---:|")
    tables = {}
    for name, chosen in variants.items():
        table, _ = fits.fit_table(raw, forms={FAMILY: chosen})
        tables[name] = table
        for quantity in fits.KT:
            f = table.fit(FAMILY, quantity)
            if f is not None:
                what = {"stress": "floor radius" if name != "one form" else "zone's peak", fits.FACE: "outer face"}[quantity]
                print(f"| {name} | {what} | {len(f.exponents)} | {', '.join(f.variables)} | {f.rms:.3f} | "
                      f"{f.loo_max:.3f} | x{1 + f.margin:.3f} |")

    print("\n| K_t | features | 3-D / model: least | median | largest | below 0.90 | above 1/0.95 |\n|---|---|---:|---:|---:|---:|---:|")
    for name, table in tables.items():
        kts = [table.fit(FAMILY, q) for q in fits.KT if table.fit(FAMILY, q) is not None]
        inside = lambda r: all(fits._in_domain(r, f.domain) for f in kts)  # noqa: E731 - a local test
        for which, data in (("near", [r for r in near if inside(r)]), ("far", [r for r in far if inside(r)])):
            print(f"| {name} | {which} | " + readings(data, [max(float(f(r)) for f in kts) for r in data]) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
