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
