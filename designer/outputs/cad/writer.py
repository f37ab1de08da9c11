"""Writing a design's CAD outputs together: all of them or none.

``export(record, step=..., stl=..., svg=..., png=..., drawing_png=...)`` writes the files the
``export`` command asks for; ``write_cad_outputs(record, out_dir)`` the ones ``optimize`` and
``evaluate`` write. Every file is made in a temporary file beside its target, and all are
moved into place only when every one succeeded; a device or FIFO among the targets (which
cannot be put back) is written first, so that a failure there leaves no file written.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from designer.outputs.cad.beam import resolve
from designer.outputs.cad.mesh import model_meshes
from designer.outputs.cad.solid import build_solid
from designer.outputs.cad.step import step_file, stl_file
from designer.outputs.drawing.figures import figure_bytes
from designer.outputs.drawing.picture import plot_model
from designer.outputs.drawing.sheet import plot_drawing
from designer.outputs.files import (commit, file_mode, is_special, make_folders, move_into_place, naming,
                                     remove_folders, temp_prefix)
from designer.outputs.part import BeamCad


def export(record: dict, step=None, stl=None, svg=None, png=None, drawing_png=None) -> dict[str, Path]:
    """Write the requested files for a design.json record; returns ``{kind: path}``.

    ``step``/``stl``: the solid; ``svg``/``drawing_png``: the dimensioned drawing; ``png``: a
    picture of the 3-D model. The record is checked first, every file is made in a temporary
    file beside its target and all are moved into place only when every one succeeded.
    """
    wanted = {k: Path(v) for k, v in (("step", step), ("stl", stl), ("svg", svg), ("png", png),
                                      ("drawing_png", drawing_png)) if v is not None}
    beam = resolve(record)
    if not wanted:
        return {}
    solid = build_solid(beam)
    return _write_all(beam, solid, wanted)


def write_cad_outputs(design: dict, out_dir: str | os.PathLike) -> dict[str, Path]:
    """The CAD outputs of ``optimize`` and ``evaluate`` in ``out_dir``.

    ``design`` is the design.json record (with its ``spec`` and ``design``). Writes
    ``<name>.step``, ``<name>-model.png`` (the 3-D picture), ``<name>-drawing.svg`` and
    ``<name>-drawing.png`` (the dimensioned drawing); returns ``{"step", "model_png",
    "drawing_svg", "drawing_png"}`` -> path.
    """
    beam = resolve(design)
    out_dir = Path(out_dir)
    stem = beam.file_stem
    wanted = {"step": out_dir / f"{stem}.step", "png": out_dir / f"{stem}-model.png",
              "svg": out_dir / f"{stem}-drawing.svg", "drawing_png": out_dir / f"{stem}-drawing.png"}
    written = _write_all(beam, build_solid(beam), wanted)
    names = {"step": "step", "png": "model_png", "svg": "drawing_svg", "drawing_png": "drawing_png"}
    return {names[k]: v for k, v in written.items()}


def _write_all(beam: BeamCad, solid, wanted: dict[str, Path]) -> dict[str, Path]:
    """Make every file in a temporary file, beside its target (in the temporary folder for a
    device or FIFO); then write the devices and FIFOs, and then move the regular files into
    place (``commit``). Should anything fail, no regular file is written and the folders made
    for them are removed. The drawing is drawn once for both of its formats."""
    staged: list[tuple[Path, Path]] = []
    made: list[Path] = []
    sheet = None
    try:
        for kind, target in wanted.items():
            special = is_special(target)
            if not special:
                made += make_folders(target.parent)
            with naming(target):
                fd, tmp = tempfile.mkstemp(prefix=temp_prefix(target), suffix=".tmp",
                                           dir=None if special else target.parent)
                os.close(fd)
                tmp = Path(tmp)
                staged.append((tmp, target))
                if kind == "step":
                    step_file(solid, tmp, beam.name)
                elif kind == "stl":
                    stl_file(solid, tmp)
                elif kind == "png":
                    tmp.write_bytes(figure_bytes(plot_model(model_meshes(beam, solid), beam), "png"))
                else:
                    sheet = sheet or plot_drawing(beam)
                    tmp.write_bytes(figure_bytes(sheet, "svg" if kind == "svg" else "png"))
                os.chmod(tmp, file_mode())
        for tmp, target in staged:
            if is_special(target):
                move_into_place(tmp, target)
        commit([(tmp, target) for tmp, target in staged if not is_special(target)])
    except BaseException:
        _remove(staged)
        remove_folders(made)
        raise
    finally:
        _remove(staged)
    return dict(wanted)


def _remove(staged) -> None:
    for tmp, _ in staged:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
