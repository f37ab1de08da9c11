"""JSON files that no fpdesign command wrote: each gets one line and exit 2 (docs/spec.md, exit codes)."""

import pytest

from designer.cli import main


@pytest.mark.parametrize("text, message", [
    ("[" * 100_000 + "]" * 100_000, "nested too deeply to be an fpdesign file"),
    ('{"version": 1, "status": NaN}', "NaN is not a JSON number"),
    ('{"version": 1, "status": Infinity}', "Infinity is not a JSON number"),
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
