"""How stiff are the wire channels in 3-D? The 3-D check of designs with and without their channels.

The beam model counts a wire channel (docs/model.md §4, ``sections.channel_inertia``) as the
section less the groove over every span between the clamp face and the features, each span
shortened by ``sections.channel_shortening`` (fitted in benchmarks/channel_study.md). For
miniature designs of the bench suite (seed 4), where the default channel is a large share of the
section, and variants of them (other channel sizes, stations further apart), this solves each
design twice in 3-D (normal mesh), with and without its channels, and prints what the channels
add to the free-end deflection in 3-D over what beam theory over the whole spans says they add
and over what the model counts, their share of the model's deflection, the whole design's
3-D/model deflection ratio, and the length ``lambda`` by which each channel span (from the clamp
face and between features, ``lambda/2`` at each end) would have to be shorter for beam theory to
give the 3-D figure, beside the model's. Run by hand (about 5 minutes):

    python benchmarks/channel_check.py [-o benchmarks/channel_check.md]
"""

from __future__ import annotations

import argparse
import copy
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SEED, COUNT = 4, 50
# (spec of the suite, what is changed, changes): channel width and depth (m, None: the default),
# stations (m, None: the design's), and a longer beam with the load further out.
VARIANTS = {
    "005-short-beam": [
        ("as designed", {}),
        ("load at 12-15 mm", {"far": True}),
        ("load at 12-15 mm, stations 2, 6 mm", {"far": True, "stations": [2e-3, 6e-3]}),
        ("load at 12-15 mm, stations 2, 9.5 mm", {"far": True, "stations": [2e-3, 9.5e-3]}),
        ("load at 12-15 mm, channel 0.25 mm wide", {"far": True, "width": 0.25e-3}),
        ("load at 12-15 mm, stations 2, 6 mm, channel 0.25 mm wide",
         {"far": True, "stations": [2e-3, 6e-3], "width": 0.25e-3}),
        ("load at 12-15 mm, stations 2, 6 mm, channel 0.05 mm deep",
         {"far": True, "stations": [2e-3, 6e-3], "depth": 0.05e-3}),
    ],
    "001-millinewton": [("as designed", {})],
}


def designed() -> dict:
    """The reported design.json record of each spec of VARIANTS (the suite's optimum)."""
    from designer import bench
    from designer.result.pipeline import DesignOptions, design

    out = {}
    for item in bench.generate_suite(COUNT, SEED):
        if item.name in VARIANTS:
            out[item.name] = design(item.spec, DesignOptions(tradeoff=False)).record
    return out


def variant(record: dict, change: dict, channels: bool) -> dict:
    v = copy.deepcopy(record)
    cad = v["spec"]["cad"]
    cad["wire_channels"] = channels
    if "width" in change:
        cad["channel_width"] = change["width"]
    if "depth" in change:
        cad["channel_depth"] = change["depth"]
    if change.get("far"):   # the 005-short-beam bar, 1.58 mm across, made 15.5 mm long
        v["design"]["length"] = 15.5e-3
        v["spec"]["load"]["position"] = [12e-3, 15e-3]
    if "stations" in change:
        v["design"]["stations"] = change["stations"]
    return v


class ChannelModel:
    """The beam model's figures of a design.json ``record``, evaluated once: its whole free-end
    deflection, the channels' share of the second moment, the section's size and the width of the
    face the channels are cut in (m), ``added``: what the channels add to the deflection by beam
    theory over the spans where they are cut, and ``model``: what the beam model counts for them
    (``model.channel_deflection``: the spans shortened by ``sections.channel_shortening``)."""

    def __init__(self, record: dict):
        from designer import model
        from designer.model import sections
        from designer.result.designfile import parse_design
        from designer.result.evaluation import evaluate

        rec = parse_design(record)
        spec, design = rec.spec, rec.design
        ev = evaluate(design, spec)
        g, sp, E = design.geometry, ev.analysis.props, float(design.material.E)
        cut = float(sections.channel_inertia(g))
        self.force, self.x, self.length = spec.load.force_max, spec.load.position_max, float(g.length)
        self.softening = 1 / (E * (float(sp.I) - cut)) - 1 / (E * float(sp.I))
        self.spans = [(float(a), float(b)) for a, b in sections.channel_spans(g, shortened=False)]
        self.model = float(model.channel_deflection(g, sp, E, self.force, self.x))
        self.model_lambda = float(sections.channel_shortening(g))
        self.deflection, self.share = float(ev.analysis.deflection), cut / float(sp.I)
        self.size = float(g.size)
        self.width = float(g.width if g.section == "rectangle" else g.diameter)

    def added(self, shorter: float = 0.0) -> float:
        """What the channels add to the free-end deflection by beam theory with each span where they
        are cut ``shorter`` by ``shorter/2`` at each end, m."""
        from designer.model.beam import _moment_arm_integral

        total = 0.0
        for a, b in self.spans:
            a, b = a + shorter / 2, b - shorter / 2
            if b > a:
                total += _moment_arm_integral(b, self.x, self.length) - _moment_arm_integral(a, self.x, self.length)
        return self.force * self.softening * total


def row(name: str, label: str, record: dict, change: dict) -> dict:
    from scipy.optimize import brentq

    from designer.checks.fea import verify_design

    t0 = time.perf_counter()
    with_channels = variant(record, change, True)
    v = verify_design(with_channels, mesh="normal")
    bare = verify_design(variant(record, change, False), mesh="normal")
    fea = v.deflection_fea - bare.deflection_fea
    m = ChannelModel(with_channels)
    beam = m.added()
    # the shortening for which beam theory gives the 3-D figure (0 where it gives less already)
    shorter = brentq(lambda s: m.added(s) - fea, 0.0, m.length) if 0 < fea < beam else 0.0
    d = with_channels["design"]
    return {"name": name, "label": label, "design": f"{d['material']} {d['section']['kind']}+{d['feature']['kind']}",
            "stations": d["stations"], "share": m.share, "of_deflection": beam / m.deflection, "ratio": fea / beam,
            "deflection": v.deflection_fea / v.deflection_model, "shorter": shorter, "size": m.size,
            "model_ratio": fea / m.model if m.model else float("nan"),
            "model_shorter": m.model_lambda,
            "width": m.width, "seconds": time.perf_counter() - t0}


def markdown(rows: list[dict]) -> str:
    lines = ["Wire channels in 3-D (`python benchmarks/channel_check.py`; normal mesh): each design solved with and "
             "without its channels. *3-D / beam theory* is what the channels add to the free-end deflection in 3-D "
             "over what beam theory says they add over the whole spans where they are cut; *3-D / model* the same "
             "over what the beam model counts (the spans shortened by `sections.channel_shortening`); *lambda* the "
             "length by which every channel span would have to be shorter (half at each end) for beam theory to give "
             "the 3-D figure, in mm and in section sizes (the height or diameter), beside the model's.", "",
             "| spec (bench suite, seed 4) | variant | design | stations (mm) | channels' share of I | of the model's "
             "deflection | 3-D / beam theory | 3-D / model | whole deflection 3-D / model | lambda (mm) | "
             "lambda / size | model's lambda (mm) | s |",
             "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['name']} | {r['label']} | {r['design']} | {', '.join(f'{s * 1e3:g}' for s in r['stations'])} | "
                     f"{r['share']:.1%} | {r['of_deflection']:.1%} | {r['ratio']:.3f} | {r['model_ratio']:.3f} | "
                     f"{r['deflection']:.3f} | {r['shorter'] * 1e3:.2f} | {r['shorter'] / r['size']:.2f} | "
                     f"{r['model_shorter'] * 1e3:.2f} | {r['seconds']:.0f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, help="also write the table as markdown")
    args = parser.parse_args(argv)
    records = designed()
    rows = []
    for name, variants in VARIANTS.items():
        for label, change in variants:
            r = row(name, label, records[name], change)
            rows.append(r)
            print(f"{name:16s} {label:58s} share {r['share']:.3f} of defl {r['of_deflection']:.3f} "
                  f"3-D/beam {r['ratio']:.3f} 3-D/model {r['model_ratio']:.3f} whole {r['deflection']:.3f} lambda {r['shorter'] * 1e3:.2f} mm", flush=True)
    text = markdown(rows)
    print(text)
    if args.output:
        from designer.outputs.files import atomic_write_text

        atomic_write_text(args.output, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
