"""JSON files that no fpdesign command wrote: each gets one line and exit 2 (docs/spec.md, exit codes)."""

from pathlib import Path

import pytest

from designer.cli import main


@pytest.mark.parametrize("text, message", [
    ("[" * 100_000 + "]" * 100_000, "nested too deeply to be an fpdesign file"),
    ('{"version": 1, "status": NaN}', "status: NaN is not a JSON number"),
    ('{"version": 1, "status": Infinity}', "status: Infinity is not a JSON number"),
    ('{"version": 1, "design": {"stations": [0.01, -Infinity]}}',
     "design.stations[1]: -Infinity is not a JSON number"),
])
@pytest.mark.parametrize("command", [["verify"], ["export", "--step", "x.step"], ["plan"]])
def test_hostile_json_is_bad_input(tmp_path, capsys, command, text, message):
    path = tmp_path / "design.json"
    path.write_text(text)
    assert main([command[0], str(path), *command[1:]]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_evaluate_on_a_design_that_is_not_a_beam_is_bad_input_and_writes_nothing(tmp_path, capsys):
    spec = tmp_path / "spec.yaml"
    spec.write_text("""\
name: off-the-end
load: {force: [1 N, 20 N], position: [100 mm, 300 mm]}
electronics: {excitation: 5 V, gain: 500, noise: 1 mV}
design:
  material: 6061-T6
  section: {kind: rectangle, width: 10 mm, height: 5 mm}
  stations: [20 mm, 400 mm]
  feature: {kind: pocket, depth: 1 mm}
  length: 300 mm
""")
    out = tmp_path / "out"
    assert main(["evaluate", str(spec), "-o", str(out), "--no-plots", "--no-cad"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == ("fpdesign: error: design.stations[1]: 0.4 m (400 mm) is off the beam; must lie "
                           "between 0 and the free length 300 mm")
    assert not out.exists()


@pytest.fixture(scope="module")
def probe_record(tmp_path_factory):
    out = tmp_path_factory.mktemp("probe") / "out"
    examples = Path(__file__).resolve().parents[2] / "examples"
    assert main(["optimize", str(examples / "probe.yaml"), "-o", str(out), "--no-cad", "--no-plots", "--quiet"]) == 0
    return out / "design.json"


@pytest.mark.parametrize("args, message", [
    (["--draws", "2000000000"], "--draws: 2000000000 is not allowed; use 100 to 10,000,000"),
    (["--grid", "3000", "3000"], "--grid: NF = 3000 is not allowed; use 2 to 100"),
    (["--angle", "nan"], "--angle: nan is not allowed; give degrees from -360 to 360"),
])
def test_simulate_refuses_what_would_not_finish_or_means_nothing(probe_record, capsys, args, message):
    assert main(["simulate", str(probe_record), *args]) == 2
    assert capsys.readouterr().err.strip() == f"fpdesign: error: {message}"


def test_readings_repeats_are_bounded(probe_record, tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:   # argparse: usage and the error, exit 2
        from designer.cli import build_parser

        build_parser().parse_args(["simulate-readings", str(probe_record), "-o", str(tmp_path / "r.csv"),
                                   "--repeats", "100000000"])
    assert stop.value.code == 2 and "must be from 1 to 10000" in capsys.readouterr().err
    assert not (tmp_path / "r.csv").exists()


def test_measure_refuses_a_negative_noise(probe_record, tmp_path, capsys):
    readings, cal = tmp_path / "r.csv", tmp_path / "cal.json"
    assert main(["simulate-readings", str(probe_record), "-o", str(readings), "--scheme", "9"]) == 0
    assert main(["calibrate", str(readings), "-o", str(cal)]) == 0
    capsys.readouterr()
    assert main(["measure", str(cal), str(readings), "--noise", "-1 mV"]) == 2
    assert capsys.readouterr().err.strip() == "fpdesign: error: --noise: '-1 mV' must be positive"


def test_no_command_writes_over_its_own_input(probe_record, tmp_path, capsys):
    import shutil

    design = tmp_path / "design.json"
    shutil.copy(probe_record, design)
    readings = tmp_path / "r.csv"
    assert main(["simulate-readings", str(design), "-o", str(readings), "--scheme", "9"]) == 0
    before = design.read_bytes(), readings.read_bytes()
    capsys.readouterr()
    for argv, flag, path, what in [
            (["calibrate", str(readings), "-o", str(readings)], "-o", readings, "readings"),
            (["export", str(design), "--step", str(design)], "--step", design, "design.json"),
            (["plan", str(design), "-o", str(design)], "-o", design, "design.json"),
            (["simulate-readings", str(design), "-o", str(design)], "-o", design, "design.json")]:
        assert main(argv) == 2
        assert capsys.readouterr().err.strip() == (f"fpdesign: error: {flag}: {path} is the {what} this command "
                                                   "reads; write to another file")
    assert (design.read_bytes(), readings.read_bytes()) == before


def _edited(record_file, folder, path, value, command) -> list[str]:
    """``command`` (its output files named relative to ``folder``) on a copy of ``record_file`` in
    ``folder`` with the value at ``path`` set to ``value``."""
    import json

    record = json.loads(record_file.read_text())
    node = record
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    bad = folder / "design.json"
    bad.write_text(json.dumps(record))
    return [command[0], str(bad), *[str(folder / a) if "." in a else a for a in command[1:]]]


@pytest.mark.parametrize("path, value, message", [
    (("version",), 99, "version: 99 is not a design.json this fpdesign reads; it reads version 1"),
    (("design", "material_properties", "fatigue"), "abc",
     "design.material_properties.fatigue: 'abc' must be a number from 1 to 1e+13"),
    (("design", "material_properties", "poisson"), -5, "design.material_properties.poisson: -5 must be a number"),
    (("design", "section", "width"), 1e300, "design.section.width: 1e+300 must be at most 100"),
    # a beam shorter than the load region (verify had stopped with "the mesh has no face at the cut")
    (("design", "length"), 0.05, "design.length: 0.05 m (50 mm) is shorter than the largest load position"),
])
@pytest.mark.parametrize("command", [["verify", "-o", "v.out"], ["export", "--step", "x.step"], ["plan"], ["simulate"]])
def test_impossible_design_json_fields_are_bad_input(probe_record, tmp_path, capsys, path, value, message, command):
    import json

    if path == ("design", "section", "width") and json.loads(probe_record.read_text())["design"]["section"]["kind"] \
            != "rectangle":
        path = ("design", "section", "diameter")
        message = message.replace("width", "diameter")
    assert main(_edited(probe_record, tmp_path, path, value, command)) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.step").exists()


@pytest.mark.parametrize("path, value, message", [
    (("design", "bridge"), "third", "design.bridge: 'third' differs from spec.bridge ('half')"),
    (("design", "bridge"), "full", "design.bridge: 'full' differs from spec.bridge ('half')"),
    (("design", "axes"), 2, "design.axes: 2 differs from spec.axes (1)"),
    (("design", "gauge", "grid_length"), 0.002, "design.gauge.grid_length: 0.002 differs from spec.gauge.grid_length"),
])
@pytest.mark.parametrize("command", [["verify", "-o", "v.out"], ["export", "--step", "x.step"], ["plan"],
                                     ["plot", "-o", "plots.out"], ["simulate-readings", "-o", "r.csv"]])
def test_a_design_block_that_disagrees_with_its_spec_is_bad_input(probe_record, tmp_path, capsys, path, value,
                                                                   message, command):
    """design.json's design block repeats the spec's bridge, axes and gauge, and commands read one
    copy or the other (verify, export and plot the design's gauge; plan and the model the spec's).
    A hand edit of one copy was read by some commands and passed over by others (a bridge
    'third' planned, exported, plotted and simulated as the spec's half bridge, exit 0); now
    every command refuses it naming the key, with nothing written."""
    assert main(_edited(probe_record, tmp_path, path, value, command)) == 2
    err = capsys.readouterr().err
    assert message in err and "give both the same" in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.json"]


def test_a_design_noise_beyond_any_reading_is_bad_input(tmp_path, capsys):
    """predicted.noise_voltage of 1e300 V overflowed plan and was written into readings by
    simulate-readings: every command that uses sigma_V refuses it, naming the key, the value
    and the bound, and writes nothing; sigma_V at the bound is still read."""
    import json

    from designer.calibration.design import LARGEST_NOISE

    good = Path(__file__).resolve().parents[1] / "data" / "cal_prototype_b.json"
    readings = tmp_path / "r.csv"
    assert main(["simulate-readings", str(good), "-o", str(readings), "--scheme", "9"]) == 0
    record = json.loads(good.read_text())
    record["predicted"]["noise_voltage"] = 1e300
    bad = tmp_path / "design.json"
    bad.write_text(json.dumps(record))
    before = sorted(p.name for p in tmp_path.iterdir())
    for argv in (["plan", str(bad), "-o", str(tmp_path / "plan.csv")],
                 ["simulate-readings", str(bad), "-o", str(tmp_path / "r2.csv")],
                 ["calibrate", str(readings), "--design", str(bad), "-o", str(tmp_path / "c.json")]):
        capsys.readouterr()
        assert main(argv) == 2
        err = capsys.readouterr().err
        named = f"--design {bad}: " if argv[0] == "calibrate" else ""   # (calibrate reads two files)
        assert err.startswith(f"fpdesign: error: {named}predicted.noise_voltage: {1e300!r} V ") and "Traceback" not in err
        assert f"at most {LARGEST_NOISE:g} V" in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    record["predicted"]["noise_voltage"] = LARGEST_NOISE
    bad.write_text(json.dumps(record))
    assert main(["plan", str(bad)]) == 0


def _every_d_as_the_first(record):
    for b in record["bridges"]:
        b["d"] = record["bridges"][0]["d"]


@pytest.mark.parametrize("edit, key, words", [
    (_every_d_as_the_first, "bridges[0].d, bridges[1].d, bridges[2].d", "two different distances"),
    (lambda r: r["bridges"][0].update(unscaled_covariance=[[-1, 0, 0], [0, -1, 0], [0, 0, -1]]),
     "bridges[0].unscaled_covariance", "(a variance) that is not positive"),
    (lambda r: r["bridges"][1].update(unscaled_covariance=[[1, 2, 0], [2, 1, 0], [0, 0, 1]]),
     "bridges[1].unscaled_covariance", "not positive semi-definite"),
    (lambda r: r["bridges"][1].update(d=1e300), "bridges[1].d", repr(1e300)),
    (lambda r: r["bridges"][1].update(k=1e200), "bridges[1].k", repr(1e200)),
    (lambda r: r["bridges"][2].update(k=r["bridges"][2]["se_k"]), "bridges[2].k", "within 3 standard errors"),
])
def test_a_calibration_that_cannot_measure_is_bad_input(tmp_path, capsys, edit, key, words):
    """Hand-edited calibration.json that measure took with exit 0 and answered with NaN: bridges
    of one axis at one station d, a covariance with negative variances, a station or k beyond any
    beam, a k not told from zero. Each is refused on reading, naming the key; nothing is written."""
    import json

    from designer import calibration as cal
    from designer.calibration import readings as rd
    from shared_inputs import clean_prototype_b

    _, dc, r = clean_prototype_b()
    record = cal.calibrate(r, dc).to_dict()
    edit(record)
    path, results = tmp_path / "calibration.json", tmp_path / "results.csv"
    path.write_text(json.dumps(record))
    src = rd.write_readings(tmp_path / "readings.csv", r)
    assert main(["measure", str(path), str(src), "-o", str(results)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"fpdesign: error: {path}: {key}: ") and words in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not results.exists()


def test_calibration_residuals_must_be_numbers(probe_record, tmp_path, capsys):
    import json

    readings, cal = tmp_path / "r.csv", tmp_path / "cal.json"
    assert main(["simulate-readings", str(probe_record), "-o", str(readings), "--scheme", "9"]) == 0
    assert main(["calibrate", str(readings), "-o", str(cal)]) == 0
    record = json.loads(cal.read_text())
    record["bridges"][0]["residuals"] = ["abc"]
    cal.write_text(json.dumps(record))
    capsys.readouterr()
    assert main(["measure", str(cal), str(readings)]) == 2
    assert "bridges[0].residuals: ['abc'] must be a list of numbers (V)" in capsys.readouterr().err


def test_a_reversed_calibration_span_and_absurd_readings_are_bad_input(probe_record, tmp_path, capsys):
    import json

    readings, cal = tmp_path / "r.csv", tmp_path / "cal.json"
    assert main(["simulate-readings", str(probe_record), "-o", str(readings), "--scheme", "9"]) == 0
    assert main(["calibrate", str(readings), "-o", str(cal)]) == 0
    record = json.loads(cal.read_text())
    record["span"]["force"] = record["span"]["force"][::-1]
    cal.write_text(json.dumps(record))
    capsys.readouterr()
    assert main(["measure", str(cal), str(readings)]) == 2
    assert "span.force: " in capsys.readouterr().err
    lines = readings.read_text().splitlines()
    cells = lines[2].split(",")
    cells[-1] = "1e308"
    lines[2] = ",".join(cells)
    readings.write_text("\n".join(lines) + "\n")
    assert main(["calibrate", str(readings), "-o", str(tmp_path / "c2.json")]) == 2
    assert "line 3, column V2: '1e308' is beyond what a reading can be" in capsys.readouterr().err
    assert not (tmp_path / "c2.json").exists()


def test_a_material_name_read_as_a_number_says_to_quote_it(tmp_path, capsys):
    spec = tmp_path / "spec.yaml"
    spec.write_text("load: {force: [1 N, 20 N], position: [100 mm, 300 mm]}\n"
                    "electronics: {excitation: 5 V, gain: 500, noise: 1 mV}\nsearch: {materials: [304]}\n")
    assert main(["optimize", str(spec), "-o", str(tmp_path / "out"), "--no-cad", "--no-plots"]) == 2
    assert 'search.materials[0]: 304 was read as a number; quote a name that looks like one ("304")' in \
        capsys.readouterr().err


HEAVY = {
    "alias bomb": ("spec", "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(8))),
    "a 2 MB spec": ("spec", "load: {force: [1 N, 20 N], position: [100 mm, 300 mm]}\nname: " + "x" * 2_000_000 + "\n"),
    "a far position": ("spec", "load: {force: [1 N, 20 N], position: [40 mm, 1e6 km]}\n"
                               "electronics: {excitation: 5 V, gain: 500, noise: 1 mV}\n"),
    "a power tower": ("spec", "load: {force: [1 N, '10**10**10 N'], position: [100 mm, 300 mm]}\n"
                              "electronics: {excitation: 5 V, gain: 500, noise: 1 mV}\n"),
}


# Runs a command in a grandchild and prints its exit code, its peak memory (kB, from wait4) and
# its standard error. A child forked from the test runner would carry the runner's memory in its
# peak (Linux keeps the high-water mark across fork and exec); this small launcher does not.
LAUNCHER = """
import json, os, subprocess, sys
proc = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
err = proc.stderr.read().decode()
_, status, usage = os.wait4(proc.pid, 0)
print(json.dumps([os.waitstatus_to_exitcode(status), usage.ru_maxrss, err]))
"""


def _measured(argv):
    """``(exit code, peak memory MB, stderr, seconds)`` of ``fpdesign argv`` in a process of its own."""
    import json
    import subprocess
    import sys
    import time

    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", LAUNCHER, sys.executable, "-m", "designer.cli", *argv],
                         check=True, capture_output=True, text=True).stdout
    code, peak_kb, err = json.loads(out)
    return code, peak_kb / 1024, err, time.perf_counter() - t0


@pytest.mark.parametrize("name", list(HEAVY))
def test_inputs_built_to_exhaust_time_or_memory_stop_at_once(tmp_path, name):
    # under 1 GB (the interpreter and the spec reader take about 60 MB) and 10 s
    _, text = HEAVY[name]
    spec = tmp_path / "spec.yaml"
    spec.write_text(text)
    code, peak_mb, err, seconds = _measured(["optimize", str(spec), "-o", str(tmp_path / "out"), "--no-cad",
                                             "--no-plots"])
    assert code == 2, err
    assert err.startswith("fpdesign: error: ") and len(err.strip().splitlines()) == 1
    assert seconds < 10 and peak_mb < 1024
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("args", [["--draws", "2000000000"], ["--grid", "3000", "3000"]])
def test_simulate_sizes_built_to_exhaust_memory_stop_at_once(probe_record, tmp_path, args):
    code, peak_mb, err, seconds = _measured(["simulate", str(probe_record), *args])
    assert code == 2 and peak_mb < 1024 and seconds < 10, err


def test_a_design_json_with_a_byte_order_mark_reads_as_without_it(tmp_path):
    # RFC 8259 section 8.1: a parser may ignore a BOM; spec.yaml and readings.csv already do
    from designer.result.designfile import read_json

    source = Path(__file__).resolve().parents[1] / "data" / "plot_prototype_b.json"
    marked = tmp_path / "design.json"
    marked.write_bytes(b"\xef\xbb\xbf" + source.read_bytes())
    assert read_json(marked) == read_json(source)


def test_an_unknown_key_of_design_json_s_spec_is_named_as_the_file_holds_it(tmp_path, capsys):
    # design.json's spec holds the spec's keys one level down: spec.colour, not spec.spec.colour
    import json

    source = Path(__file__).resolve().parents[1] / "data" / "plot_prototype_b.json"
    record = json.loads(source.read_text())
    record["spec"]["colour"] = "red"
    path = tmp_path / "design.json"
    path.write_text(json.dumps(record))
    assert main(["plan", str(path)]) == 2
    assert capsys.readouterr().err.startswith("fpdesign: error: spec.colour: unknown key")


@pytest.mark.parametrize("value, message", [
    ({"material": "2024-T3", "bogus": 1}, "spec.design.bogus: unknown key"),
    ({"material": "unobtainium"}, "spec.design.material: 'unobtainium'"),
    ("abc", "spec.design: 'abc' must be a mapping"),
])
@pytest.mark.parametrize("command", [["plan"], ["export", "--step", "x.step"]])
def test_the_spec_design_block_of_a_design_json_is_checked(probe_record, tmp_path, capsys, value, message, command):
    """docs/spec.md §4: design.json's spec is read back as a spec.yaml is, every key checked;
    its ``design`` block (a fixed design's) was dropped unread, any content exit 0."""
    assert main(_edited(probe_record, tmp_path, ("spec", "design"), value, command)) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.json"]


def test_an_empty_path_or_noise_is_bad_input(probe_record, tmp_path, capsys, monkeypatch):
    """'' (an unset shell variable) named the current folder: evaluate wrote design.json and the
    report there, plot drew beside design.json, measure --noise '' took the calibration's noise."""
    monkeypatch.chdir(tmp_path)
    examples = Path(__file__).resolve().parents[2] / "examples"
    readings, cal = tmp_path / "r.csv", tmp_path / "cal.json"
    assert main(["simulate-readings", str(probe_record), "-o", str(readings), "--scheme", "9"]) == 0
    assert main(["calibrate", str(readings), "-o", str(cal)]) == 0
    capsys.readouterr()
    before = sorted(p.name for p in tmp_path.iterdir())
    for argv, wanted in [
            (["evaluate", str(examples / "prototype-b.yaml"), "-o", "", "--no-cad", "--no-plots", "--quiet"],
             "-o: '' is empty; give a folder for design.json and the report"),
            (["plot", str(probe_record), "-o", ""], "-o: '' is empty; give a folder for the plots"),
            (["measure", str(cal), str(readings), "-o", ""], "-o: '' is empty; give a file name"),
            (["measure", str(cal), str(readings), "--noise", ""], "--noise: '' cannot be read")]:
        assert main(argv) == 2
        assert capsys.readouterr().err.strip().startswith(f"fpdesign: error: {wanted}")
    assert sorted(p.name for p in tmp_path.iterdir()) == before
