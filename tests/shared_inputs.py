"""Inputs that tests of more than one layer (unit, validation, e2e) build on.

Each block says which test files use it. Only inputs live here; the assertions stay in the
test files.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

from designer.checks.montecarlo import grid
from designer.model import Geometry, MaterialParams
from designer.result.evaluation import evaluate, fixed_design
from designer.result.record import build_record
from designer.spec.reader import load_spec, parse_spec

DATA = Path(__file__).resolve().parent / "data"


# ----------------------------------------------------------------- beam model inputs
# unit/test_model_sections.py, validation/test_beam_closed_forms.py

MM = 1e-3
E_AL = 70e9      # Pa, a round number: the closed forms hold for any E
RHO_AL = 2700.0  # kg/m^3


def make_spec(**overrides):
    raw = {
        "load": {"force": ["1 N", "20 N"], "position": ["100 mm", "300 mm"]},
        "electronics": {"excitation": "5 V", "gain": 500, "noise": "1 mV"},
        "bridge": "half",
    }
    raw.update(overrides)
    return parse_spec(raw)


def material(E=E_AL):
    return MaterialParams(E=E, allowable=100e6, density=RHO_AL)


# A pocket's floor radius: the spec's default end-mill corner radius (cad.corner_radius, R0.2).
FLOOR_RADIUS = 0.2 * MM
# A 5.5 mm slot's corner radius in plan: its end mill's, Ø3 (outputs.cad.mills: the largest
# catalogue end mill at most 0.6 of the slot's width).
PLAN_RADIUS = 1.5 * MM


def rectangle(b, h, feature="none", stations=(0.02, 0.08), length=0.4, **kw):
    if feature == "pocket":
        kw.setdefault("floor_radius", FLOOR_RADIUS)
        kw.setdefault("plan_radius", PLAN_RADIUS)
    return Geometry(section="rectangle", feature=feature, stations=stations, length=length,
                    width=b, height=h, gauge_length=6.9 * MM, pocket_length=8.9 * MM,
                    pocket_width=kw.pop("pocket_width", 5.5 * MM), **kw)


def circular(kind, D, feature="none", wall=None, stations=(0.02, 0.08), length=0.4, **kw):
    if feature == "pocket":
        kw.setdefault("floor_radius", FLOOR_RADIUS)
    return Geometry(section=kind, feature=feature, stations=stations, length=length, diameter=D, wall=wall,
                    gauge_length=6.9 * MM, pocket_length=8.9 * MM, pocket_width=5.5 * MM, **kw)


# ----------------------------------------------------------------- a prototype for the Monte Carlo
# validation/test_montecarlo.py, unit/test_montecarlo_estimates.py

def montecarlo_prototype(examples, name):
    """(spec, k_i, d_i, forces, positions) of an example's fixed design on the paper's 7 x 7 grid."""
    spec = load_spec(examples / f"{name}.yaml")
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    g = ev.design.geometry
    forces, positions = grid(spec.load.force_min, spec.load.force_max, spec.load.position_min,
                             spec.load.position_max)
    return spec, [float(ev.analysis.sensitivity)] * len(g.stations), list(g.stations), forces, positions


# ----------------------------------------------------------------- CAD fixtures and damaged designs
# unit/test_cad_options.py, e2e/test_cli_export.py

def cad_record(name: str) -> dict:
    return json.loads((DATA / f"cad_{name}.json").read_text())


def cad_mutate(name: str, change) -> dict:
    rec = copy.deepcopy(cad_record(name))
    change(rec)
    return rec


CAD_BAD = {
    "missing section": ("prototype_b", lambda r: r["design"].pop("section"), "design.section"),
    "negative width": ("prototype_b", lambda r: r["design"]["section"].update(width=-0.0127),
                       "design.section.width"),
    "flat deeper than the wall": ("prototype_c_flats", lambda r: r["design"]["feature"].update(depth=0.002),
                                  "design.feature.depth"),
    "pocket deeper than half": ("rect_pockets", lambda r: r["design"]["feature"].update(depth=0.004),
                                "design.feature.depth"),
    "station off the beam": ("prototype_b", lambda r: r["design"].update(stations=[0.02, 0.06, 0.46]),
                             "design.stations[2]"),
    "pocket over the clamp face": ("rect_pockets", lambda r: r["design"].update(stations=[0.003, 0.06]),
                                   "design.stations[0]"),
    "holes overlapping": ("prototype_b", lambda r: r["design"].update(stations=[0.02, 0.025, 0.1]),
                          "design.stations[1]"),
    "clamp too short": ("prototype_b", lambda r: r["spec"]["cad"].update(clamp_length=0.01),
                        "spec.cad.clamp_length"),
    "end mill wider than the slot": ("rect_pockets", lambda r: r["spec"]["cad"].update(end_mill_diameter=0.006),
                                     "spec.cad.end_mill_diameter"),
    # moved across the bar, an end mill cuts a flat as long as itself: the 8.9 mm flat takes at most 8.9 mm
    "end mill longer than the flat": ("round_flats", lambda r: r["spec"]["cad"].update(end_mill_diameter=0.0095),
                                      "spec.cad.end_mill_diameter"),
    "groove off the beam": ("round_flats", lambda r: r["spec"]["cad"].update(groove_positions=[0.07, 0.125]),
                            "spec.cad.groove_positions"),
    "default groove at the free end": ("prototype_b", lambda r: r["spec"]["cad"].update(load_grooves=True),
                                       "spec.cad.load_grooves"),
    "channel deeper than the pocket": ("rect_pockets", lambda r: r["spec"]["cad"].update(channel_depth=0.0015),
                                       "spec.cad.channel_depth"),
    "unknown feature": ("prototype_b", lambda r: r["design"]["feature"].update(kind="slot"),
                        "design.feature.kind"),
    "corner radius as deep as the pocket": ("rect_pockets", lambda r: r["spec"]["cad"].update(corner_radius=0.001),
                                            "spec.cad.corner_radius"),
    "corner radius of half the end mill": ("rect_pockets", lambda r: r["spec"]["cad"].update(
        end_mill_diameter=0.001, corner_radius=0.0005), "spec.cad.corner_radius"),
    "negative corner radius": ("round_flats", lambda r: r["spec"]["cad"].update(corner_radius=-0.0002),
                               "spec.cad.corner_radius"),
    "corner radius as text": ("tube_flats", lambda r: r["spec"]["cad"].update(corner_radius="0.2 mm"),
                              "spec.cad.corner_radius"),
    "flat ends over the gauge": ("round_flats", lambda r: r["spec"]["cad"].update(corner_radius=0.0011),
                                 "spec.cad.corner_radius"),
}


# ----------------------------------------------------------------- a design record for the 3-D check
# validation/test_fea_beam_theory.py, unit/test_checks_bad_input.py, e2e/test_cli_verify.py

def fea_record(design: dict, load: dict, **extra) -> dict:
    raw = {"name": "fea-test", "load": load, "electronics": {"excitation": "5 V", "gain": 1000, "noise": "1.3 mV"},
           "bridge": "half", "limits": {"fatigue": False}, "design": design}
    raw.update(extra)
    spec = parse_spec(raw)
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    return json.loads(json.dumps(build_record("feasible" if ev.feasible else "infeasible", spec, ev)))


def fea_bar(length_mm: float, position_mm: tuple, size_mm: float = 10.0, feature=None, stations=(30, 50)) -> dict:
    return fea_record({"material": "2024-T3",
                       "section": {"kind": "rectangle", "width": f"{size_mm} mm", "height": f"{size_mm} mm"},
                       "stations": [f"{s} mm" for s in stations], "feature": feature or {"kind": "none"},
                       "length": f"{length_mm} mm"},
                      {"force": ["2 N", "20 N"], "position": [f"{p} mm" for p in position_mm]},
                      targets={"force_error": "20 %", "position_error": "10 %"})


# ----------------------------------------------------------------- optimiser specs
# unit/test_optimize_search.py, e2e/test_cli_optimize.py

def optimize_spec_text(**changes):
    base = {
        "load": "  force: [1 N, 20 N]\n  position: [60 mm, 150 mm]",
        "electronics": "  excitation: 5 V\n  gain: 128\n  noise_rti: 50 nV",
        "limits": "  max_deflection: 2 mm",
        "targets": "  force_error: 1 %\n  position_error: 1 mm",
        "search": "  materials: [7075-T6, 6061-T6]\n  sections: [rectangle, round]",
    }
    base.update(changes)
    return "name: test\n" + "".join(f"{k}:\n{v}\n" for k, v in base.items())


# ----------------------------------------------------------------- the search under stress
# unit/test_optimize_stability.py, e2e/test_cli_optimize.py

SMALL_CLEARANCES = """\
  clamp_clearance: 0.3 mm
  load_clearance: 0.3 mm
  tip_margin: 0.5 mm
  pocket_margin: 0.1 mm
  gauge_gap: 0.2 mm
  min_wall: 0.1 mm
  min_pocket_depth: 0.02 mm"""
MINIATURE_GAUGE = "gauge: {name: miniature, factor: 2.0, length: 1 mm, width: 0.8 mm, max_strain: 1500 ue}"


def _text(force, position, noise_rti, limits, gauge=MINIATURE_GAUGE, material="Ti-6Al-4V", section="rectangle",
          objective="error", feature="pocket", extra="", force_error="2 %"):
    return f"""\
name: stability
load:
  force: {force}
  position: {position}
electronics:
  excitation: 5 V
  gain: 500
  noise_rti: {noise_rti}
{gauge}
bridge: full
limits:
{limits}
targets:
  force_error: {force_error}
  position_error: 2 %
search:
  materials: [{material}]
  sections: [{section}]
  feature: {feature}
objective: {objective}
{extra}"""


# Sub-millimetre sections at nominal sizes: ISO 2768-m (the default) deviates them by ±0.1 mm,
# which leaves no design; their drawings would carry deviations of their own.
NOMINAL = "tolerances: {class: none}\n"

STABILITY_SCALES = {
    # a 14 mm finger read at millinewtons
    # (its 1 mm slot is cut by a 0.5 mm micro end mill: the CAD's standard ones start at 1 mm;
    # and its slot's depth, a few tenths of a millimetre, is set to 0.01 mm as micro-machining
    # does: on the default 0.05 mm grid one step is a fifth of the slot)
    "millinewtons on a millimetre beam": _text("[2 mN, 100 mN]", "[8 mm, 14 mm]", "760 nV", SMALL_CLEARANCES
                                               + "\n  width: [0.3 mm, 4 mm]\n  height: [0.3 mm, 4 mm]",
                                               extra="cad: {end_mill_diameter: 0.5 mm, depth_step: 0.01 mm}\n"
                                               + NOMINAL),
    # a metre-long whisker read at millinewtons, gauges on its surface (a miniature gauge's
    # pocket is short for its section: outside the slots' fitted domain, docs/model.md §7), which
    # reaches 2.1 % in force, not 2 %
    "millinewtons on a metre beam": _text("[5 mN, 200 mN]", "[0.4 m, 1 m]", "300 nV",
                                          SMALL_CLEARANCES + "\n  width: [0.5 mm, 20 mm]\n  height: [0.5 mm, 20 mm]"
                                          "\n  max_deflection: 20 mm", feature="none", force_error="3 %",
                                          extra=NOMINAL),
    # a short stiff lug at kilonewtons, and a metre-long weigh beam: gauges on the plain bar's
    # surface, as a gauge-sized pocket is short for sections this large (outside the slots'
    # fitted domain, docs/model.md §7). (At 2 kN the lug has no design: a section strong enough
    # puts its first station nearer the clamp than the model holds, docs/model.md §7.)
    "kilonewtons on a millimetre beam": _text("[50 N, 1.5 kN]", "[30 mm, 60 mm]", "500 nV",
                                              "  width: [5 mm, 40 mm]\n  height: [5 mm, 40 mm]",
                                              gauge="gauge: BF350-3AA", material="17-4PH-H900", feature="none"),
    "kilonewtons on a metre beam": _text("[100 N, 5 kN]", "[0.3 m, 1 m]", "500 nV",
                                         "  width: [10 mm, 150 mm]\n  height: [10 mm, 150 mm]\n  max_deflection: 10 mm",
                                         gauge="gauge: CEA-06-125UW-120", material="17-4PH-H900", feature="none"),
}


def raise_roundoff(self, x0):
    """Stands in for nlopt.opt.optimize: the solver stops with RoundoffLimited."""
    import nlopt

    raise nlopt.RoundoffLimited("NLopt roundoff-limited")


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def check_plot_files(paths, names, formats):
    """The plot files are exactly ``names`` x ``formats``, each a plausible PNG or SVG."""
    import xml.etree.ElementTree as ET

    assert sorted(p.name for p in paths) == sorted(f"{n}.{f}" for n in names for f in formats)
    for p in paths:
        data = p.read_bytes()
        assert 10_000 < len(data) < 3_000_000, (p.name, len(data))
        if p.suffix == ".png":
            assert data.startswith(PNG_SIGNATURE)
        else:
            assert ET.fromstring(data).tag.endswith("svg")


# ----------------------------------------------------------------- the 3-D check's correction loop
# unit/test_adjust.py, unit/test_correct.py, e2e/test_cli_verify_rounds.py

# The gripper finger with a stiffer deflection limit, one material and one section: its optimum
# sits on the deflection limit with the stresses well below the allowable (unit/test_adjust.py;
# unit/test_correct.py judges it with a stand-in 3-D check of known ratios).
STIFF_FINGER = """\
name: stiff-finger
load:
  force: [0.5 N, 20 N]
  position: [40 mm, 110 mm]
electronics:
  excitation: 5 V
  gain: 128
  noise_rti: 50 nV
gauge: BF350-3AA
bridge: half
stations: 2
limits:
  max_deflection: 0.4 mm
  width: [4 mm, 16 mm]
  height: [3 mm, 16 mm]
targets:
  force_error: 1 %
  position_error: 1 mm
search:
  materials: [7075-T6]
  sections: [round]
  feature: pocket
objective: error
tolerances: {class: none}  # at nominal sizes: the 3-D loop's tests put the deflection limit on its edge
"""

# A fixed design of the same finger: a round bar with flats.
STIFF_FINGER_DESIGN = """\
design:
  material: 7075-T6
  section: {kind: round, diameter: 11 mm}
  stations: [9.5 mm, 30.6 mm]
  feature: {kind: pocket, depth: 2 mm}
"""


# ----------------------------------------------------------------- signals
# e2e/test_signals_and_devices.py, unit/test_hostile_table.py

def wait_for_handlers(proc, timeout=30.0):
    """Until the command in ``proc`` has put its SIGTERM handler in place (Linux: the caught-signal
    mask in /proc/PID/status); before that the interpreter is still starting and Python's
    defaults act. Elsewhere: a fixed second."""
    import signal
    import time

    status = Path(f"/proc/{proc.pid}/status")
    if not status.exists():
        time.sleep(1.0)
        return
    start = time.monotonic()
    while time.monotonic() - start < timeout and proc.poll() is None:
        try:
            caught = next((line.split()[1] for line in status.read_text().splitlines() if line.startswith("SigCgt:")),
                          "0")
        except OSError:
            return
        if int(caught, 16) & (1 << (signal.SIGTERM - 1)):
            return
        time.sleep(0.02)


# ----------------------------------------------------------------- the optimiser's derivatives
# unit/test_corrections.py, unit/test_adjust.py

def assert_exact_jacobian(problem, x, params, h=1e-6):
    """OpenMDAO-style check: the casadi Jacobian of ``problem``'s constraints at ``x`` against
    central finite differences of the same function. Returns the constraints at ``x``."""
    import numpy as np
    import pytest

    _, _, g, jac = problem.functions(x, params)
    jac = np.asarray(jac)
    for i in range(len(x)):
        step = np.zeros(len(x))
        step[i] = h
        up = np.asarray(problem.functions(x + step, params)[2]).ravel()
        down = np.asarray(problem.functions(x - step, params)[2]).ravel()
        assert jac[:, i] == pytest.approx((up - down) / (2 * h), rel=1e-5, abs=1e-7)
    return g


# ----------------------------------------------------------------- calibration fixtures
# unit/test_calibration_fit.py, unit/test_readings.py, e2e/test_cli_calibration.py,
# validation/test_calibration_closed_forms.py, validation/test_calibration_montecarlo.py

def calibration_record(key: str) -> dict:
    """``tests/data/cal_prototype_{key}.json``: the paper's Prototype A, B or C as design.json."""
    return json.loads((DATA / f"cal_prototype_{key}.json").read_text())


def calibration_constants(key: str):
    """What calibration knows of that design (``calibration.design_constants``)."""
    from designer.calibration import design_constants

    return design_constants(calibration_record(key))


def clean_prototype_b(seed=2, scheme="9"):
    """Prototype B's record, constants and noisy readings at a calibration scheme's loads."""
    from designer.calibration import readings

    return (calibration_record("b"), calibration_constants("b"),
            readings.simulated_scheme_readings(calibration_record("b"), scheme, seed=seed))


# A rectangle with holes whose mass optimum meets five limits at once, among them the fatigue
# limit at the hole, whose edge the model keeps at its nominal stress (no K_t of a hole is fitted,
# docs/model.md §7): in 3-D the hole's edge peaks above it. unit/test_optimize_stability.py,
# e2e/test_cli_optimize.py
SEVERAL_LIMITS_TEXT = """\
name: several-limits
load:
  force: [1.864 N, 44 N]
  position: [273.4 mm, 554.8 mm]
electronics:
  excitation: 10 V
  gain: 1.0
  noise: 0.001913 mV
gauge: BF120-3AA
bridge: half
limits:
  width: [3.605 mm, 30.7 mm]
  height: [3.161 mm, 22.33 mm]
targets:
  force_error: 2.22 %
  position_error: 9.212 mm
search:
  materials: [17-7PH-RH950]
  sections: [rectangle]
  feature: hole
objective: mass
tolerances: {class: none}  # nominal sizes: the limits that bind together are the nominal optimum's
"""


# A stubby lug (32 mm long, up to 16 mm high) on its deflection limit: its shear deformation and
# the clamp's give make it deflect more than Euler-Bernoulli theory in 3-D, and still about
# 1.036 x the model with its fitted shear on the coarse mesh (docs/model.md §4), which the loop
# then corrects. (Loaded from 28 mm: its gauges' stations, the first kept 0.65 heights from the
# clamp face, docs/model.md §7, need the room.) e2e/test_cli_verify_rounds.py
STUBBY_LUG = """\
name: stubby-lug
load:
  force: [2 N, 200 N]
  position: [28 mm, 32 mm]
electronics:
  excitation: 5 V
  gain: 128
  noise_rti: 50 nV
gauge: BF350-3AA
bridge: half
stations: 2
limits:
  max_deflection: 0.012 mm
  clamp_clearance: 2 mm
  load_clearance: 2 mm
  width: [4 mm, 16 mm]
  height: [3 mm, 16 mm]
targets:
  force_error: 5 %
  position_error: 5 mm
search:
  materials: [7075-T6]
  sections: [rectangle]
  feature: none
objective: error
"""
