"""The wire channels' stiffness in 3-D: a series of bars, each solved with and without its channels.

The beam model counts a wire channel as the section less the groove over every span between the
clamp face and the features (docs/model.md §4); in 3-D a channel adds less than beam theory over
those spans says, as if each span were shorter. This series measures by how much, on the sections
the optimiser chooses (GROUPS): rectangles from 0.6 to 8 times as wide as high (the channel cut
in the wide face of a blade) with slots 0.6 or 0.9 of their width, round bars and tubes, with
channels 0.05-0.45 of the face wide and 1.5-15 % of the section deep, and features from half a
size to four sizes apart and from the clamp. Each bar is solved twice (normal mesh), with and
without its channels; what the channels add to the free-end deflection in 3-D is compared with
what beam theory says they add, and ``lambda``, the length by which every channel span (half at
each end) would have to be shorter for beam theory to give the 3-D figure, is solved for. The
same is done on the coarser partner mesh of each solve, to show how far the mesh moves it.

Then it fits ``lambda = k_round D`` on round bars and tubes and ``k_slot h^(1-q) b^q`` on
rectangles (``h`` the height, ``b`` the width of the face the channel is cut in): ``q`` by least
squares on the rectangles' logarithms, each ``k`` the lowest of its family's bars, so that the
model never counts less compliance than 3-D finds (``sections.channel_shortening`` carries the
figures), and shows what the model with the shipped figures counts against 3-D.

Run by hand (about 25 minutes; ``--reuse CSV`` takes the 3-D figures of the bars an earlier run
solved):  python benchmarks/channel_study.py [-o benchmarks/channel_study.md]
(the rows also go to a CSV beside it).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

SIZE = 12e-3         # the section's largest dimension: the width of a flat bar, the height of a tall one, D
ASPECTS = (0.6, 1.0, 2.0, 4.0, 8.0)   # rectangles' width over height
TUBE_WALL = 0.25     # of the diameter
DEPTH = 0.2          # the pockets' depth, of the section size
# (label, shapes (None: all), channel width as a share of the face: rectangles, round bars and tubes,
# channel depth as a share of the section size, slot width as a share of the bar's, Halton points
# per shape, points skipped). A slot's channel enters through the straight part of its end wall:
# at most the slot's width less the end mill (at most 0.6 of the slot), so 0.4 of the slot.
GROUPS = (
    ("main", None, (0.05, 0.22), (0.05, 0.4), (0.04, 0.10), 0.6, 6, 0),
    ("deep, wide", ("rectangle 1:1", "rectangle 4:1", "round", "tube (wall 0.25 D)"), (0.15, 0.35), (0.25, 0.45),
     (0.09, 0.15), 0.9, 5, 6),
    ("shallow", ("rectangle 1:1", "rectangle 4:1", "round", "tube (wall 0.25 D)"), (0.05, 0.2), (0.05, 0.2),
     (0.015, 0.04), 0.6, 5, 11),
    ("wide slots", ("rectangle 1:1", "rectangle 4:1"), (0.1, 0.3), (0.1, 0.3), (0.04, 0.10), 0.9, 4, 16),
)


def shapes(slot: float) -> list[dict]:
    out = []
    for a in ASPECTS:
        b, h = (SIZE, SIZE / a) if a >= 1 else (SIZE * a, SIZE)
        out.append({"name": f"rectangle {a:g}:1", "family": "rectangle-pocket", "width": b, "height": h,
                    "pocket_width": slot * b})
    out.append({"name": "round", "family": "round-pocket", "diameter": SIZE})
    out.append({"name": f"tube (wall {TUBE_WALL:g} D)", "family": "tube-pocket", "diameter": SIZE,
                "wall": TUBE_WALL * SIZE})
    return out


def cases() -> list[tuple[str, object, float, float]]:
    """(shape name, study Case, channel width, channel depth) of the series: per group and shape,
    Halton points over the channel's width (of the face it is cut in), its depth (of the section
    size), the gap between the features and the first feature's distance from the clamp (both in
    the section's largest dimension)."""
    from designer.checks.study import Case, halton

    out = []
    for _, only, rect_w, round_w, t, slot, points, skip in GROUPS:
        for shape in shapes(slot):
            name = shape.pop("name")
            if only is not None and name not in only:
                continue
            rect = shape["family"].startswith("rectangle")
            face = shape["width"] if rect else shape["diameter"]
            size = shape["height"] if rect else shape["diameter"]
            w_lo, w_hi = rect_w if rect else round_w
            for u in halton(skip + points, 4)[skip:]:
                width = face * (w_lo + (w_hi - w_lo) * u[0])
                depth = size * (t[0] + (t[1] - t[0]) * u[1])
                out.append((name, Case(**shape, depth=DEPTH * size, gap=(0.5 + 3.5 * u[2]) * SIZE / max(size, face),
                                       clamp_clearance=(0.3 + 1.7 * u[3]) * SIZE), width, depth))
    return out


def spec_text(case, width: float, depth: float, channels: bool) -> str:
    """The study case's spec with its channels ``width`` x ``depth`` (m), or none."""
    cad = (f"cad: {{corner_radius: {case.corner_radius * 1e3:.6g} mm, wire_channels: {str(channels).lower()}, "
           f"channel_width: {width * 1e3:.6g} mm, channel_depth: {depth * 1e3:.6g} mm}}")
    text = case.spec_text()
    start = text.index("cad: {")
    return text[:start] + cad + text[text.index("\n", start):]


def shortening(model, added: float) -> float:
    """``lambda`` for which beam theory with every channel span shorter by it gives ``added``; 0
    where beam theory gives less already."""
    from scipy.optimize import brentq

    beam = model.added()
    return brentq(lambda s: model.added(s) - added, 0.0, model.length) if 0 < added < beam else 0.0


def key(name: str, case, width: float, depth: float) -> str:
    """A case's name in the CSV, so that a later run can take its 3-D figures (``--reuse``)."""
    return f"{name}|{width * 1e6:.1f}|{depth * 1e6:.1f}|{case.gap:.4f}|{case.clamp_clearance * 1e6:.1f}"


def run(name: str, case, width: float, depth: float, solved: dict | None = None) -> dict:
    """One bar of the series: solved in 3-D with and without its channels (or its 3-D figures
    from ``solved``, a row of an earlier run), and the beam model's figures."""
    from channel_check import ChannelModel

    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    t0 = time.perf_counter()
    record = evaluate_fixed(parse_spec_text(spec_text(case, width, depth, True), source=case.family)).record
    if solved is None:
        from designer.checks.fea import verify_design

        bare = evaluate_fixed(parse_spec_text(spec_text(case, width, depth, False), source=case.family)).record
        cut, plain = verify_design(record, mesh="normal"), verify_design(bare, mesh="normal")
        added, added_coarse = cut.deflection_fea - plain.deflection_fea, cut.deflection_coarse - plain.deflection_coarse
        seconds = time.perf_counter() - t0
    else:
        added, added_coarse, seconds = (float(solved[k]) for k in ("added_fea", "added_coarse", "seconds"))
    m = ChannelModel(record)
    spans = [b - a for a, b in m.spans]
    return {"key": key(name, case, width, depth), "shape": name, "size": m.size, "face": m.width,
            "slot": case.pocket_width / case.width if case.width else 1.0,
            "channel_width": width, "channel_depth": depth, "share": m.share, "first_span": spans[0],
            "second_span": spans[1], "added_fea": added, "added_coarse": added_coarse, "ratio": added / m.added(),
            "lambda": shortening(m, added), "lambda_coarse": shortening(m, added_coarse),
            "model_ratio": added / m.model, "model_lambda": m.model_lambda, "seconds": seconds}


def fit(rows: list[dict]) -> tuple[float, float, float]:
    """``(k_round, k_slot, q)``: ``lambda = k_round D`` on round bars and tubes, ``k_slot s^(1-q)
    b^q`` on rectangles; ``q`` by least squares on the rectangles' logarithms, each ``k`` the
    lowest of its family's rows."""
    import numpy as np

    rect = [r for r in rows if r["shape"].startswith("rectangle")]
    aspect = np.log([r["face"] / r["size"] for r in rect])
    y = np.log([r["lambda"] / r["size"] for r in rect])
    q = float(np.polyfit(aspect, y, 1)[0])
    k_slot = min(r["lambda"] / (r["size"] ** (1 - q) * r["face"] ** q) for r in rect)
    k_round = min(r["lambda"] / r["size"] for r in rows if not r["shape"].startswith("rectangle"))
    return k_round, k_slot, q


def markdown(rows: list[dict]) -> str:
    from designer.model import sections

    k_round, k_slot, q = fit(rows)
    ship = (sections.CHANNEL_SHORTENING_ROUND, sections.CHANNEL_SHORTENING_SLOT, sections.CHANNEL_SHORTENING_EXPONENT)
    lines = ["Wire channels in 3-D: a series of bars (`python benchmarks/channel_study.py`; normal mesh), each solved "
             "with and without its channels. *3-D / beam theory* is what the channels add to the free-end deflection "
             "in 3-D over what beam theory says over the whole spans where they are cut; *lambda* the length by "
             "which every channel span (from the clamp face to the first pocket and between pockets; half at each "
             "end) would have to be shorter for beam theory to give the 3-D figure (and on the coarser partner "
             "mesh); *3-D / model* what the channels add in 3-D over what the beam model counts "
             f"(`sections.channel_shortening`: lambda = {ship[0]:g} D on round bars and tubes, "
             f"{ship[1]:g} h^{1 - ship[2]:.2f} b^{ship[2]:g} on rectangles, h the height, b the width of the face the "
             "channel is cut in). Slot: the slot's width over the bar's.", "",
             "| bar | slot | channel width / face | channel depth / size | channels' share of I | spans / size | "
             "3-D / beam theory | lambda / size | (coarse mesh) | model's lambda / size | 3-D / model | s |",
             "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['shape']} | {r['slot']:.1f} | {r['channel_width'] / r['face']:.3f} | "
                     f"{r['channel_depth'] / r['size']:.3f} | {r['share']:.1%} | {r['first_span'] / r['size']:.2f}, "
                     f"{r['second_span'] / r['size']:.2f} | {r['ratio']:.3f} | {r['lambda'] / r['size']:.3f} | "
                     f"{r['lambda_coarse'] / r['size']:.3f} | {r['model_lambda'] / r['size']:.3f} | "
                     f"{r['model_ratio']:.3f} | {r['seconds']:.0f} |")
    ratios = sorted(r["model_ratio"] for r in rows)
    lines += ["", f"Fit: q = {q:.3f} (least squares on the rectangles' log lambda/h against log b/h); the lowest "
              f"factor of the round bars and tubes {k_round:.3f}, of the rectangles {k_slot:.3f} ({len(rows)} bars). "
              f"Shipped: {ship[0]:g}, {ship[1]:g}, q = {ship[2]:g}. The channels add in 3-D {ratios[0]:.3f}-"
              f"{ratios[-1]:.3f} of what the model counts (median {ratios[len(ratios) // 2]:.3f}); beam theory over "
              f"the whole spans counts {1 / max(r['ratio'] for r in rows):.2f}-{1 / min(r['ratio'] for r in rows):.2f} "
              "times the 3-D figure."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "benchmarks" / "channel_study.md")
    parser.add_argument("--reuse", type=Path, metavar="CSV",
                        help="take the 3-D figures of the bars already in this CSV of an earlier run")
    args = parser.parse_args(argv)
    solved = {}
    if args.reuse is not None:
        import csv

        with open(args.reuse, newline="", encoding="utf-8") as fh:
            solved = {r["key"]: r for r in csv.DictReader(fh)}
    rows = []
    for item in cases():
        r = run(*item, solved.get(key(*item)))
        rows.append(r)
        print(f"{r['shape']:18s} w/face {r['channel_width'] / r['face']:.3f} t/size {r['channel_depth'] / r['size']:.3f} "
              f"share {r['share']:.3f} spans {r['first_span'] / r['size']:.2f} {r['second_span'] / r['size']:.2f} "
              f"3-D/beam {r['ratio']:.3f} lambda/size {r['lambda'] / r['size']:.3f} "
              f"(coarse {r['lambda_coarse'] / r['size']:.3f}) 3-D/model {r['model_ratio']:.3f} {r['seconds']:.0f} s",
              flush=True)
    from designer.outputs.files import atomic_write_text

    keys = list(rows[0])
    lines = [",".join(keys)] + [",".join(f"{r[k]:.6g}" if isinstance(r[k], float) else str(r[k]) for k in keys)
                                for r in rows]
    atomic_write_text(args.output.with_suffix(".csv"), "\n".join(lines) + "\n")
    text = markdown(rows)
    print(text)
    atomic_write_text(args.output, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
