"""Output folders and files are all or nothing (docs/spec.md, exit codes): a run that cannot put
every file in place leaves the folder exactly as it was, and its one line names the user's path,
never a scratch folder or temporary file."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from designer.cli import main
from designer.outputs import files
from designer.outputs.part import MAX_FILE_STEM

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def snapshot(folder: Path) -> dict:
    """Every entry under ``folder``: a file's bytes, a folder as None."""
    return {p.relative_to(folder).as_posix(): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def test_a_folder_in_the_way_of_an_output_is_named_and_nothing_is_moved(tmp_path, capsys):
    out = tmp_path / "out"
    (out / "report.md").mkdir(parents=True)      # design.json would go in first, then report.md fails
    (out / "my-notes.txt").write_text("kept")
    before = snapshot(out)
    assert main(["evaluate", str(EXAMPLES / "prototype-a.yaml"), "-o", str(out), "--no-cad", "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == f"fpdesign: error: cannot write {out / 'report.md'}: a folder is in the way"
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]    # no hidden scratch folder


def _fail_on(monkeypatch, name: str, error: BaseException):
    """``os.replace`` in designer.outputs.files raising ``error`` when it moves a file to ``name``."""
    real = os.replace

    def replace(src, dst, *args, **kwargs):
        if Path(dst).name == name == Path(src).name:   # the staged file, not the old one put back
            raise error
        return real(src, dst, *args, **kwargs)

    monkeypatch.setattr(files.os, "replace", replace)


@pytest.mark.parametrize("error", [PermissionError(13, "Permission denied"), KeyboardInterrupt()])
def test_a_move_that_fails_midway_puts_the_old_files_back_and_takes_the_new_ones_out(tmp_path, monkeypatch,
                                                                                     error):
    out = tmp_path / "out"
    out.mkdir()
    for name in ("a.txt", "c.txt"):
        (out / name).write_text(f"old {name}")
    before = snapshot(out)
    _fail_on(monkeypatch, "c.txt", error)    # after a.txt (replaced) and b.txt (new) are in place
    with pytest.raises(type(error)) as raised:
        with files.staged_directory(out) as scratch:
            for name in ("a.txt", "b.txt", "c.txt"):
                (scratch / name).write_text(f"new {name}")
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    if isinstance(error, OSError):
        assert raised.value.filename == str(out / "c.txt")


def test_a_failed_run_removes_the_folders_it_made(tmp_path, monkeypatch):
    out = tmp_path / "new" / "out"
    _fail_on(monkeypatch, "b.txt", PermissionError(13, "Permission denied"))
    with pytest.raises(PermissionError):
        with files.staged_directory(out) as scratch:
            for name in ("a.txt", "b.txt"):
                (scratch / name).write_text(name)
    assert list(tmp_path.iterdir()) == []


def test_an_error_while_writing_names_the_file_in_the_output_folder(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(OSError) as raised:
        with files.staged_directory(out) as scratch:
            raise OSError(28, "No space left on device", str(scratch / "design.json"))
    assert raised.value.filename == str(out / "design.json")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("second", ["same", "dotted", "symlink", "hardlink"])
def test_two_outputs_that_name_one_file_are_refused_before_anything_is_written(tmp_path, capsys, second):
    design = Path(__file__).resolve().parents[1] / "data" / "cad_rect_pockets.json"
    folder = tmp_path / "p"
    folder.mkdir()
    first = folder / "beam.out"
    other = {"same": first, "dotted": folder / "." / "beam.out", "symlink": folder / "link.out",
             "hardlink": folder / "hard.out"}[second]
    if second == "symlink":
        other.symlink_to(first.name)
    if second == "hardlink":
        first.write_text("mine")
        os.link(first, other)
    before = snapshot(folder)
    assert main(["export", str(design), "--step", str(first), "--stl", str(other)]) == 2
    assert capsys.readouterr().err.strip() == (f"fpdesign: error: --step {first} and --stl {other} name the same "
                                               "file; give each output its own file")
    assert snapshot(folder) == before


def test_an_export_below_a_file_is_refused_before_any_folder_is_made(tmp_path, capsys):
    design = Path(__file__).resolve().parents[1] / "data" / "cad_rect_pockets.json"
    (tmp_path / "afile").write_text("x")
    before = snapshot(tmp_path)
    target = tmp_path / "afile" / "z.png"
    assert main(["export", str(design), "--step", str(tmp_path / "n1" / "ok.step"), "--png", str(target)]) == 2
    assert capsys.readouterr().err.strip() == (f"fpdesign: error: --png: {target} cannot be written: "
                                               f"{tmp_path / 'afile'} is a file, not a folder")
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("command, example, name", [("evaluate", "prototype-a.yaml", "report.md"),
                                                    ("evaluate", "prototype-a.yaml", "design.json"),
                                                    ("optimize", "probe.yaml", "report.md")])
def test_optimize_and_evaluate_refuse_to_write_over_their_own_spec(tmp_path, capsys, command, example, name):
    out = tmp_path / "out"
    out.mkdir()
    spec = out / name
    spec.write_bytes((EXAMPLES / example).read_bytes())
    before = snapshot(out)
    assert main([command, str(spec), "-o", str(out), "--no-cad", "--no-plots"]) == 2
    assert capsys.readouterr().err.strip() == (f"fpdesign: error: {spec} is the spec this command reads; write the "
                                               "outputs to another folder")
    assert snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


@pytest.mark.parametrize("how", ["spec", "option"])
def test_evaluate_refuses_to_write_over_a_catalogue_it_reads(tmp_path, capsys, how):
    out = tmp_path / "out"
    out.mkdir()
    catalogue = out / "report.md"
    catalogue.write_bytes((Path(__file__).resolve().parents[1] / "data" / "user-catalogue.yaml").read_bytes())
    spec = out / "spec.yaml"
    text = (EXAMPLES / "prototype-a.yaml").read_text(encoding="utf-8")
    spec.write_text(text + ("catalogue: report.md\n" if how == "spec" else ""), encoding="utf-8")
    before = snapshot(out)
    option = ["--catalogue", str(catalogue)] if how == "option" else []
    assert main(["evaluate", str(spec), "-o", str(out), "--no-cad", "--no-plots", *option]) == 2
    assert capsys.readouterr().err.strip() == (f"fpdesign: error: {catalogue} is the catalogue this command reads; "
                                               "write the outputs to another folder")
    assert snapshot(out) == before


def test_a_spec_listed_among_a_previous_run_s_outputs_is_not_removed(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    spec = out / "operating-region.png"      # a plot of an earlier run, which this one does not draw
    spec.write_bytes((EXAMPLES / "prototype-a.yaml").read_bytes())
    (out / "design.json").write_text('{"files": {"plots": ["operating-region.png"]}}')
    main(["evaluate", str(spec), "-o", str(out), "--no-cad", "--no-plots"])
    assert spec.read_bytes() == (EXAMPLES / "prototype-a.yaml").read_bytes()
    assert sorted(p.name for p in out.iterdir()) == ["design.json", "operating-region.png", "report.md"]


@pytest.mark.parametrize("name, stem", [
    ("a" * 300, "a" * MAX_FILE_STEM),
    ("gripper finger " * 30, ("gripper-finger-" * 30)[:MAX_FILE_STEM].rstrip("-")),
    ("Fühler", "Fuhler"),
])
def test_a_file_name_made_of_a_long_design_name_is_cut_to_its_first_characters(name, stem):
    from designer.outputs.cad import resolve
    from shared_inputs import cad_mutate

    beam = resolve(cad_mutate("prototype_c", lambda r: r["spec"].update(name=name)))
    assert beam.file_stem == stem and len(beam.file_stem) <= MAX_FILE_STEM
    assert beam.name == name.strip()     # the report, drawing and STEP keep the whole name


def test_a_file_whose_name_is_near_the_limit_is_written_through_its_temporary(tmp_path):
    path = tmp_path / ("b" * 250 + ".step")
    files.atomic_write_text(path, "model")
    with files.temporary_sibling(tmp_path / ("c" * 250 + ".stl")) as tmp:
        tmp.write_text("mesh")
    assert path.read_text() == "model"
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


def test_a_signal_after_the_outputs_are_moved_in_still_leaves_one_whole_run(tmp_path, monkeypatch, capsys):
    """Ctrl-C just after a run's files are moved into the folder, while its scratch folder is being
    removed: the previous run's files that this run did not write are removed all the same, no
    scratch folder is left, and the signal then stops the run (it had left the new design beside
    the old run's STEP and drawing, and the scratch folder)."""
    import signal

    from designer import interrupt

    out = tmp_path / "out"
    out.mkdir()
    (out / "old.step").write_text("the previous run's")
    real = files.shutil.rmtree

    def signalled(path, *args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)
        real(path, *args, **kwargs)

    restore = interrupt.install()
    try:
        monkeypatch.setattr(files.shutil, "rmtree", signalled)
        with pytest.raises(KeyboardInterrupt):
            with files.staged_directory(out, stale={"old.step"}) as scratch:
                (scratch / "design.json").write_text("{}")
        # and the run's one line says the outputs are whole (exit 130 had read as nothing written)
        from designer.cli import _stopped

        assert _stopped(signal.SIGINT) == 130
    finally:
        restore()
    assert snapshot(out) == {"design.json": b"{}"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert capsys.readouterr().err == f"fpdesign: interrupted after its outputs were put in place whole ({out})\n"


def test_a_file_that_cannot_be_written_leaves_no_folder_made_for_it(tmp_path):
    """A name too long for the file system: the error names it, and the folder made for it is
    removed again (an empty folder had been left behind with exit 2)."""
    target = tmp_path / "new" / "deeper" / ("a" * 300 + ".json")
    with pytest.raises(OSError):
        files.atomic_write_text(target, "{}")
    assert list(tmp_path.iterdir()) == []
