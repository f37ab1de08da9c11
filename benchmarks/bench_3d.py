"""Do the designs fpdesign reports hold in 3-D? The optimiser's answer, checked by ``verify``.

For every optimiser example and the feasible specs of the bench suite (generated from a seed),
the design that ``optimize`` reports *without* ``--verify`` is checked with the 3-D check
(``fpdesign verify``, normal mesh by default), and the fixed-design examples are checked as
``evaluate`` reports them. Printed per design: the 3-D/model ratios of the gauge strains, the
free-end deflection and the peak stress (at the features: to the model's K_t times the nominal), and
the limits the 3-D figures break. Run by hand:

    python benchmarks/bench_3d.py [--count 40] [--seed 0] [--mesh normal] [-o benchmarks/bench_3d.md]

With ``--perturbed N`` the specs are instead N of the optimiser examples with one to three of their
figures (load, electronics, limits, targets) each moved by a factor of 10^U(-0.6, 0.6), drawn
from the seed: the neighbourhood of specs users write, where the bench suite's kinds may not
reach (such a run found the round flats' far-flat extra length, docs/model.md §7).

With ``--kinds KIND ...`` only the bench suite's specs of those kinds are checked, of every seed
given (``--seed 1 2 3``), without the examples: the kilonewton lugs' flats up to 6 gauge grids long
(benchmarks/bench_3d_kilonewton.md).

With ``--designs SECTION+FEATURE ...`` (e.g. ``round+pocket``) only the designs of those families
are checked, the examples' and the specs' of every seed given: a family's designs after its fits
changed (benchmarks/bench_3d_round_flats.md).
"""

from __future__ import annotations

import argparse
import random
import re
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# Acceptance of the issue "designs that hold in 3-D": 3-D/model within these.
STRAIN_TOLERANCE = 0.02
DEFLECTION_TOLERANCE = 0.03
STRESS_TOLERANCE = 0.10


OPTIMISER_EXAMPLES = ("gripper-finger", "weigh-bar", "probe", "prototype-b-optimized")
PERTURBED_KEYS = ("load", "electronics", "limits", "targets")   # the figures that are moved
PERTURBED_SPREAD = 0.6    # each moved by a factor 10^U(-spread, spread)


def perturbed_specs(count: int, seed: int):
    """(name, what was moved, spec text) of ``count`` optimiser examples with figures moved."""
    import yaml

    rng = random.Random(seed)
    examples = {n: yaml.safe_load((ROOT / "examples" / f"{n}.yaml").read_text(encoding="utf-8"))
                for n in OPTIMISER_EXAMPLES}
    for i in range(count):
        name = rng.choice(OPTIMISER_EXAMPLES)
        raw = yaml.safe_load(yaml.safe_dump(examples[name]))
        leaves = [leaf for top in PERTURBED_KEYS for leaf in _numeric_leaves(raw.get(top), top)]
        moved = []
        for _ in range(rng.choice((1, 2, 2, 3))):
            parent, key, path = rng.choice(leaves)
            value, factor = parent[key], 10 ** rng.uniform(-PERTURBED_SPREAD, PERTURBED_SPREAD)
            if isinstance(value, str):
                number, unit = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(.*?)\s*", value).groups()
                parent[key] = f"{float(number) * factor:.4g} {unit}".strip()
            elif isinstance(value, int):
                parent[key] = max(1, round(value * factor))
            else:
                parent[key] = value * factor
            moved.append(f"{path} {value} -> {parent[key]}")
        yield f"{name}~{i:02d}", "; ".join(moved), yaml.safe_dump(raw, sort_keys=False)


def _numeric_leaves(node, path: str):
    """(container, key, path) of every number or quantity ('20 N') under ``node`` at ``path``."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        where = f"{path}[{key}]" if isinstance(node, list) else f"{path}.{key}"
        if isinstance(value, (dict, list)):
            yield from _numeric_leaves(value, where)
        elif (isinstance(value, (int, float)) and not isinstance(value, bool)) or (
                isinstance(value, str) and re.fullmatch(r"\s*[-+0-9.eE]+\s*\S*\s*", value)):
            yield node, key, where


def designs(count: int, seed: int, refused: list, perturbed: int = 0, kinds=(), examples: bool = True):
    """(name, kind, record) for the examples and the generated specs that have a feasible optimum;
    with ``kinds`` (or not ``examples``), the generated specs of those kinds alone."""
    from designer import bench
    from designer.errors import FpdError
    from designer.result.pipeline import DesignOptions, design, evaluate_fixed
    from designer.spec.reader import load_spec, parse_spec_text

    if perturbed:
        for name, moved, text in perturbed_specs(perturbed, seed):
            try:
                result = design(parse_spec_text(text, source=name), DesignOptions(tradeoff=False))
            except FpdError as exc:   # a moved figure the product refuses: said, no design to check
                print(f"{name} ({moved}): refused: {str(exc).splitlines()[0]}", flush=True)
                refused.append(name)
                continue
            if result.status == "optimal":
                yield name, moved, result.record
            else:
                print(f"{name} ({moved}): {result.status}", flush=True)
        return
    for path in [] if kinds or not examples else sorted((ROOT / "examples").glob("*.yaml")):
        spec = load_spec(path)
        if spec.design is not None:
            yield path.stem, "fixed", evaluate_fixed(spec).record
        else:
            yield path.stem, "example", design(spec, DesignOptions(tradeoff=False)).record
    for item in bench.generate_suite(count, seed):
        if item.expected == "infeasible" or (kinds and item.kind not in kinds):
            continue
        try:
            result = design(item.spec, DesignOptions(tradeoff=False))
        except FpdError as exc:  # a generated spec the product refuses (no size to try): no design to check
            print(f"{item.name}: no design: {str(exc).splitlines()[0]}", flush=True)
            refused.append(item.name)
            continue
        if result.status == "optimal":
            yield item.name, item.kind, result.record


def row(name: str, kind: str, record: dict, mesh: str) -> dict:
    from designer.checks.fea import verify_design

    t0 = time.perf_counter()
    v = verify_design(record, mesh=mesh)
    d = record["design"]
    label = f"{d['material']} {d['section']['kind']}+{d['feature']['kind']}"
    # the peak at the features against the model's K_t x nominal; a plain beam's peak (read half
    # a depth or more from the clamp face) against the model's nominal stress at the same place
    if d["feature"]["kind"] != "none" and v.stress_feature_model > 0:
        stress, where = v.stress_feature_fea / v.stress_feature_model, "features"
    else:
        stress, where = v.stress_peak.value / v.stress_model_at_peak, v.stress_peak.where
    return {"name": name, "kind": kind, "design": label, "strain": v.ratios,
            "deflection": v.deflection_fea / v.deflection_model,
            "stress": stress, "where": where, "stress_converged": v.stress_converged,
            # limits the 3-D figures break where the model says they hold; a fixed design's limits
            # that the model already reports broken (the paper's prototypes miss some targets) are
            # listed apart: there the 3-D check agrees with the model
            "failed": [c.name for c in v.limits if not c.satisfied and c.model_satisfied],
            "known": [c.name for c in v.limits if not c.satisfied and not c.model_satisfied],
            "seconds": time.perf_counter() - t0}


def agrees(r: dict) -> bool:
    """Every limit the model says is met holds in 3-D, and the figures agree within the tolerances."""
    return ("error" not in r and all(abs(s - 1) <= STRAIN_TOLERANCE for s in r["strain"]) and abs(r["deflection"] - 1) <= DEFLECTION_TOLERANCE
            and abs(r["stress"] - 1) <= STRESS_TOLERANCE and not r["failed"])


def markdown(rows: list[dict], mesh: str, suite: str = "", refused=(), examples: bool = True) -> str:
    lines = [f"3-D check (`verify --mesh {mesh}`) of the designs fpdesign reports (optimize without --verify)"
             + (f": {'the examples and ' if examples else ''}{suite}" if suite else "") + ".",
             f"Tolerances: gauge strain ±{STRAIN_TOLERANCE:.0%}, deflection ±{DEFLECTION_TOLERANCE:.0%}, "
             f"peak stress ±{STRESS_TOLERANCE:.0%}.", "",
             "| spec | kind | design | gauge strain 3-D/model | deflection | peak stress (where) | limits broken in 3-D "
             "(model: met) | broken in both | agrees | s |",
             "|---|---|---|---|---:|---|---|---|---|---:|"]
    for r in rows:
        if "error" in r:  # the 3-D check could not run: the design does not hold as far as anyone knows
            lines.append(f"| {r['name']} | {r['kind']} | {r['design']} | the 3-D check failed: {r['error']} | | | | | no | |")
            continue
        lines.append(f"| {r['name']} | {r['kind']} | {r['design']} | {', '.join(f'{s:.3f}' for s in r['strain'])} | "
                     f"{r['deflection']:.3f} | {r['stress']:.2f} ({r['where']}) | {', '.join(r['failed']) or '-'} | "
                     f"{', '.join(r.get('known', [])) or '-'} | "
                     f"{'yes' if agrees(r) else 'no'} | {r['seconds']:.1f} |")
    n = sum(agrees(r) for r in rows)
    meet = sum("error" not in r and not r["failed"] for r in rows)
    lines += ["", f"{meet} of {len(rows)} designs meet in 3-D every limit the model says they meet; {n} of them also "
              "agree with the model within the tolerances."]
    if refused:
        lines += ["", f"Generated specs the product refuses as input (no size to try: their message names why), "
                  f"so with no design to check: {', '.join(refused)}."]
    return "\n".join(lines) + "\n"


def _of_seeds(args, refused: list):
    """``designs`` of every seed of ``args.seed``, their names (and those of the specs refused,
    added to ``refused``) prefixed ``sN:`` when there are several seeds; the examples once."""
    for seed in args.seed:
        prefix = f"s{seed}:" if len(args.seed) > 1 else ""
        mine = []
        # the examples once, with the first seed's specs
        for name, kind, record in designs(args.count, seed, mine, args.perturbed, args.kinds,
                                          examples=seed == args.seed[0]):
            yield (prefix if kind not in ("example", "fixed") else "") + name, kind, record
        refused += [prefix + name for name in mine]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=40, help="generated specs of the bench suite [40]: over 20 feasible")
    p.add_argument("--seed", type=int, nargs="+", default=[0], help="the bench suite's seeds [0]")
    p.add_argument("--kinds", nargs="+", default=(), metavar="KIND",
                   help="only the bench suite's specs of these kinds (no examples)")
    p.add_argument("--designs", nargs="+", default=(), metavar="SECTION+FEATURE",
                   help="only the designs of these families, e.g. round+pocket (examples included)")
    p.add_argument("--mesh", default="normal", choices=("coarse", "normal", "fine"))
    p.add_argument("--perturbed", type=int, default=0, metavar="N",
                   help="instead of the bench suite, N optimiser examples with figures moved (seeded)")
    p.add_argument("-o", "--output", type=Path, help="also write the table as markdown")
    args = p.parse_args(argv)
    rows = []
    refused = []
    several = len(args.seed) > 1
    for name, kind, record in _of_seeds(args, refused):
        d = record["design"]
        if args.designs and f"{d['section']['kind']}+{d['feature']['kind']}" not in args.designs:
            continue
        try:
            rows.append(row(name, kind, record, args.mesh))
        except Exception as exc:  # noqa: BLE001 - a benchmark reports every failure
            print(f"{name}: the 3-D check failed: {type(exc).__name__}: {exc}", flush=True)
            rows.append({"name": name, "kind": kind, "design": f"{d['material']} {d['section']['kind']}+"
                         f"{d['feature']['kind']}", "error": f"{type(exc).__name__}: {str(exc).splitlines()[0]}"})
            continue
        r = rows[-1]
        print(f"{name:28s} {r['design']:28s} strain {', '.join(f'{s:.3f}' for s in r['strain'])}  "
              f"deflection {r['deflection']:.3f}  stress {r['stress']:.2f}  "
              f"{'holds and agrees' if agrees(r) else 'breaks ' + ', '.join(r['failed']) if r['failed'] else 'meets every limit, outside the tolerances'}",
              flush=True)
    seeds = ", ".join(map(str, args.seed))
    suite = (f"the feasible specs of the bench suite's {args.count} generated with seed {seeds}" if not args.perturbed
             else f"{args.perturbed} optimiser examples with figures moved (seed {seeds}; the kind column says "
                  "which; those refused or infeasible are left out), instead of the examples themselves")
    if args.kinds:
        suite = (f"the feasible {', '.join(args.kinds)} specs of the bench suite's {args.count} generated with "
                 f"seed{'s' if several else ''} {seeds} (`sN:` names the seed)")
    if args.designs:
        suite += f", of them the {' and '.join(args.designs)} designs"
    text = markdown(rows, args.mesh, suite, refused, examples=not args.kinds)
    print(text)
    if args.output:
        args.output.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
