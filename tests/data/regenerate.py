"""Rebuild every file in tests/data from the examples in examples/.

    python tests/data/regenerate.py                    # rewrite tests/data
    python tests/data/regenerate.py -o DIR             # write into DIR instead
    python tests/data/regenerate.py -o DIR --compare   # and compare each file with tests/data

How each file is made:

- plot_prototype_b.json, plot_prototype_c.json: ``fpdesign evaluate examples/prototype-{b,c}.yaml
  --no-cad --no-plots``; its design.json without the "files" list, numbers to 10 significant
  digits.
- plot_optimized.json: ``fpdesign optimize --no-cad --no-plots`` of examples/prototype-b.yaml
  without its design: block, renamed prototype-b-search (all 9 materials x 3 section families);
  the same two edits.
- plot_tradeoff.json: that spec solved again (library, designer.search) with
  limits.max_deflection of 1, 2, 3, 5, 8 and 12 mm, and with limits.min_frequency of 20, 30,
  45, 60, 80 and 100 Hz; every candidate of every solve is a point (material, section family,
  the limit in SI, its error ratio, feasible), numbers to 10 significant digits.
- cal_prototype_{a,b,c}.json: the fixed designs of examples/prototype-{a,b,c}.yaml with the loads
  of the paper's Table 2 (Prototype B: 20-3000 g, and its three bridges of Table 1 at 20, 60 and
  100 mm), the catalogue's BF120-3AA gauge and targets of 5 % and 5 mm, evaluated by the library
  (designer.result.evaluation); kept: the spec without limits, the design, and the predictions a
  calibration reads (errors, sensitivity, noise voltage, gauge strain), at full precision; the
  gauge without its grid size; a note on the assumed electronics instead of the messages.
- cad_*.json: the designs the CAD tests build: Prototypes A, B (three bridges, 20-3000 g), C and C
  with 0.65 mm flats from examples/prototype-*.yaml, and four more below, all with the
  electronics of examples/prototype-b.yaml, the BF120-3AA gauge, default limits (C keeps its zero
  load clearance and tip margin), targets of 3 % and 20 mm and the listed cad: options; no
  predictions or limits (the CAD reads the geometry only), a note saying what each is.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import io
import json
import math
import sys
import tempfile
from pathlib import Path

import yaml

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
EXAMPLES = ROOT / "examples"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))  # the source tree, as the tests use it

from designer.cli import main  # noqa: E402
from designer.result.evaluation import evaluate, fixed_design  # noqa: E402
from designer.result.record import build_record  # noqa: E402
from designer import search  # noqa: E402
from designer.spec.reader import parse_spec  # noqa: E402

DIGITS = 10  # significant digits of the plot and CAD fixtures
GAUGE_GRID = ("grid_length", "grid_width")


def example(name: str) -> dict:
    return yaml.safe_load((EXAMPLES / f"{name}.yaml").read_text(encoding="utf-8"))


def significant(value, digits: int = DIGITS):
    """``value`` with every float rounded to ``digits`` significant digits."""
    if isinstance(value, float):
        return float(f"{value:.{digits}g}") if math.isfinite(value) else value
    if isinstance(value, dict):
        return {k: significant(v, digits) for k, v in value.items()}
    if isinstance(value, list):
        return [significant(v, digits) for v in value]
    return value


def command_record(argv: list[str]) -> dict:
    """design.json of ``fpdesign <argv> -o <scratch> --no-cad --no-plots``, without its "files" list."""
    with tempfile.TemporaryDirectory() as scratch:
        out = Path(scratch) / "out"
        with contextlib.redirect_stdout(io.StringIO()):
            code = main([*argv, "-o", str(out), "--no-cad", "--no-plots"])
        if code not in (0, 1):
            raise SystemExit(f"fpdesign {' '.join(argv)}: exit {code}")
        record = json.loads((out / "design.json").read_text(encoding="utf-8"))
    record.pop("files", None)
    return record


def evaluated(raw: dict):
    """(spec, design.json record) of a spec dictionary with a design: block, by the library."""
    spec = parse_spec(raw)
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    return spec, ev, json.loads(json.dumps(build_record("feasible", spec, ev)))


def without(mapping: dict, keys) -> dict:
    return {k: v for k, v in mapping.items() if k not in keys}


# ----------------------------------------------------------------------------- plot fixtures

def search_spec() -> dict:
    """examples/prototype-b.yaml as a search: no design: block."""
    raw = example("prototype-b")
    raw.pop("design")
    raw["name"] = "prototype-b-search"
    return raw


def plot_evaluated(name: str) -> dict:
    return significant(command_record(["evaluate", str(EXAMPLES / f"{name}.yaml")]))


def plot_optimized() -> dict:
    with tempfile.TemporaryDirectory() as scratch:
        path = Path(scratch) / "prototype-b-search.yaml"
        path.write_text(yaml.safe_dump(search_spec(), sort_keys=False), encoding="utf-8")
        return significant(command_record(["optimize", str(path), "--quiet"]))


TRADEOFF_LEVELS = {"max_deflection": ("mm", (1, 2, 3, 5, 8, 12)), "min_frequency": ("Hz", (20, 30, 45, 60, 80, 100))}


def plot_tradeoff() -> dict:
    out = {}
    for key, (unit, levels) in TRADEOFF_LEVELS.items():
        points = []
        for level in levels:
            raw = search_spec()
            raw["limits"][key] = f"{level} {unit}"
            spec = parse_spec(raw)
            for cand in search.optimize(spec).candidates:
                ev = cand.evaluation
                points.append({"material": cand.material, "section": cand.family.label,
                               "x": getattr(spec.limits, key),
                               "objective": None if ev is None else float(ev.error_ratio),
                               "feasible": bool(ev is not None and ev.feasible)})
        out[key] = points
    return significant(out)


# ----------------------------------------------------------------------------- calibration fixtures

CAL_NOTE = ("Noh et al. 2025 Prototype {P} (Table 1, loads of Table 2) as a calibration fixture. k_i = V_s G g n "
            "y_g / (4 E I_s) (MODEL.md section 3) with I_s = {I_s:.6g} m^4, y_g = {y_g:.6g} m. Electronics assumed "
            "(not given in the paper): 5 V excitation, gain {gain:g}, 1.3 mV RMS output noise per channel (measured "
            "on Prototype B, section 4.3).")
CAL_SPEC_KEYS = ("name", "load", "electronics", "gauge", "bridge", "stations", "axes", "targets", "objective")
CAL_PREDICTED = ("force_error", "position_error", "sensitivity", "noise_voltage", "gauge_strain")


def cal_fixture(key: str) -> dict:
    raw = example(f"prototype-{key}")
    raw["gauge"] = "BF120-3AA"
    raw["targets"] = {"force_error": "5 %", "position_error": "5 mm"}
    if key == "b":
        raw["load"]["force"] = ["20 gf", "3000 gf"]                   # Table 2
        raw["design"]["stations"] = ["20 mm", "60 mm", "100 mm"]     # Table 1: all three bridges
    spec, ev, rec = evaluated(raw)
    s, d = rec["spec"], rec["design"]
    s = {k: s[k] for k in CAL_SPEC_KEYS}
    s["electronics"] = without(s["electronics"], ("noise_output",))
    s["gauge"] = without(s["gauge"], GAUGE_GRID)
    d["gauge"] = without(d["gauge"], GAUGE_GRID)
    props = ev.analysis.props
    note = CAL_NOTE.format(P=key.upper(), I_s=float(props.I_s), y_g=float(props.y_g), gain=spec.electronics.gain)
    return {"version": rec["version"], "status": "feasible", "spec": significant(s), "design": significant(d),
            "predicted": {k: rec["predicted"][k] for k in CAL_PREDICTED}, "constraints": [], "candidates": [],
            "solver": rec["solver"], "messages": [note]}


# ----------------------------------------------------------------------------- CAD fixtures

CAD_SPEC_DROP = ("search", "design")
ZERO_CLEARANCE = {"load_clearance": "0 mm", "tip_margin": "0 mm"}   # as examples/prototype-c.yaml
CAD = {
    # file: (note, example it starts from, changes to its spec)
    "prototype_a": ("Noh et al. 2025, Table 1, Prototype A: 6061 aluminium 50 x 3.18 mm, 800 mm, full bridges at 20 "
                    "and 120 mm", "prototype-a", {}),
    "prototype_b": ("Noh et al. 2025, Table 1, Prototype B: 2024 aluminium 12.7 mm square, 450 mm, half bridges at "
                    "20, 60, 100 mm over 9.5 mm holes", "prototype-b",
                    {"load.force": ["20 gf", "3000 gf"], "design.stations": ["20 mm", "60 mm", "100 mm"]}),
    "prototype_c": ("Noh et al. 2025, Table 1, Prototype C: 6061 aluminium tube 12.7 x 1.65 mm, 200 mm, half bridges "
                    "at 20 and 70 mm on two axes", "prototype-c", {"limits": ZERO_CLEARANCE}),
    "prototype_c_flats": ("Prototype C with 0.65 mm flats under the gauges on all four faces (the paper's tube had "
                          "none)", "prototype-c",
                          {"name": "prototype-c-flats", "limits": ZERO_CLEARANCE,
                           "design.feature": {"kind": "pocket", "depth": "0.65 mm"}}),
    "rect_pockets": ("a rectangle with slot pockets, wire channels and default load grooves", "prototype-b",
                     {"name": "rect-pockets", "load.force": ["0.5 N", "20 N"], "load.position": ["80 mm", "145 mm"],
                      "design": {"material": "7075-T6", "section": {"kind": "rectangle", "width": "20 mm",
                                                                    "height": "8 mm"},
                                 "stations": ["20 mm", "60 mm"], "feature": {"kind": "pocket", "depth": "1 mm"},
                                 "length": "150 mm"},
                      "cad": {"load_grooves": True}}),
    "round_flats": ("a round bar with flats; clamp, bolts and grooves given in the spec", "prototype-b",
                    {"name": "round-flats", "load.force": ["0.5 N", "20 N"], "load.position": ["60 mm", "115 mm"],
                     "design": {"material": "2024-T3", "section": {"kind": "round", "diameter": "16 mm"},
                                "stations": ["15 mm", "45 mm"], "feature": {"kind": "pocket", "depth": "1.2 mm"},
                                "length": "120 mm"},
                     "cad": {"clamp_length": "30 mm", "bolt_diameter": "5 mm", "load_grooves": True,
                             "groove_positions": ["70 mm", "100 mm"], "groove_depth": "0.4 mm"}}),
    "square_biaxial_pockets": ("a biaxial square with slot pockets on all four faces", "prototype-b",
                               {"name": "square-biaxial", "axes": 2, "load.force": ["0.5 N", "20 N"],
                                "load.position": ["80 mm", "155 mm"],
                                "design": {"material": "7075-T6", "section": {"kind": "rectangle", "width": "14 mm",
                                                                              "height": "14 mm"},
                                           "stations": ["20 mm", "60 mm"],
                                           "feature": {"kind": "pocket", "depth": "1 mm"}, "length": "160 mm"}}),
    "tube_flats": ("a tube with flats at three stations and default load grooves", "prototype-b",
                   {"name": "tube-flats", "load.force": ["1 N", "40 N"], "load.position": ["100 mm", "195 mm"],
                    "design": {"material": "6061-T6", "section": {"kind": "tube", "diameter": "20 mm",
                                                                  "wall": "2.5 mm"},
                               "stations": ["20 mm", "50 mm", "80 mm"], "feature": {"kind": "pocket", "depth": "1 mm"},
                               "length": "200 mm"},
                    "cad": {"load_grooves": True}}),
}


def cad_fixture(name: str) -> dict:
    note, source, changes = CAD[name]
    raw = example(source)
    base = example("prototype-b")
    raw["electronics"] = base["electronics"]
    raw["gauge"] = "BF120-3AA"
    raw["limits"] = {}
    raw["targets"] = {"force_error": "3 %", "position_error": "20 mm"}
    for path, value in changes.items():
        *parents, last = path.split(".")
        node = raw
        for p in parents:
            node = node[p]
        node[last] = copy.deepcopy(value)
    _, _, rec = evaluated(raw)
    s = without(rec["spec"], CAD_SPEC_DROP)
    s["electronics"] = without(s["electronics"], ("noise_output",))
    return significant({"version": rec["version"], "status": "feasible", "spec": s, "design": rec["design"],
                        "predicted": {}, "constraints": [], "candidates": [], "solver": rec["solver"], "note": note})


# ----------------------------------------------------------------------------- writing and comparing

def builders() -> dict:
    """{file name: (function making its content, json.dumps indent, trailing newline)}."""
    out = {}
    for name in CAD:
        out[f"cad_{name}.json"] = (lambda n=name: cad_fixture(n), 2, True)
    for key in "abc":
        out[f"cal_prototype_{key}.json"] = (lambda k=key: cal_fixture(k), 2, True)
    out["plot_optimized.json"] = (plot_optimized, 1, False)
    out["plot_prototype_b.json"] = (lambda: plot_evaluated("prototype-b"), 1, False)
    out["plot_prototype_c.json"] = (lambda: plot_evaluated("prototype-c"), 1, False)
    out["plot_tradeoff.json"] = (plot_tradeoff, 1, False)
    return out


def flatten(value, prefix: str = "") -> dict:
    if isinstance(value, dict):
        items = {}
        for k, v in value.items():
            items.update(flatten(v, f"{prefix}.{k}" if prefix else k))
        return items if value else {prefix: {}}
    if isinstance(value, list):
        items = {}
        for i, v in enumerate(value):
            items.update(flatten(v, f"{prefix}[{i}]"))
        return items if value else {prefix: []}
    return {prefix: value}


def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def compare(old, new, rel: float = 1e-9) -> dict:
    """Keys only in one, numbers apart by more than ``rel``, other values that differ."""
    a, b = flatten(old), flatten(new)
    numbers, others, worst = [], [], 0.0
    for key in sorted(a.keys() & b.keys()):
        x, y = a[key], b[key]
        if _number(x) and _number(y):
            scale = max(abs(x), abs(y))
            apart = 0.0 if x == y else (abs(x - y) / scale if scale else math.inf)
            worst = max(worst, apart)
            if apart > rel:
                numbers.append((key, x, y, apart))
        elif x != y:
            others.append((key, x, y))
    return {"only_committed": sorted(a.keys() - b.keys()), "only_regenerated": sorted(b.keys() - a.keys()),
            "numbers": numbers, "others": others, "worst": worst,
            "equal": not (a.keys() ^ b.keys()) and not numbers and not others}


def report(name: str, result: dict, limit: int = 12) -> None:
    verdict = "EQUAL" if result["equal"] else "DIFFERENT"
    print(f"{name}: {verdict} (largest relative difference of a number: {result['worst']:.2e})")
    sides = (("only in the committed file", "only_committed"), ("only in the regenerated file", "only_regenerated"))
    for label, key in sides:
        if result[key]:
            print(f"  {label} ({len(result[key])}): {', '.join(result[key][:limit])}"
                  + (" ..." if len(result[key]) > limit else ""))
    if result["numbers"]:
        print(f"  numbers apart by more than 1e-9 ({len(result['numbers'])}):")
        for key, x, y, apart in result["numbers"][:limit]:
            print(f"    {key}: {x!r} -> {y!r} ({apart:.2e})")
    if result["others"]:
        print(f"  other values that differ ({len(result['others'])}):")
        for key, x, y in result["others"][:limit]:
            print(f"    {key}: {x!r} -> {y!r}")


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-o", "--output", type=Path, default=HERE, help="folder to write into [tests/data]")
    parser.add_argument("--compare", action="store_true",
                        help="compare each file with the one in tests/data before it is written")
    parser.add_argument("files", nargs="*", help="only these files (names in tests/data)")
    args = parser.parse_args(argv)
    table = builders()
    unknown = sorted(set(args.files) - table.keys())
    if unknown:
        parser.error(f"not a file of tests/data: {', '.join(unknown)}")
    args.output.mkdir(parents=True, exist_ok=True)
    for name, (build, indent, newline) in table.items():
        if args.files and name not in args.files:
            continue
        committed = json.loads((HERE / name).read_text(encoding="utf-8")) if args.compare else None
        content = build()
        (args.output / name).write_text(json.dumps(content, indent=indent) + ("\n" if newline else ""),
                                        encoding="utf-8")
        print(f"wrote {args.output / name}", flush=True)
        if args.compare:
            report(name, compare(committed, content))
    return 0


if __name__ == "__main__":
    sys.exit(run())
