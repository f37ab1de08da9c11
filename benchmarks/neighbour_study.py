"""Three stations: what each station's gauge strain loses to its neighbouring features, in 3-D.

The pocket fits (docs/model.md §7) are of isolated features, and the limit ``pocket_gap_i`` keeps
neighbouring slots and round flats half a section size apart end to end (``limits.POCKET_GAP``),
set by pairs (benchmarks/feature_gap_study.md). With three stations the middle feature has a
neighbour on each side. This study measures, on single-axis bars with three features ``gap``
sizes apart, each station's 3-D/model gauge strain (``biaxial_strain.measure``: ``verify``'s
solve on one mesh level, F along -Z) over the same bar's with its features 4 sizes apart (as the
corrections' study), and lists the model's room under its accuracy targets (``u_eps``,
``corrections.strain_allowance``) beside it.

The bars are ``biaxial_peak``'s bases with one axis (7075-T6, the BF350-3AA gauge, 20 N): Ø18.3 mm
round bars with flats (as the fits' X1; the flat as wide as the bar lets it be) and 8.5 mm square
bars with 5.5 mm wide slots; feature length over size 0.41-1.0 (flats) and 1.05-1.65 (slots,
whose fits start at 0.9 and whose gauge backing needs 8.9 mm), depth over size 0.06-0.28. The
first feature starts 5 mm from the clamp; the load range starts 7 mm past the last feature and
ends 67 mm past it (where ``verify`` loads). Every run is kept in a JSON cache, so an interrupted
study resumes and ``--table`` rewrites the table from the cache alone. Run by hand (one FEA job
at a time; 15-70 s a run on the normal mesh):

    python benchmarks/neighbour_study.py [--mesh normal] [--only round rect] [--fine KEY ...]
        [--table] [--cache benchmarks/neighbour_study.json] [-o benchmarks/neighbour_study.md]
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from biaxial_peak import _chord
from biaxial_peak import design as peak_design

ISOLATED = 4.0             # sizes apart: as the corrections' study, the reference
GAPS = (0.5, 0.75, 1.0)    # 0.5: the closest pocket_gap_i allows
# family: (base design, size in mm, lengths over size, depths over size) of the full grid
FAMILIES = {"round": ("R1", 18.3, (0.45, 0.6, 1.0), (0.11, 0.06)),
            "rect": ("Q1", 8.5, (1.05, 1.65), (0.118, 0.059))}
# past the grid: the shortest deep flat (7.5 mm), the deepest flats and slots the limits allow
# (max_pocket_fraction 0.3) and a deep slot as short as the gauge backing lets it be (8.9 mm)
BOUNDING = [("round", 0.41, 0.16), ("rect", 1.05, 0.18), ("round", 0.45, 0.25), ("rect", 1.05, 0.28)]
PARTIAL = [("round", 0.6, 0.16, g) for g in (ISOLATED, 0.5)] + [("rect", 1.65, 0.28, g) for g in (ISOLATED, 0.5)]


def key(fam: str, length: float, depth: float, gap: float) -> str:
    return f"{fam}/l{length:g}/p{depth:g}/g{gap:g}"


def cases(only=()) -> list[tuple]:
    """``(family, length/size, depth/size, gap/size)`` of every run, isolated first."""
    out = [(fam, lr, dr, gap) for fam, (_, _, lengths, depths) in FAMILIES.items()
           for dr in depths for lr in lengths for gap in (ISOLATED, *GAPS)]
    out += [(fam, lr, dr, gap) for fam, lr, dr in BOUNDING for gap in (ISOLATED, *GAPS)] + PARTIAL
    return [c for c in out if not only or c[0] in only]


def record(fam: str, length: float, depth: float, gap: float) -> dict:
    """The design.json record of a case: three features ``gap`` sizes apart, one axis."""
    base, size, _, _ = FAMILIES[fam]
    rec = copy.deepcopy(peak_design(base))
    d, spec = rec["design"], rec["spec"]
    l_f, p = round(length * size, 2), round(depth * size, 2)
    if fam == "round":
        d["section"]["diameter"] = size / 1e3
        d["feature"]["width"] = _chord(size, p) / 1e3
    d["feature"]["depth"], d["feature"]["length"] = p / 1e3, l_f / 1e3
    first = 5.0 + l_f / 2 + 0.01
    stations = [first + i * (l_f + gap * size) for i in range(3)]
    end = stations[-1] + l_f / 2
    d["stations"] = [s / 1e3 for s in stations]
    d["length"] = round((end + 72) / 1e3, 5)
    d["axes"] = spec["axes"] = 1
    spec["stations"] = 3
    spec["load"]["position"] = [round((end + 7) / 1e3, 5), round((end + 67) / 1e3, 5)]
    return rec


def model_figures(rec: dict) -> dict:
    """The model's room ``u_eps`` and the family's own strain fit ``C_eps`` at the case."""
    from designer.model import corrections
    from designer.result.designfile import parse_design

    g = parse_design(rec).design.geometry
    table = corrections.load()
    fit = table.fit(corrections.family(g), "strain")
    return {"u_eps": float(corrections.strain_allowance(g, table)),
            "c_eps": float(fit(corrections.parameters(g))) if fit is not None else 1.0}


def _ratios(run: dict) -> list[float]:
    return [f / m for f, m in zip(run["fea"], run["model"])]


def _losses(cache: dict, case: tuple, mesh: str) -> list[float] | None:
    """Each station's loss against the isolated case, ``1 - (3-D/model) / (3-D/model isolated)``."""
    near, alone = cache.get(f"{key(*case)}/{mesh}"), cache.get(f"{key(*case[:3], ISOLATED)}/{mesh}")
    if near is None or alone is None:
        return None
    return [1 - a / b for a, b in zip(_ratios(near), _ratios(alone))]


def slot_law(cache: dict, mesh: str) -> str:
    """The slots' losses against ``a (p/h) exp(-m l/h) S``, ``S`` the sum over a station's
    neighbours of ``exp(-k gap/h)`` (the far neighbour of an outer station at ``2 gap + l``)."""
    import numpy as np
    from scipy.optimize import least_squares

    rows = []
    for case in cases(["rect"]):
        run = cache.get(f"{key(*case)}/{mesh}")
        loss = _losses(cache, case, mesh) if case[3] != ISOLATED else None
        if loss is None:
            continue
        lr, dr, gap = run["length"] / run["size"], run["depth"] / run["size"], case[3]
        rows += [(lr, dr, [gap, gap] if i == 1 else [gap, 2 * gap + lr], value) for i, value in enumerate(loss)]
    if len(rows) < 4:
        return ""
    y = np.array([r[3] for r in rows])

    def law(q):
        a, k, m = q
        return np.array([a * dr * math.exp(-m * lr) * sum(math.exp(-k * g) for g in gaps) for lr, dr, gaps, _ in rows])

    q = least_squares(lambda q: law(q) - y, [0.5, 4.0, 2.0]).x
    e = law(q) - y
    return (f"Slots ({len(rows)} stations): loss = a (p/h) exp(-m l/h) sum exp(-k gap/h), a {q[0]:.3g}, k {q[1]:.3g}, "
            f"m {q[2]:.3g}: rms {np.sqrt(np.mean(e ** 2)) * 100:.3f} %, largest {np.max(np.abs(e)) * 100:.3f} % "
            f"(no law: rms {np.sqrt(np.mean(y ** 2)) * 100:.3f} %, largest {np.max(np.abs(y)) * 100:.3f} %).")


def table(cache: dict, mesh: str) -> str:
    out = [f"Three stations, each feature `gap` sizes from its neighbours (`python benchmarks/neighbour_study.py`, "
           f"{mesh} mesh): each station's 3-D/model gauge strain and its loss against the same bar with its "
           f"features {ISOLATED:g} sizes apart (positive: the gauge reads less); `u_eps` is the model's room under the "
           "accuracy targets for the fits' own error.", "",
           "| family | l/size | p/size | C_eps | u_eps | gap (sizes) | 3-D/model 1, 2, 3 | loss 1, 2, 3 |",
           "|---|---:|---:|---:|---:|---:|---|---|"]
    for case in cases():
        run = cache.get(f"{key(*case)}/{mesh}")
        if run is None:
            continue
        loss = _losses(cache, case, mesh) if case[3] != ISOLATED else None
        out.append(f"| {case[0]} | {run['length'] / run['size']:.3f} | {run['depth'] / run['size']:.3f} | "
                   f"{run['c_eps']:.4f} | {run['u_eps']:.4f} | {case[3]:g} | "
                   + ", ".join(f"{r:.4f}" for r in _ratios(run)) + " | "
                   + (", ".join(f"{x * 100:+.2f} %" for x in loss) if loss else "-") + " |")
    fine = [case for case in cases() if case[3] != ISOLATED and _losses(cache, case, "fine")]
    if fine:
        out += ["", f"On the fine mesh, where both runs were made (the {mesh} mesh's loss beside it):", ""]
        out += [f"- {key(*case)}: " + ", ".join(f"{x * 100:+.2f} %" for x in _losses(cache, case, "fine"))
                + f" ({mesh}: " + ", ".join(f"{x * 100:+.2f} %" for x in _losses(cache, case, mesh)) + ")"
                for case in fine]
    out.append("")
    for fam in FAMILIES:     # at the closest gap the limits allow, each station's best-resolved figures
        closest = [c for c in cases([fam]) if c[3] == GAPS[0] and f"{key(*c)}/{mesh}" in cache]
        if not closest:
            continue
        best = {c: "fine" if _losses(cache, c, "fine") else mesh for c in closest}
        least = min(min(_ratios(cache[f"{key(*c)}/{m}"])) for c, m in best.items())
        most = max(max(_losses(cache, c, m) or [0.0]) for c, m in best.items())
        room = min(cache[f"{key(*c)}/{mesh}"]["u_eps"] for c in closest)
        out.append(f"- {fam}, {GAPS[0]:g} sizes apart (the closest `pocket_gap_i` allows; fine mesh where solved): "
                   f"3-D/model at least {least:.4f}, loss at most {most * 100:.2f} %, against a room u_eps of "
                   f"{room * 100:.2f} %.")
    law = slot_law(cache, mesh)
    return "\n".join(out + (["", law] if law else [])) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    p.add_argument("--only", nargs="+", default=(), choices=tuple(FAMILIES))
    p.add_argument("--fine", nargs="+", default=(), metavar="KEY", help="cases (e.g. round/l0.45/p0.11/g0.5) "
                   "to solve on the fine mesh too")
    p.add_argument("--table", action="store_true", help="only rewrite the table from the cache")
    p.add_argument("--cache", type=Path, default=HERE / "neighbour_study.json")
    p.add_argument("-o", "--output", type=Path, help="also write the table as markdown")
    args = p.parse_args()
    cache = json.loads(args.cache.read_text()) if args.cache.exists() else {}
    todo = [] if args.table else [(c, args.mesh) for c in cases(args.only)]
    for text in args.fine:
        fam, length, depth, gap = text.split("/")
        todo.append(((fam, float(length[1:]), float(depth[1:]), float(gap[1:])), "fine"))
    for case, mesh in todo:
        name = f"{key(*case)}/{mesh}"
        if name in cache:
            continue
        from biaxial_strain import measure

        rec = record(*case)
        cache[name] = {**measure(rec, mesh), **model_figures(rec)}
        args.cache.write_text(json.dumps(cache, indent=1))
        print(name, ", ".join(f"{r:.4f}" for r in _ratios(cache[name])), flush=True)
    text = table(cache, args.mesh)
    print(text)
    if args.output:
        args.output.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
