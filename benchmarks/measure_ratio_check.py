"""Does ``fpdesign measure``'s check against known loads tell a sensor that measures as
predicted from readings that do not fit its calibration?

``measure`` gives the RMS, over the rows with a load, of each estimate's error in units of its
predicted 1-sigma (``calibration.measurement.error_ratios``) and warns above
``CONSISTENT_RATIO``. For the weigh-bar example's design (low noise: the bridge offsets are many
sigma_V) and the paper's Prototype B (noise 1.3 mV), this calibrates N simulated sensors on the
4- and the 9-point scheme (sigma_V from the residuals, as ``calibrate`` does by default) and
measures a 7 x 7 grid of loads (Prototype B: the paper's loads) on

- the same sensor (independent noise): the ratio should stay under the threshold;
- a sensor whose first bridge's zero has moved by 2, 5 and 10 sigma_V since calibrating;
- another simulated sensor (other offsets);
- for the biaxial Prototype C, a sensor turned about its axis by 1 and 3 degrees since calibrating
  (its force and position read as calibrated; only the angle's ratio, the third, can tell).

It prints the median, the 99th percentile and the range of the larger of the force's and the
position's (biaxial: and the angle's) ratio, and how often each case is warned of. Run by hand
(about a minute):

    python benchmarks/measure_ratio_check.py [--sensors 300]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from designer import calibration as cal  # noqa: E402
from designer.calibration import readings as rd  # noqa: E402
from designer.calibration.measurement import CONSISTENT_RATIO, error_ratios  # noqa: E402


def designs() -> dict:
    from designer.result.pipeline import DesignOptions, design
    from designer.spec.reader import load_spec

    weigh_bar = design(load_spec(ROOT / "examples" / "weigh-bar.yaml"), DesignOptions(tradeoff=False)).record
    return {"weigh-bar": (weigh_bar, "grid"),
            "Prototype B": (rd.read_design(ROOT / "tests" / "data" / "cal_prototype_b.json"), "paper"),
            "Prototype C": (rd.read_design(ROOT / "tests" / "data" / "cal_prototype_c.json"), "paper")}


def ratios(record: dict, scheme: str, measured: str, seed: int, case: str) -> float:
    constants = cal.design_constants(record)
    fitted = cal.calibrate(rd.simulated_scheme_readings(record, scheme, seed), constants)
    loads = rd.simulated_scheme_readings(record, measured, seed)
    offsets = rd.simulated_sensor_offsets(record, seed)
    if case.startswith("zero"):
        offsets = offsets + np.eye(len(offsets))[0] * float(case.split()[1]) * fitted.noise
    elif case == "another sensor":
        offsets = rd.simulated_sensor_offsets(record, seed + 100_000)
    felt = loads.angle   # the angles the loads are applied at; the file gives loads.angle
    if case.startswith("turned"):
        felt = loads.angle + np.radians(float(case.split()[1]))
    data = rd.simulate_readings(record, loads.force, loads.position, np.random.default_rng([seed, 7]), felt,
                                offsets=offsets)
    return max(error_ratios(cal.measure_readings(fitted, data), loads.force, loads.position, loads.angle))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sensors", type=int, default=300)
    args = p.parse_args(argv)
    cases = ("same sensor", "zero 2", "zero 5", "zero 10", "another sensor")
    print(f"warned above {CONSISTENT_RATIO:g}; {args.sensors} simulated sensors per row\n")
    print("| design | scheme | measured | case | median | 99th pct | range | warned |")
    print("|---|---|---|---|---:|---:|---|---:|")
    for name, (record, measured) in designs().items():
        turns = ("turned 1", "turned 3") if cal.design_constants(record).axes == 2 else ()   # biaxial
        for scheme in ("4", "9"):
            for case in cases + turns:
                r = np.array([ratios(record, scheme, measured, seed, case) for seed in range(args.sensors)])
                label = (case.replace("zero", "zero moved by") + (" σ_V on bridge 1" if case.startswith("zero") else "")
                         + ("° about its axis" if case.startswith("turned") else ""))
                print(f"| {name} | {scheme}-point | {measured} | {label} | {np.median(r):.2f} | "
                      f"{np.quantile(r, 0.99):.2f} | {r.min():.2f}-{r.max():.2f} | "
                      f"{np.mean(r > CONSISTENT_RATIO):.0%} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
