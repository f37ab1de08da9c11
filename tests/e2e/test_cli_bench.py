"""``fpdesign bench`` as a whole command (issue 5): its files, its table and its refusals."""

from __future__ import annotations

import pytest

from designer.cli import main

pytestmark = pytest.mark.slow


def test_bench_command_writes_its_files_and_prints_the_table(tmp_path, capsys):
    specs = tmp_path / "specs"
    specs.mkdir()
    out = tmp_path / "out"
    code = main(["bench", "--specs", str(specs), "--count", "2", "--methods", "ipopt,grid", "--levels", "3",
                 "-o", str(out), "--quiet"])
    text = capsys.readouterr().out
    assert code == 0
    assert (out / "bench.md").is_file() and (out / "bench.png").is_file()
    assert "ipopt" in text and "grid" in text and "median" in text


@pytest.mark.parametrize("argv, message", [
    (["--methods", "ipopt,newton"], "--methods: 'newton' is not a method"),
    (["--count", "-1"], "--count: -1 is not allowed; use 0 to 1000"),
    (["--specs", "no-such-folder"], "--specs: no-such-folder is not a folder"),
    (["--count", "0", "--specs", "EMPTY"], "nothing to run"),
])
def test_bench_bad_input_exits_2_with_a_message(argv, message, tmp_path, capsys):
    empty = tmp_path / "empty"
    empty.mkdir()
    argv = [str(empty) if a == "EMPTY" else a for a in argv]
    code = main(["bench", *argv, "-o", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()
