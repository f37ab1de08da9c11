"""Front-ends of the catalogue (``electronics.adc``, materials/frontends.yaml): their noise, range
and counts against closed forms and the datasheets' own figures, the input-range limit, and bad
input (docs/spec.md §2.2, docs/model.md §3)."""

import json
import math

import pytest

from designer.errors import SpecError
from designer.spec.reader import parse_spec

LOAD = {"force": ["0.5 N", "20 N"], "position": ["30 mm", "100 mm"]}
DESIGN = {"material": "6061-T6", "section": {"kind": "rectangle", "width": "10 mm", "height": "4 mm"},
          "stations": ["10 mm", "25 mm"], "feature": {"kind": "none"}}


def _spec(electronics, gauge="BF350-3AA", bridge="half", design=DESIGN, **rest):
    return parse_spec({"load": LOAD, "electronics": electronics, "gauge": gauge, "bridge": bridge,
                       "design": design, **rest})


def test_johnson_noise_is_the_textbook_figure():
    """sqrt(4 k T R B): 1 kΩ at 300 K has the familiar 4.07 nV/√Hz, and 10 kΩ in 10 kHz 1.3 µV RMS
    (Horowitz & Hill, The Art of Electronics, 3rd ed., §8.1.1, at room temperature)."""
    from designer.model.electronics import johnson_noise

    assert johnson_noise(1e3, 1.0, 300.0) == pytest.approx(4.07e-9, rel=2e-3)
    assert johnson_noise(1e4, 1e4, 300.0) == pytest.approx(1.3e-6, rel=0.01)
    # over a bandwidth B it grows as sqrt(B): 10 Hz readings have a noise bandwidth of 5 Hz
    assert johnson_noise(350.0, 5.0, 300.0) == pytest.approx(4.07e-9 * math.sqrt(0.35 * 5), rel=2e-3)


def test_hx711_at_10_hz_and_gain_128_has_the_datasheet_s_noise_range_and_codes():
    """HX711 datasheet, Key Electrical Characteristics: 50 nV RMS input noise at gain 128 and 10 Hz
    (90 nV at 80 Hz), input range ±0.5·AVDD/gain (±19.53 mV at 5 V), 24-bit two's complement: one
    code is 2·19.53 mV / 2^24 = 2.33 nV. To it the model adds the 350 Ω bridge's Johnson noise in
    5 Hz and the quantisation step / sqrt(12), in quadrature."""
    spec = _spec({"adc": "HX711", "rate": "10 Hz", "excitation": "5 V"})
    e, fe = spec.electronics, spec.front_end_noise
    assert e.gain == 128  # the highest gain it offers, unless given
    assert fe.converter == pytest.approx(50e-9)
    assert fe.full_scale == pytest.approx(0.5 * 5 / 128)
    assert fe.step == pytest.approx(2 * 0.5 * 5 / 128 / 2 ** 24)
    assert fe.counts_per_volt == pytest.approx(2 ** 24 * 128 / 5)
    johnson = math.sqrt(4 * 1.380649e-23 * 296.15 * 350 * 5)
    total = math.sqrt(50e-9 ** 2 + johnson ** 2 + (fe.step / math.sqrt(12)) ** 2)
    assert spec.sigma_v == pytest.approx(128 * total, rel=1e-12)
    assert 50e-9 < total < 50.4e-9  # the converter's noise dominates a 350 ohm bridge
    fast = _spec({"adc": "HX711", "rate": "80 Hz", "excitation": "5 V"}).front_end_noise
    assert fast.converter == pytest.approx(90e-9)
    assert fast.johnson == pytest.approx(johnson * math.sqrt(8))


def test_an_amplifier_front_end_adds_its_density_over_the_noise_bandwidth_and_the_converter_s_step():
    """An instrumentation amplifier of white noise density e_n before an N-bit converter: e_n·sqrt(rate/2)
    at its input, and a code of 2·0.5·V_ref/gain/2^N."""
    from designer.spec import frontends

    amp = next(fe for fe in frontends.catalogue().values() if fe.kind == "amplifier")
    spec = _spec({"adc": amp.name, "gain": amp.gain_range[1] / 2, "rate": "100 Hz", "bits": 12, "reference": "3.3 V",
                  "excitation": "3.3 V"})
    fe, gain = spec.front_end_noise, amp.gain_range[1] / 2
    assert fe.converter == pytest.approx(amp.noise_density * math.sqrt(50))
    assert fe.step == pytest.approx(3.3 / gain / 2 ** 12)
    assert fe.quantisation == pytest.approx(fe.step / math.sqrt(12))


def _bridge_output(spec, evaluation):
    """V_s·G·n·ε/4 at station 1 for F_max at x_max (the paper's eq. 4 with the bridge factor n)."""
    return (spec.electronics.excitation * spec.gauge.factor * spec.bridge_factor
            * evaluation.analysis.gauge_strain[0] / 4)


def test_the_input_range_is_a_limit_on_the_bridge_output_at_full_load():
    """A 10 x 4 mm 6061 bar at 20 N, 100 mm: the plain-beam strain at 10 mm is M y / (E I) =
    20·0.09·0.002/(68.9e9·10·4³/12e12) = 980 µε; a full bridge of G = 2 at 5 V gives 4.9 mV, inside
    the HX711's ±19.5 mV at gain 128. At 100 N it gives 24.5 mV: the input saturates."""
    from designer.result.evaluation import evaluate, fixed_design

    spec = _spec({"adc": "HX711", "excitation": "5 V"}, bridge="full")
    ev = evaluate(fixed_design(spec), spec)
    strain = 20 * 0.090 * 0.002 / (68.9e9 * 0.010 * 0.004 ** 3 / 12)
    assert ev.analysis.gauge_strain[0] == pytest.approx(strain, rel=0.05)  # the clamp factor near the root
    limit = next(lim for lim in ev.limits if lim.name == "adc_range")
    assert limit.value == pytest.approx(_bridge_output(spec, ev))
    assert limit.rating == pytest.approx(0.5 * 5 / 128) and float(limit.normalised) < 0
    heavy = parse_spec({"load": {"force": ["0.5 N", "100 N"], "position": LOAD["position"]},
                        "electronics": {"adc": "HX711", "excitation": "5 V"}, "gauge": "BF350-3AA",
                        "bridge": "full", "design": DESIGN})
    over = evaluate(fixed_design(heavy), heavy)
    assert "adc_range" in [lim.name for lim in over.violations]
    assert _bridge_output(heavy, over) > 0.5 * 5 / 128


def test_design_json_gives_the_full_load_output_in_mv_per_v_and_counts(tmp_path):
    """predicted.front_end: output per station in V/V and in counts (V_s·output / code step)."""
    from designer.result.evaluation import evaluate, fixed_design
    from designer.result.record import build_record

    spec = _spec({"adc": "HX711", "rate": "80 Hz", "excitation": "5 V"})
    ev = evaluate(fixed_design(spec), spec)
    fe = build_record("feasible", spec, ev)["predicted"]["front_end"]
    per_volt = [2.0 * 2 * s / 4 for s in ev.analysis.gauge_strain]
    assert fe["output_per_volt"] == pytest.approx(per_volt)
    assert fe["output_counts"] == pytest.approx([v * 5 * 2 ** 24 * 128 / 5 for v in per_volt])
    assert fe["full_scale_per_volt"] == pytest.approx(0.5 / 128)
    assert fe["noise"]["converter"] == pytest.approx(90e-9) and fe["rate"] == 80
    json.dumps(fe)


@pytest.mark.parametrize("electronics, key, allowed", [
    ({"adc": "HX712", "excitation": "5 V"}, "electronics.adc", "HX711"),
    ({"adc": "HX711", "rate": "20 Hz", "excitation": "5 V"}, "electronics.rate", "10 Hz, 80 Hz"),
    ({"adc": "HX711", "gain": 100, "excitation": "5 V"}, "electronics.gain", "128"),
    ({"adc": "HX711", "excitation": "12 V"}, "electronics.excitation", "2.6 V to 5.5 V"),
    ({"adc": "HX711", "excitation": "5 V", "noise_rti": "50 nV"}, "electronics.noise_rti", "one or the other"),
    ({"adc": "HX711", "excitation": "5 V", "bits": 16}, "electronics.bits", "amplifier"),
    ({"excitation": "5 V", "gain": 128, "noise_rti": "50 nV", "rate": "10 Hz"}, "electronics.rate", "electronics.adc"),
    # the INA333's density is given from 0.1 Hz to 1 kHz (SBOS445C 6.5): a noise bandwidth (rate / 2) of
    # 0.5 uHz made the noise 1000 times smaller than the datasheet says anywhere
    ({"adc": "INA333", "gain": 100, "rate": "1 uHz", "bits": 16, "excitation": "5 V"}, "electronics.rate",
     "0.2 Hz to 2000 Hz"),
    ({"adc": "INA333", "gain": 100, "rate": "10 kHz", "bits": 16, "excitation": "5 V"}, "electronics.rate",
     "0.2 Hz to 2000 Hz"),
    # its output swings within its supply, at most 5.5 V: a converter's range centred on 50 V cannot be reached
    ({"adc": "INA333", "gain": 100, "rate": "10 Hz", "bits": 16, "reference": "100 V", "excitation": "5 V"},
     "electronics.reference", "at most 5.5 V"),
])
def test_bad_front_end_input_names_the_key_the_value_and_what_is_allowed(electronics, key, allowed):
    with pytest.raises(SpecError) as err:
        _spec(electronics)
    message = str(err.value)
    assert message.startswith(key) and allowed in message and "\n" not in message


def test_every_catalogue_front_end_names_its_datasheet_and_offers_a_setting():
    from designer.spec import frontends

    table = frontends.catalogue()
    assert {"HX711"} <= set(table)
    for fe in table.values():
        assert len(fe.source) > 40
        if fe.kind == "adc":
            assert fe.rates() and all(fe.gains(r) for r in fe.rates())
        else:
            assert fe.noise_density > 0 and fe.gain_range[0] < fe.gain_range[1]


@pytest.mark.parametrize("name, gain, rate, nv", [
    ("ADS1232", 128, "10 Hz", 17), ("ADS1234", 128, "80 Hz", 44),   # SBAS350G Tables 7-1, 7-2 (5 V)
    ("AD7190", 128, "4.7 Hz", 8.5), ("AD7190", 1, "4800 Hz", 14300),  # AD7190 Rev. C Table 6 (sinc4, chop off)
    ("ADS1220", 128, "20 Hz", 90), ("NAU7802", 128, "80 Hz", 150),    # SBAS501C Table 1; NAU7802 Rev 2.1 Features
])
def test_the_converter_noise_is_the_datasheet_s_at_that_gain_and_rate(name, gain, rate, nv):
    fe = _spec({"adc": name, "gain": gain, "rate": rate, "excitation": "5 V"}).front_end_noise
    assert fe.converter == pytest.approx(nv * 1e-9)


# ----------------------------------------------------------------- readings in counts

SPEC_TEXT = """name: counted
load: {force: [0.5 N, 20 N], position: [40 mm, 110 mm]}
electronics: {adc: HX711, rate: 10 Hz, excitation: 5 V}
gauge: BF350-3AA
bridge: half
design:
  material: 6061-T6
  section: {kind: round, diameter: 8 mm}
  stations: [10 mm, 30 mm]
  feature: {kind: none}
"""


def _design(tmp_path):
    from designer.cli import main

    (tmp_path / "spec.yaml").write_text(SPEC_TEXT)
    assert main(["evaluate", str(tmp_path / "spec.yaml"), "-o", str(tmp_path / "out"), "--no-cad",
                 "--no-plots"]) == 0
    return tmp_path / "out" / "design.json"


def test_one_hx711_count_is_avdd_over_2_to_the_24_at_the_amplifier_output(tmp_path):
    """HX711: ±0.5·AVDD/gain over 2^24 codes at the input, times the gain: AVDD / 2^24 = 0.298 µV per
    count at 5 V, whatever the gain."""
    from designer.calibration.design import design_constants
    from designer.calibration.readings import read_design

    constants = design_constants(read_design(_design(tmp_path)))
    assert constants.volts_per_count == pytest.approx(5 / 2 ** 24, rel=1e-12)
    assert constants.noise / constants.volts_per_count == pytest.approx(128 * 50.29e-9 / (5 / 2 ** 24), rel=1e-3)


def test_calibrate_and_measure_read_counts_as_the_same_volts(tmp_path):
    """Readings simulated in counts (rounded to whole counts) calibrate to the same k and d as the
    same readings in volts, within the rounding (a count is 1/22 of the noise), and measure alike."""
    import json

    import numpy as np

    from designer.calibration import readings as rd
    from designer.cli import main

    design = _design(tmp_path)
    for unit, extra in (("volts", []), ("counts", ["--counts"])):
        assert main(["simulate-readings", str(design), "-o", str(tmp_path / f"cal-{unit}.csv"), "--scheme", "9",
                     *extra]) == 0
        assert main(["simulate-readings", str(design), "-o", str(tmp_path / f"use-{unit}.csv"), "--scheme", "grid",
                     *extra]) == 0
        assert main(["calibrate", str(tmp_path / f"cal-{unit}.csv"), "--design", str(design), "-o",
                     str(tmp_path / f"cal-{unit}.json")]) == 0
        assert main(["measure", str(tmp_path / f"cal-{unit}.json"), str(tmp_path / f"use-{unit}.csv"), "-o",
                     str(tmp_path / f"res-{unit}.csv")]) == 0
    assert "C1,C2" in (tmp_path / "cal-counts.csv").read_text()
    cal = {u: json.loads((tmp_path / f"cal-{u}.json").read_text()) for u in ("volts", "counts")}
    for bv, bc in zip(cal["volts"]["bridges"], cal["counts"]["bridges"]):
        assert bc["k"] == pytest.approx(bv["k"], rel=1e-4) and bc["d"] == pytest.approx(bv["d"], abs=2e-6)
    assert cal["counts"]["volts_per_count"] == pytest.approx(5 / 2 ** 24)
    volts, counts = (rd.parse_readings((tmp_path / f"use-{u}.csv").read_text()) for u in ("volts", "counts"))
    assert counts.counts and np.all(counts.voltages == np.round(counts.voltages))
    assert np.allclose(counts.voltages * 5 / 2 ** 24, volts.voltages, atol=5 / 2 ** 25 * 1.0001)


def test_counts_without_a_front_end_to_convert_them_are_refused(tmp_path, capsys):
    from designer.calibration.readings import parse_readings
    from designer.cli import main
    from designer.errors import CsvError

    design = _design(tmp_path)
    assert main(["simulate-readings", str(design), "-o", str(tmp_path / "cal.csv"), "--scheme", "9", "--counts"]) == 0
    assert main(["calibrate", str(tmp_path / "cal.csv"), "-o", str(tmp_path / "cal.json")]) == 2
    err = capsys.readouterr().err
    assert "counts (C1, C2, ...)" in err and "--design" in err and not (tmp_path / "cal.json").exists()
    with pytest.raises(CsvError, match="mix volts"):
        parse_readings("mass_g,position_mm,V1,C2\n100,50,0.1,200\n")


def test_a_file_in_counts_is_named_by_its_own_columns(tmp_path, capsys):
    """Messages about a readings file in counts name its columns (C2), not the volts they are
    converted to (V2), and do not give a count as volts."""
    from designer.cli import main

    design = _design(tmp_path)
    src = tmp_path / "cal.csv"
    assert main(["simulate-readings", str(design), "-o", str(src), "--scheme", "9", "--counts"]) == 0
    rows = [line.split(",") if not line.startswith("#") else line for line in src.read_text().splitlines()]
    header = next(r for r in rows if isinstance(r, list))
    dead = header.index("C2")
    text = "\n".join(r if isinstance(r, str) else ",".join(c if i != dead or r is header else "0"
                                                               for i, c in enumerate(r)) for r in rows)
    src.write_text(text + "\n")
    capsys.readouterr()
    assert main(["calibrate", str(src), "--design", str(design), "-o", str(tmp_path / "cal.json")]) == 2
    err = capsys.readouterr().err
    assert "column C2: does not respond to the load: it reads the same count in every row" in err
    assert "V2" not in err and " V in every row" not in err
    no_first = "\n".join(r if isinstance(r, str) else ",".join(c for i, c in enumerate(r) if i != header.index("C1"))
                          for r in rows)
    src.write_text(no_first + "\n")
    assert main(["calibrate", str(src), "--design", str(design), "-o", str(tmp_path / "cal.json")]) == 2
    assert "bridge columns ['C2'] must be ['C1', 'C2']" in capsys.readouterr().err


def test_an_unknown_front_end_exits_2_with_the_catalogue_s_names(tmp_path, capsys):
    from designer.cli import main

    (tmp_path / "spec.yaml").write_text(SPEC_TEXT.replace("adc: HX711", "adc: HX717"))
    assert main(["evaluate", str(tmp_path / "spec.yaml"), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"]) == 2
    err = capsys.readouterr().err.strip()
    assert "electronics.adc: 'HX717'" in err and "HX711" in err and "AD7190" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "out").exists()
