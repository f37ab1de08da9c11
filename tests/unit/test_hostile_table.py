"""Hostile input, table-driven: every command against bad spec.yaml values, keys and types (every
section), bad design.json, readings.csv and calibration.json, and bad paths and flags.

docs/spec.md §10: bad input exits 2 with one line on standard error, ``fpdesign: error: …``,
naming the key (or line and column) and the value, with no traceback, and nothing is written. A
wrong command-line argument is reported by the argument parser: its usage, then one error line.

Each case runs ``designer.cli.main`` in-process in a folder of its own (the working directory,
so that default output folders land there too) and checks: the exit code, the one error line and
the words it must hold, no traceback, the folder unchanged (no file created, none left behind),
and the time (under ``CASE_SECONDS``) and the process's peak memory (under ``PEAK_RSS_MB``).
"""

from __future__ import annotations

import copy
import json
import random
import resource
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import yaml

from designer.cli import main

DATA = Path(__file__).resolve().parents[1] / "data"
#: Bad input is refused while reading it: a second is plenty; 10 s flags a case that computed.
CASE_SECONDS = 10.0
#: The test process's peak resident memory: the package, numpy, scipy, pint and the suite's own
#: files take a few hundred MB; a case that allocates by a hostile size (a grid of 1e9) passes this.
PEAK_RSS_MB = 3000

# ----------------------------------------------------------------------------- inputs

#: A valid spec with a fixed design: `evaluate` of it succeeds (a 300 mm aluminium bar).
GOOD_SPEC = {
    "name": "hostile",
    "load": {"force": ["1 N", "20 N"], "position": ["100 mm", "300 mm"]},
    "electronics": {"excitation": "5 V", "gain": 500, "noise": "1 mV"},
    "gauge": "BF120-3AA",
    "bridge": "half",
    "design": {"material": "6061-T6", "section": {"kind": "rectangle", "width": "10 mm", "height": "5 mm"},
               "stations": ["20 mm", "60 mm"], "feature": {"kind": "pocket", "depth": "1 mm"},
               "length": "310 mm"},
}
#: A complete design.json (the paper's Prototype B, as the plot tests read it).
GOOD_DESIGN = json.loads((DATA / "plot_prototype_b.json").read_text())
MISSING = object()   # a key removed
#: A plain round bar 0.004 mm across: a beam as given, nothing on the 0.01 mm grid it is judged on.
TINY_DESIGN = {"material": "6061-T6", "section": {"kind": "round", "diameter": "0.004 mm"},
               "stations": ["20 mm", "60 mm"], "feature": {"kind": "none"}, "length": "310 mm"}


def _set(tree, path: str, value):
    """A copy of ``tree`` with ``path`` ("a.b[1].c") set to ``value`` (removed when MISSING)."""
    tree = copy.deepcopy(tree)
    parts = []
    for part in path.split("."):
        while "[" in part:
            name, rest = part.split("[", 1)
            if name:
                parts.append(name)
            index, part = rest.split("]", 1)
            parts.append(int(index))
        if part:
            parts.append(part)
    node = tree
    for key in parts[:-1]:
        node = node.setdefault(key, {}) if isinstance(key, str) else node[key]
    if value is MISSING:
        del node[parts[-1]]
    else:
        node[parts[-1]] = value
    return tree


@dataclass
class Case:
    id: str
    argv: tuple                      # with {spec}, {design}, {readings}, {cal}, {out} for the files
    files: dict = field(default_factory=dict)   # name -> text (or bytes) written before the run
    expect: tuple = ()               # words the error line must hold
    usage: bool = False              # reported by the argument parser (usage, then the error line)
    code: int = 2

    def __post_init__(self):
        self.argv = tuple(self.argv)


def _token(value) -> str:
    """How a bad value shows in a message: text as written, anything else as Python writes it."""
    return value if isinstance(value, str) else repr(value)


def _shown(value):
    """The words that show a bad value: for a list, the list or one of its items (a message
    names the item at fault, ``load.force[1]: 'abc' ...``)."""
    if isinstance(value, (list, dict)):
        items = value.values() if isinstance(value, dict) else value
        return (repr(value),) + tuple(_token(v) for v in items)
    return _token(value)


# spec.yaml: each case a (key, value) set into GOOD_SPEC, run through a command that reads a spec.
SPEC_COMMANDS = (
    ("evaluate", "{spec}", "-o", "{out}", "--no-cad", "--no-plots"),
    ("optimize", "{spec}", "-o", "{out}", "--no-cad", "--no-plots", "--quiet"),
    ("simulate", "{spec}", "--draws", "100", "--grid", "2", "2"),
)

NUMBER_HOSTILES = ("abc", "-3", [1, 2], {"a": 1}, True, float("nan"), "1e400 m", "1e30 m", "", "3 4")

SPEC_VALUES = [
    # key, value, words of the message beyond the key (default: the value as written)
    ("name", 42, ()), ("name", "", ()), ("name", [1], ()), ("name", "   ", ()),
    ("name", "a\x00b", ("control characters",)), ("name", "a\nb", ("on one line",)),
    ("load", "heavy", ()), ("load", [1, 2], ()), ("load", MISSING, ("missing",)),
    ("load.force", MISSING, ("missing",)), ("load.position", MISSING, ("missing",)),
    ("load.colour", "red", ("unknown key",)),
    ("load.force", "20 N", ()), ("load.force", ["20 N", "1 N"], ("reversed",)), ("load.force", ["1 N"], ()),
    ("load.force", ["1 N", "2 N", "3 N"], ()), ("load.force", ["1 N", "abc"], ()), ("load.force", ["-1 N", "2 N"], ()),
    ("load.force", ["1 mm", "2 mm"], ("wrong units",)), ("load.force", ["1 N", "1e300 N"], ()),
    ("load.force", [True, 2], ()), ("load.force", ["1 N", float("inf")], ()), ("load.force", ["1 N", "1 N"], ()),
    ("load.position", ["100 N", "300 N"], ("wrong units",)), ("load.position", ["300 mm", "100 mm"], ("reversed",)),
    ("load.position", ["0 mm", "100 mm"], ()), ("load.position", ["100 mm", "1e6 km"], ()),
    ("load.position", {"a": 1}, ()), ("load.position", ["100 mm", "300 mm 4"], ()),
    ("electronics", MISSING, ("missing",)), ("electronics", "5 V", ()), ("electronics.excitation", MISSING, ("missing",)),
    ("electronics.excitation", "5 N", ("wrong units",)), ("electronics.excitation", "-5 V", ()),
    ("electronics.excitation", "1e9 V", ()), ("electronics.excitation", [5], ()), ("electronics.excitation", 0, ()),
    ("electronics.gain", "abc", ()), ("electronics.gain", 0, ()), ("electronics.gain", -1, ()),
    ("electronics.gain", "1e300", ()), ("electronics.gain", "5 V", ("wrong units",)),
    ("electronics.noise", "1 mm", ("wrong units",)), ("electronics.noise", "-1 mV", ()),
    ("electronics.noise", MISSING, ("exactly one", "none is given")),
    ("electronics.noise_rti", "50 nV", ("exactly one", "(noise, noise_rti)")),
    ("electronics.noise_strain", "abc", ("exactly one", "(noise, noise_strain)")), ("electronics.hum", "50 Hz", ("unknown key",)),
    ("gauge", "NOPE-1", ()), ("gauge", 42, ()), ("gauge", [1], ()), ("gauge", True, ()),
    ("gauge", {"name": "BF120-3AA", "factor": "abc"}, ()), ("gauge", {"factor": 2}, ("missing",)),
    ("gauge", {"name": "BF120-3AA", "bogus": 1}, ("bogus", "unknown key")),
    ("gauge", {"name": "BF120-3AA", "max_strain": "2 mm"}, ("max_strain", "wrong units")),
    ("gauge", {"name": "BF120-3AA", "length": "-7 mm"}, ("length",)),
    ("gauge", {"name": "NOPE", "factor": 2}, ("NOPE",)), ("gauge", {"name": 350}, ("350",)),
    ("gauge", {"name": "BF120-3AA", "resistance": "120 V"}, ("resistance", "wrong units")),
    ("gauge", {"name": "BF120-3AA", "grid_length": "20 mm"}, ("gauge.grid_length", "backing")),
    ("bridge", "double", ()), ("bridge", 2, ()), ("bridge", True, ()), ("bridge", [1], ()),
    ("stations", 1, ()), ("stations", 11, ()), ("stations", 2.5, ()), ("stations", "two", ()), ("stations", True, ()),
    ("axes", 0, ()), ("axes", 3, ()), ("axes", "x", ()), ("axes", 1.5, ()),
    ("limits", "strict", ()), ("limits", {"bogus": 1}, ("limits.bogus", "unknown key")),
    ("limits.safety_factor", 0.5, ()), ("limits.safety_factor", "abc", ()), ("limits.safety_factor", "2 mm", ()),
    ("limits.fatigue", "yes", ()), ("limits.fatigue", 1, ()),
    ("limits.max_deflection", "-1 mm", ()), ("limits.max_deflection", "1 N", ("wrong units",)),
    ("limits.min_frequency", "100 mm", ("wrong units",)), ("limits.min_frequency", 0, ()),
    ("limits.width", ["16 mm", "4 mm"], ("reversed",)), ("limits.width", "4 mm", ()),
    ("limits.height", ["3 mm", "abc"], ()), ("limits.height", [1], ()),
    ("limits.min_wall", 0, ()), ("limits.min_wall", "1 V", ("wrong units",)),
    ("limits.clamp_clearance", "-1 mm", ()), ("limits.load_clearance", "x", ()),
    ("limits.tip_margin", "-5 mm", ()), ("limits.tip_margin", "1e3 m", ()),
    ("limits.pocket_margin", [1], ()), ("limits.gauge_gap", {"a": 1}, ()),
    ("limits.min_pocket_depth", 0, ()), ("limits.min_pocket_depth", "0.5 N", ("wrong units",)),
    ("limits.max_pocket_fraction", 0.5, ("below 0.5",)), ("limits.max_pocket_fraction", -0.1, ()),
    ("limits.min_snr", "abc", ()), ("limits.min_snr", -5, ()),
    ("targets", [1], ()), ("targets.force_error", "abc", ()), ("targets.force_error", -1, ()),
    ("targets.force_error", "5 mm", ("wrong units",)), ("targets.position_error", "5 N", ("wrong units",)),
    ("targets.position_error", "-1 %", ()), ("targets.position_error", 0, ()), ("targets.speed", 1, ("unknown key",)),
    ("search", "all", ()), ("search.materials", "unobtainium", ()), ("search.materials", 42, ()),
    ("search.materials", [], ()), ("search.materials", ["6061-T6", "nope"], ("search.materials[1]", "nope")),
    ("search.materials", {"a": 1}, ()), ("search.materials", [7075], ("7075", "quote")),
    ("search.materials", ["6061-T6", "all"], ("search.materials[1]", "whole list", "one of [6061-T6,")),
    ("search.sections", "triangle", ()), ("search.sections", [], ()), ("search.sections", ["round", 3], ("3",)),
    ("search.feature", "slot", ()), ("search.feature", 1, ()), ("search.method", "grid", ("unknown key",)),
    ("search.stock", "cheap", ("none, metric, imperial, any",)), ("search.stock", ["metric"], ()),
    ("search.stock", 1, ()),
    ("objective", "speed", ()), ("objective", 1, ()), ("objective", ["error"], ()),
    ("cad", "yes", ()), ("cad.clamp_length", "abc", ()), ("cad.clamp_length", "-1 mm", ()),
    ("cad.bolt_diameter", "M5", ()), ("cad.end_mill_diameter", "3 N", ("wrong units",)),
    ("cad.corner_radius", "2 mm", ("pocket depth",)), ("cad.corner_radius", 0, ()),
    ("cad.channel_width", [1], ()), ("cad.channel_depth", "-0.5 mm", ()), ("cad.groove_depth", "1e9 mm", ()),
    ("cad.depth_step", "0.025 mm", ("multiple of 0.01 mm",)), ("cad.depth_step", "2 mm", ("0.01 mm to 1 mm",)),
    ("cad.depth_step", "0 mm", ()), ("cad.depth_step", "1 N", ("wrong units",)),
    ("cad.wire_channels", "yes", ()), ("cad.load_grooves", 1, ()), ("cad.groove_positions", "60 mm", ()),
    ("cad.groove_positions", [], ()), ("cad.groove_positions", ["abc"], ()), ("cad.colour", "red", ("unknown key",)),
    ("design", "fixed", ()), ("design.material", "unobtainium", ()), ("design.material", 7075, ("quote",)),
    ("design.material", MISSING, ("missing",)), ("design.material", ["6061-T6"], ()),
    ("design.section", "rectangle", ()), ("design.section.kind", "hexagon", ()),
    ("design.section.width", MISSING, ("missing",)), ("design.section.width", "abc", ()),
    ("design.section.height", "-5 mm", ()), ("design.section.height", "1e6 m", ()),
    # under 0.005 mm a size rounds to nothing on the 0.01 mm grid the design is judged on
    ("design", TINY_DESIGN, ("design.section.diameter", "must be positive", "rounded to 0.01 mm")),
    ("design.section", {"kind": "tube", "diameter": "10 mm", "wall": "6 mm"}, ("design.section.wall", "half")),
    ("design.section", {"kind": "round", "diameter": "10 mm", "width": "3 mm"}, ("width", "unknown key")),
    ("design.stations", ["20 mm"], ()), ("design.stations", ["60 mm", "20 mm"], ("[60.0, 20.0] mm", "increase")),
    ("design.stations", "20 mm", ()), ("design.stations", ["20 mm", "abc"], ()),
    ("design.stations", ["20 mm", "400 mm"], ("off the beam",)), ("design.stations", ["20 mm", "20 mm"], ("[20.0, 20.0] mm", "increase")),
    # the default pocket is as long as the gauge backing and its margins (8.9 mm for BF120-3AA's 6.9 mm)
    ("design.stations", ["20 mm", "25 mm"], ("design.stations[1]", "too close", "8.9 mm pockets would overlap")),
    ("design.feature", "pocket", ()), ("design.feature.kind", "slot", ()), ("design.feature.depth", "3 mm", ("half",)),
    ("design.feature.depth", MISSING, ("missing",)), ("design.feature.depth", "1 N", ("wrong units",)),
    ("design.feature", {"kind": "hole", "diameter": "6 mm"}, ("design.feature.diameter", "height")),
    ("design.feature", {"kind": "hole", "diameter": "abc"}, ()),
    ("design.length", "200 mm", ("shorter",)), ("design.length", "-1 mm", ()), ("design.length", "1 kg", ()),
    ("design.colour", "red", ("unknown key",)),
    ("colour", "red", ("unknown key",)),
]
# a number with a unit, each hostile form (NUMBER_HOSTILES), at keys of four kinds
for _key in ("load.force[1]", "electronics.excitation", "limits.min_wall", "design.section.width"):
    for _value in NUMBER_HOSTILES:
        SPEC_VALUES.append((_key, _value, ()))


def _spec_cases():
    out = []
    for i, (key, value, words) in enumerate(SPEC_VALUES):
        # optimize reads of a design: block only its length and number of stations (docs/spec.md §3)
        fixed_only = (key.startswith("design.stations") and value in (["20 mm", "400 mm"], ["20 mm", "25 mm"])
                      or value is TINY_DESIGN)
        command = SPEC_COMMANDS[0 if fixed_only else i % len(SPEC_COMMANDS)]
        raw = _set(GOOD_SPEC, key, value)
        named = key.split("[")[0] if "[" in key else key
        # "give exactly one of [noise, noise_rti, noise_strain]" names the three keys together
        named = (named, "electronics: give exactly one") if named.startswith("electronics.noise") else named
        expect = (named,) + (tuple(words) or (
            () if value is MISSING or _token(value) == "" else (_shown(value),)))
        out.append(Case(f"spec:{key}={_token(value) if value is not MISSING else 'missing'}:{command[0]}",
                        command, {"spec": yaml.safe_dump(raw, allow_unicode=True)}, expect))
    return out


def _raw_spec_cases():
    """Files that are not a spec mapping at all."""
    good = yaml.safe_dump(GOOD_SPEC)
    texts = [
        ("empty", "", ("empty",)),
        ("comment only", "# nothing\n", ("empty",)),
        ("a list", "- load\n- electronics\n", ("mapping", "list")),
        ("a number", "42\n", ("mapping", "int")),
        ("syntax", "load: {force: [1 N, 20 N\n", ("YAML syntax error", "line")),
        ("tab", "load:\n\tforce: 1\n", ("YAML syntax error",)),
        ("duplicate key", good + "name: again\n", ("'name'", "twice")),
        ("alias", good + "colour: &x red\nshade: *x\n", ("aliases",)),
        ("deep", good + "cad: " + "{a: " * 30 + "1" + "}" * 30 + "\n", ("nested",)),
        ("too big", good + "# " + "x" * 1_100_000 + "\n", ("MB",)),
        ("binary", b"\xff\xfe\x00\x01load: 1\n", ("cannot be read",)),
        ("python tag", good + "gain: !!python/object/apply:os.system ['true']\n", ("line",)),
        ("key a list", "[a, b]: 1\n" + good, ("line",)),
        ("long value", good.replace("name: hostile", "name: hostile\nbridge2: " + "x" * 5000), ("bridge2",)),
    ]
    out = []
    for i, (name, text, words) in enumerate(texts):
        command = SPEC_COMMANDS[i % len(SPEC_COMMANDS)]
        out.append(Case(f"spec-file:{name}:{command[0]}", command, {"spec": text}, words))
    return out


# design.json: each case a (key, value) set into GOOD_DESIGN, run through a command that reads one.
DESIGN_COMMANDS = (
    ("export", "{design}", "--step", "{out}.step"),
    ("plot", "{design}", "-o", "{out}"),
    ("simulate", "{design}", "--draws", "100", "--grid", "2", "2"),
    ("verify", "{design}", "-o", "{out}", "--mesh", "coarse"),
    ("plan", "{design}", "-o", "{out}.csv"),
    ("simulate-readings", "{design}", "-o", "{out}.csv"),
    ("calibrate", "{readings}", "-o", "{out}.json", "--design", "{design}"),
)
DESIGN_VALUES = [
    ("version", 2, ()), ("version", "1", ()), ("version", True, ()),
    ("spec", MISSING, ("missing",)), ("spec", "x", ()), ("spec", [], ()),
    ("design", MISSING, ("missing",)), ("design", 3, ()),
    ("design.material", 3, ()), ("design.material", MISSING, ("missing",)),
    ("design.material_properties", MISSING, ("missing",)), ("design.material_properties.E", -1, ()),
    ("design.material_properties.E", "70 GPa", ()), ("design.material_properties.yield", 0, ()),
    ("design.material_properties.density", True, ()), ("design.material_properties.poisson", 0.7, ()),
    ("design.section", MISSING, ("missing",)), ("design.section.kind", "hexagon", ()),
    ("design.section.width", -0.01, ()), ("design.section.width", 1e9, ()), ("design.section.height", "12 mm", ()),
    ("design.feature.kind", "slot", ()), ("design.feature.diameter", 0.02, ("design.feature",)),
    ("design.feature.diameter", MISSING, ("missing",)),
    ("design.length", 0, ()), ("design.length", None, ("missing",)), ("design.length", 1e9, ()),
    ("design.stations", [0.02], ()), ("design.stations", [0.1, 0.02], ("[100.0, 20.0] mm", "increase")),
    ("design.stations", [0.02, "x"], ("design.stations[1]", "'x'")),
    ("design.stations", [0.02, 0.9], ("off the beam",)), ("design.stations", "0.02", ()),
    ("design.axes", 3, ()), ("design.adjustment", {"gauge_strain": [1.0], "deflection": 1.0,
                                                   "stress_concentration": 1.0}, ("gauge_strain",)),
    ("design.adjustment", "x", ("adjustment",)),
    ("spec.load.force", "abc", ("spec.load.force",)), ("spec.load.force", [2.0, 1.0], ("spec.load.force",)),
    ("spec.load.position", [0.15], ("spec.load.position",)), ("spec.electronics.noise", -1, ("spec.electronics",)),
    ("spec.electronics", "x", ("spec.electronics",)), ("spec.bridge", "double", ("spec.bridge",)),
    ("spec.gauge", "NOPE-1", ("spec.gauge",)), ("spec.colour", 1, ("spec.colour",)),
    ("spec.limits.safety_factor", 0.1, ("spec.limits.safety_factor",)), ("spec.axes", 7, ("spec.axes",)),
    ("spec.cad.corner_radius", -1.0, ("spec.cad.corner_radius", "-1.0")), ("spec.load", MISSING, ("spec.load", "missing")),
    ("predicted.sensitivity", [1.0], ("predicted.sensitivity",)),
    ("predicted.sensitivity", "x", ("predicted.sensitivity",)),
    ("predicted.noise_voltage", -1, ("predicted.noise_voltage",)),
    ("predicted", "x", ("predicted",)),
]


def _design_cases():
    out = []
    for i, (key, value, words) in enumerate(DESIGN_VALUES):
        # predicted figures are read by plot, plan, calibrate and simulate-readings (docs/spec.md §4);
        # simulate, verify and export judge the design afresh
        commands = DESIGN_COMMANDS if not key.startswith("predicted") else [
            c for c in DESIGN_COMMANDS if c[0] in ("plot", "plan", "calibrate", "simulate-readings")]
        for j in range(2):   # two commands per value, all in turn
            command = commands[(2 * i + j) % len(commands)]
            record = _set(GOOD_DESIGN, key, value)
            expect = words or (key, _shown(value))
            out.append(Case(f"design:{key}={_token(value) if value is not MISSING else 'missing'}:{command[0]}",
                            command, {"design": json.dumps(record)}, tuple(expect)))
    texts = [("not json", "{design", ("not valid JSON", "line 1")), ("a list", "[1, 2]", ("JSON object",)),
             ("empty", "", ("not valid JSON",)), ("NaN", '{"version": NaN}', ("NaN",)),
             ("binary", b"\xff\xfe\x00", ("cannot be read",)), ("deep", "[" * 100_000 + "]" * 100_000, ("nested",))]
    for i, (name, text, words) in enumerate(texts):
        command = DESIGN_COMMANDS[i % len(DESIGN_COMMANDS)]
        out.append(Case(f"design-file:{name}:{command[0]}", command, {"design": text}, words))
    return out


GOOD_READINGS = None   # filled by the module fixture: calibrate and measure read them
GOOD_CAL = None


def _csv_cases():
    """Each a function of the good readings text, and the words of the message."""
    def header_swap(old, new):
        return lambda text: text.replace(old, new, 1)

    def row(i, transform):
        def edit(text):
            lines = text.splitlines()
            data = [n for n, line in enumerate(lines) if line and not line.startswith("#")][1:]
            lines[data[i]] = transform(lines[data[i]])
            return "\n".join(lines) + "\n"
        return edit

    def cell(i, column, value):
        return row(i, lambda line: ",".join(value if j == column else c for j, c in enumerate(line.split(","))))

    def column(j, value):   # every data row's cell j (j = 2 is V1): text, or a function of the row
        def edit(text):
            lines = text.splitlines()
            return "\n".join([lines[1]] + [",".join((value(n) if callable(value) else value) if i == j else c
                                                     for i, c in enumerate(line.split(",")))
                                            for n, line in enumerate(lines[2:])])
        return edit

    edits = [
        ("empty", lambda t: "", ("empty",)),
        ("header only", lambda t: t.splitlines()[1] + "\n", ("no data rows",)),
        ("unknown column", header_swap("V1", "volts1"), ("volts1", "not a known column")),
        ("column twice", header_swap("V2", "V1"), ("V1", "twice")),
        ("mass and force", header_swap("position_mm", "force_N"), ("force_N or mass_g",)),
        ("no bridges", lambda t: "\n".join(",".join(l.split(",")[:2]) for l in t.splitlines() if not l.startswith("#")),
         ("no bridge columns",)),
        ("one bridge", lambda t: "\n".join(",".join(l.split(",")[:3]) for l in t.splitlines() if not l.startswith("#")),
         ("at least 2 stations",)),
        ("gap", header_swap("V2", "V3"), ("V3", "without gaps")),
        ("mixed axes", header_swap("V2", "V2y"), ("mix",)),
        ("angle one-axis", header_swap("mass_g", "angle_deg"), (("angle_deg", "column force_N missing"),)),
        ("short row", row(2, lambda l: l.rsplit(",", 1)[0]), ("line", "cells")),
        ("text cell", cell(3, 2, "abc"), ("line", "V1", "abc")),
        ("empty cell", cell(1, 3, ""), ("line", "V2", "empty")),
        ("nan cell", cell(1, 3, "nan"), ("line", "V2", "nan")),
        ("inf cell", cell(1, 0, "inf"), ("line", "mass_g", "inf")),
        ("huge volts", cell(0, 2, "1e300"), ("line", "V1", "1e300")),
        ("negative mass", cell(0, 0, "-200"), ("line", "mass_g", "-200")),
        ("negative position", cell(0, 1, "-5"), ("line", "position_mm", "-5")),
        ("huge mass", cell(0, 0, "1e12"), ("line", "mass_g", "1e12")),
        ("binary", lambda t: b"\xff\xfe\x00\x01", ("cannot be read",)),
        ("quote", row(0, lambda l: '"' + l), ("line",)),
    ]
    calibrate_only = [
        ("no position", lambda t: "\n".join(",".join(c for j, c in enumerate(l.split(",")) if j != 1)
                                            for l in t.splitlines() if not l.startswith("#")), ("position_mm", "missing")),
        ("two rows", lambda t: "\n".join([l for l in t.splitlines() if not l.startswith("#")][:3]), ("2 data rows",)),
        ("one position", lambda t: "\n".join(
            [t.splitlines()[1]] + [",".join(["200", "150"] + l.split(",")[2:]) for l in t.splitlines()[2:]]),
         ("position_mm",)),
        ("disconnected bridge", column(2, "0"), ("column V1", "does not respond to the load", "0.0 V")),
        ("bridge reading 1e-320 V", column(3, "1e-320"), ("column V2", "does not respond to the load", "1e-320")),
        ("bridge reading noise", column(2, lambda n: f"{0.1 + random.Random(n).gauss(0, 1e-3):.9f}"),
         ("column V1", "does not respond to the load", "standard errors")),
    ]
    out = []
    for name, edit, words in edits:
        out.append(("calibrate", name, edit, words))
        out.append(("measure", name, edit, words))
    for name, edit, words in calibrate_only:
        out.append(("calibrate", name, edit, words))
    return out


def _cal_edits():
    return [
        ("bridges", MISSING, ("bridges", "missing")), ("bridges", [], ("bridges",)), ("version", 9, ("version", "9")),
        ("version", MISSING, ("version",)), ("bridges[0].k", 0, ("bridges[0].k", "0")),
        ("bridges[0].k", "x", ("bridges[0].k", "x")), ("bridges[0].d", float("inf"), ("Infinity", "finite")),
        ("bridges[0].station", 0, ("bridges[0].station", "0")), ("bridges[1].station", 5, ("bridges",)),
        ("bridges[0].axis", "q", ("bridges[0].axis", "q")),
        ("bridges[0].unscaled_covariance", [[1, 2], [3, 4]], ("unscaled_covariance",)),
        ("bridges[0].unscaled_covariance", "x", ("unscaled_covariance",)),
        ("bridges[0].residuals", ["a"], ("bridges[0].residuals",)), ("bridges[0]", 7, ("bridges[0]", "7")),
        ("span", MISSING, ("span",)), ("span.force", [2.0, 1.0], ("span",)), ("span.position", "x", ("span.position",)),
        ("noise", "x", ("noise",)), ("noise.sigma_v", -1, ("noise.sigma_v",)),
        ("bridges[0].c", True, ("bridges[0].c",)),
    ]


# paths and flags: every command, each a (argv, words, usage).
FLAG_CASES = [
    (("optimize", "{spec}", "--method", "magic"), ("--method", "magic"), False),
    (("optimize", "{spec}", "--verify-rounds", "-1"), ("--verify-rounds", "-1"), False),
    (("optimize", "{spec}", "--verify-rounds", "x"), ("--verify-rounds", "x"), True),
    (("optimize", "{spec}", "--verify-mesh", "huge"), ("--verify-mesh", "huge"), True),
    # flags of the 3-D check, or of the readings, without it: refused, not silently ignored
    (("optimize", "{spec}", "--verify-rounds", "2"), ("--verify-rounds", "2", "without --verify"), False),
    (("optimize", "{spec}", "--verify-mesh", "fine"), ("--verify-mesh", "fine", "without --verify"), False),
    (("simulate", "{design}", "--draws", "100", "--grid", "2", "2", "--scheme", "4"),
     ("--scheme", "4", "without --readings"), False),
    (("optimize", "{missing}.yaml"), ("no such file",), False),
    (("optimize", "{dir}"), ("cannot be read",), False),
    (("optimize", "{spec}", "--bogus"), ("fpdesign optimize: error: unrecognized arguments: --bogus",), True),
    (("evaluate", "{spec}", "-o", "{spec}"), ("-o", "is a file"), False),
    (("optimize", "{spec}", "-o", "{readings}", "--quiet"), ("-o", "is a file"), False),
    (("verify", "{design}", "-o", "{spec}"), ("-o", "is a file"), False),
    (("bench", "--count", "1", "-o", "{spec}"), ("-o", "is a file"), False),
    (("export", "{design}", "--step", "{dir}"), ("{dir}", "folder"), False),
    (("plan", "{design}", "-o", "{dir}"), ("{dir}", "folder"), False),
    (("measure", "{cal}", "{readings}", "-o", "{dir}"), ("{dir}", "folder"), False),
    (("evaluate", "{missing}.yaml"), ("no such file",), False),
    (("simulate", "{design}", "--draws", "0"), ("--draws", "0"), False),
    (("simulate", "{design}", "--draws", "x"), ("--draws", "x"), True),
    (("simulate", "{design}", "--grid", "1", "1"), ("--grid", "1"), False),
    (("simulate", "{design}", "--grid", "7"), ("--grid",), True),
    (("simulate", "{design}", "--angle", "inf"), ("--angle", "inf"), False),
    (("simulate", "{design}", "--seed", "-1"), ("--seed", "-1"), True),
    (("simulate", "{design}", "--seed", "x"), ("--seed", "x"), True),
    (("simulate", "{design}", "--draws", "100", "--grid", "2", "2", "--scheme", "magic", "--readings", "{out}.csv"),
     ("scheme", "magic"), True),
    (("simulate", "{design}", "--draws", "100", "--grid", "2", "2", "--readings", "{design}"),
     ("--readings", "design.json"), False),
    (("simulate", "{missing}.json"), ("no such file",), False),
    (("simulate", "{spec}.txt"), ("no such file",), False),
    (("export", "{design}"), ("--step",), False),
    (("export", "{design}", "--step", "{design}"), ("--step", "design.json"), False),
    (("export", "{missing}.json", "--step", "{out}.step"), ("no such file",), False),
    (("plot", "{design}", "--format", "gif"), ("--format", "gif"), True),
    (("plot", "{design}", "--tradeoff", "{missing}.json", "-o", "{out}"), ("--tradeoff", "no such file"), False),
    (("plot", "{design}", "--tradeoff", "{spec}", "-o", "{out}"), ("--tradeoff",), False),
    (("plot", "{design}", "-o", "{spec}"), ("{spec}",), False),
    (("materials", "--yaml"), ("--yaml",), True),
    (("plan", "{design}", "--repeats", "0"), ("--repeats", "0"), True),
    (("plan", "{design}", "-o", "{design}"), ("-o", "design.json"), False),
    (("plan", "{dir}"), ("cannot be read",), False),
    (("calibrate", "{readings}"), ("-o",), True),
    (("calibrate", "{readings}", "-o", "{readings}"), ("-o", "readings"), False),
    (("calibrate", "{readings}", "-o", "{out}.json", "--noise", "magic"), ("--noise", "magic"), True),
    (("calibrate", "{readings}", "-o", "{out}.json", "--noise", "design"), ("noise", "design"), False),
    (("calibrate", "{missing}.csv", "-o", "{out}.json"), ("no such file",), False),
    (("calibrate", "{readings}", "-o", "{dir}"), ("{dir}",), False),
    (("measure", "{cal}", "{readings}", "--noise", "abc"), ("--noise", "abc"), False),
    (("measure", "{cal}", "{readings}", "--noise", "1 mm"), ("--noise", "1 mm"), False),
    (("measure", "{cal}", "{readings}", "--noise", "1e30 V"), ("--noise", "1e30 V"), False),
    (("measure", "{cal}", "{readings}", "-o", "{cal}"), ("-o", "calibration.json"), False),
    (("measure", "{readings}", "{cal}"), ("readings.csv", "not valid JSON"), False),
    (("measure", "{cal}", "{missing}.csv"), ("no such file",), False),
    (("simulate-readings", "{design}", "-o", "{out}.csv", "--scheme", "magic"), ("--scheme", "magic"), True),
    (("simulate-readings", "{design}", "-o", "{out}.csv", "--seed", "-1"), ("--seed", "-1"), True),
    (("simulate-readings", "{design}", "-o", "{out}.csv", "--repeats", "-3"), ("--repeats", "-3"), True),
    (("simulate-readings", "{design}", "-o", "{design}"), ("-o", "design.json"), False),
    (("simulate-readings", "{design}"), ("-o",), True),
    (("verify", "{design}", "--mesh", "huge"), ("--mesh", "huge"), True),
    (("verify", "{missing}.json"), ("no such file",), False),
    (("bench", "--count", "-1"), ("--count", "-1"), False),
    (("bench", "--count", "100000000", "-o", "{out}"), ("--count", "100000000"), False),
    (("bench", "--levels", "1"), ("--levels", "1"), False),
    (("bench", "--levels", "1000", "-o", "{out}"), ("--levels", "1000"), False),
    (("bench", "--methods", "magic"), ("--methods", "magic"), False),
    (("bench", "--methods", ","), ("--methods",), False),
    (("bench", "--specs", "{missing}"), ("--specs",), False),
    (("bench", "--seed", "-1", "-o", "{out}"), ("--seed", "-1"), True),
    (("frobnicate",), ("frobnicate",), True),
    ((), ("COMMAND",), True),
]


def _all_cases():
    cases = _spec_cases() + _raw_spec_cases() + _design_cases()
    for command, name, edit, words in _csv_cases():
        argv = (("calibrate", "{readings}", "-o", "{out}.json") if command == "calibrate"
                else ("measure", "{cal}", "{readings}", "-o", "{out}.csv"))
        cases.append(Case(f"csv:{name}:{command}", argv, {"readings": edit}, words))
    for key, value, words in _cal_edits():
        cases.append(Case(f"calibration:{key}={_token(value) if value is not MISSING else 'missing'}",
                          ("measure", "{cal}", "{readings}"), {"cal": (key, value)}, words))
    for argv, words, usage in FLAG_CASES:
        cases.append(Case(f"flag:{' '.join(argv)}", argv, {}, words, usage=usage))
    return cases


CASES = _all_cases()
NAMES = {"spec": "spec.yaml", "design": "design.json", "readings": "readings.csv", "cal": "calibration.json"}


@pytest.fixture(scope="module")
def good_files(tmp_path_factory):
    """Valid readings.csv and calibration.json of GOOD_DESIGN (made by the commands themselves)."""
    folder = tmp_path_factory.mktemp("good")
    design = folder / "design.json"
    design.write_text(json.dumps(GOOD_DESIGN))
    assert main(["simulate-readings", str(design), "-o", str(folder / "readings.csv"), "--scheme", "9"]) == 0
    assert main(["calibrate", str(folder / "readings.csv"), "-o", str(folder / "calibration.json")]) == 0
    return {"spec": yaml.safe_dump(GOOD_SPEC), "design": design.read_text(),
            "readings": (folder / "readings.csv").read_text(), "cal": (folder / "calibration.json").read_text()}


def _snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns) for p in sorted(folder.rglob("*"))}


def _prepare(case: Case, folder: Path, good: dict) -> list[str]:
    for key, name in NAMES.items():
        content = case.files.get(key, good[key])
        if key == "readings" and callable(content):
            content = content(good["readings"])
        if key == "cal" and isinstance(content, tuple):
            content = json.dumps(_set(json.loads(good["cal"]), *content))
        path = folder / name
        path.write_bytes(content if isinstance(content, bytes) else content.encode())
    (folder / "adir").mkdir()
    subs = {"spec": folder / "spec.yaml", "design": folder / "design.json", "readings": folder / "readings.csv",
            "cal": folder / "calibration.json", "out": folder / "out", "dir": folder / "adir",
            "missing": folder / "missing"}
    return [_fill(arg, subs) for arg in case.argv], subs


def _fill(text: str, subs: dict) -> str:
    for key, path in subs.items():
        text = text.replace("{" + key + "}", str(path))
    return text


def test_an_argument_no_command_takes_is_reported_with_that_commands_usage(capsys):
    """A positional argument calibrate does not take (its design goes with --design): the message
    shows calibrate's own usage, which says so, not the top level's ``fpdesign COMMAND ...``."""
    code = main(["calibrate", "design.json", "readings.csv", "-o", "calibration.json"])
    lines = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert lines[0].startswith("usage: fpdesign calibrate [-h] [--design DESIGN]"), lines
    assert lines[-1] == "fpdesign calibrate: error: unrecognized arguments: readings.csv"


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_input_exits_2_with_one_line_and_writes_nothing(case, good_files, tmp_path, monkeypatch, capsys):
    argv, subs = _prepare(case, tmp_path, good_files)
    monkeypatch.chdir(tmp_path)   # default output folders (out, verify, bench) land here too
    before = _snapshot(tmp_path)
    capsys.readouterr()
    t0 = time.perf_counter()
    code = main(argv)
    seconds = time.perf_counter() - t0
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == case.code, err
    assert "Traceback" not in err
    if case.usage:   # argparse: usage, then "fpdesign ...: error: ..."
        assert lines and lines[0].startswith("usage:") and "error:" in lines[-1], err
        line = lines[-1]
        assert sum("error:" in x for x in lines) == 1, err
    else:
        assert len(lines) == 1 and lines[0].startswith("fpdesign: error: "), err
        line = lines[0]
    for word in case.expect:   # a word, or a tuple of words of which one must be there
        alternatives = (word,) if isinstance(word, str) else word
        alternatives = [_fill(w, subs) for w in alternatives]
        assert any(w in line for w in alternatives), f"{alternatives!r} not in {line!r}"
    assert _snapshot(tmp_path) == before, "files were created, changed or removed"
    assert seconds < CASE_SECONDS, f"{seconds:.1f} s"
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 < PEAK_RSS_MB


def test_the_table_covers_every_command_with_150_cases_or_more():
    commands = {c.argv[0] for c in CASES if c.argv}
    assert commands >= {"optimize", "evaluate", "simulate", "export", "plot", "verify", "plan", "calibrate",
                        "measure", "simulate-readings", "materials", "bench"}
    assert len(CASES) >= 150


# Signals: Ctrl-C (SIGINT) and SIGTERM stop a long command with 130 or 143, one line, no
# traceback, nothing written (docs/spec.md §10). The signal comes from a timer while the command runs.
SIGNAL_COMMANDS = (
    ("optimize", str(Path(__file__).resolve().parents[2] / "examples" / "probe.yaml"), "-o", "{out}", "--quiet"),
    ("simulate", "{design}", "--draws", "10000000", "--readings", "{out}.csv"),
    ("bench", "--count", "3", "--quiet", "-o", "{out}", "--specs", str(Path(__file__).resolve().parents[2] / "examples")),
)
SIGNAL_DELAY = 1.0   # s: every one of these runs for longer than this


@pytest.mark.parametrize("signum, code, message", [(2, 130, "fpdesign: interrupted"),
                                                   (15, 143, "fpdesign: terminated")], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("argv", SIGNAL_COMMANDS, ids=[c[0] for c in SIGNAL_COMMANDS])
def test_a_signal_stops_the_command_with_its_code_and_writes_nothing(argv, signum, code, message, good_files,
                                                                       tmp_path):
    # in a process of its own: a signal sent to the test's own process could land after the
    # command (killing the test runner), and IPOPT may leave a caught Ctrl-C pending for the
    # next solve in the same process
    import signal
    import subprocess
    import sys

    from shared_inputs import wait_for_handlers

    argv, _ = _prepare(Case("signal", argv), tmp_path, good_files)
    before = _snapshot(tmp_path)
    proc = subprocess.Popen([sys.executable, "-m", "designer.cli", *argv], cwd=tmp_path, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    wait_for_handlers(proc)
    time.sleep(SIGNAL_DELAY)
    t0 = time.perf_counter()
    proc.send_signal(signal.Signals(signum))
    _, err = proc.communicate(timeout=60)
    seconds = time.perf_counter() - t0
    lines = [x for x in err.splitlines() if "CasADi" not in x]
    assert proc.returncode == code, err
    assert lines == [message] and "Traceback" not in err
    assert _snapshot(tmp_path) == before
    assert seconds < CASE_SECONDS
