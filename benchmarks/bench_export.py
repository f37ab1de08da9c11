"""Time ``fpdesign export`` on the CAD test designs (run by hand: ``python benchmarks/bench_export.py``).

Prints, per design, the median over ``--repeat`` runs of: building the solid, writing STEP,
writing STL, the whole ``export --step --stl`` call, the drawing (SVG and PNG) and the 3-D
picture. Imports (cadquery, matplotlib) are timed once, before, and are not in the medians.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per measurement (median reported)")
    parser.add_argument("designs", nargs="*", help="design.json files (default: tests/data/cad_*.json)")
    args = parser.parse_args(argv)
    paths = [Path(p) for p in args.designs] or sorted((ROOT / "tests" / "data").glob("cad_*.json"))

    t0 = time.perf_counter()
    import cadquery  # noqa: F401
    t_cq = time.perf_counter() - t0
    t0 = time.perf_counter()
    import matplotlib.figure  # noqa: F401
    t_mpl = time.perf_counter() - t0
    from designer.outputs.cad.beam import resolve
    from designer.outputs.cad.mesh import model_meshes
    from designer.outputs.cad.solid import build_solid
    from designer.outputs.cad.step import write_step, write_stl
    from designer.outputs.cad.writer import export
    from designer.outputs.drawing.figures import save_figure
    from designer.outputs.drawing.picture import plot_model
    from designer.outputs.drawing.sheet import plot_drawing
    from designer.result.designfile import load_design

    print(f"import cadquery {t_cq:.2f} s, matplotlib {t_mpl:.2f} s (once per process, not below)")
    print(f"median of {args.repeat} runs, seconds")
    header = f"{'design':28s} {'solid':>6s} {'STEP':>6s} {'STL':>6s} {'export':>7s} {'drawing':>8s} {'picture':>8s}"
    print(header)
    print("-" * len(header))
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        # warm up: fonts, OCCT statics
        record = load_design(paths[0])
        export(record, step=out / "w.step", svg=out / "w.svg", png=out / "w.png")
        for path in paths:
            record = load_design(path)
            beam = resolve(record)
            solid = build_solid(beam)
            t_solid = median_time(lambda: build_solid(resolve(record)), args.repeat)
            t_step = median_time(lambda: write_step(solid, out / "b.step", beam.name), args.repeat)
            t_stl = median_time(lambda: write_stl(solid, out / "b.stl"), args.repeat)
            t_export = median_time(lambda: export(record, step=out / "e.step", stl=out / "e.stl"), args.repeat)

            def draw():
                fig = plot_drawing(beam)
                save_figure(fig, out / "d.svg", "svg")
                save_figure(fig, out / "d.png", "png")

            def picture():
                fig = plot_model(model_meshes(beam, solid), beam)
                save_figure(fig, out / "p.png", "png")

            t_draw = median_time(draw, args.repeat)
            t_pic = median_time(picture, args.repeat)
            name = path.stem.removeprefix("cad_")
            print(f"{name:28s} {t_solid:6.2f} {t_step:6.2f} {t_stl:6.2f} {t_export:7.2f} {t_draw:8.2f} {t_pic:8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
