"""The files of the CAD model written by the library (designer.outputs.cad.write_cad_outputs):
their names and permissions. Slow: each test builds the OpenCascade solid and renders it.
"""

from __future__ import annotations

import os

import pytest

from designer.outputs import cad
from shared_inputs import cad_record as record

pytestmark = pytest.mark.slow


def test_write_cad_outputs_names_files_after_the_design(tmp_path):
    written = cad.write_cad_outputs(record("prototype_c"), tmp_path)
    assert {k: p.name for k, p in written.items()} == {
        "step": "prototype-c.step", "model_png": "prototype-c-model.png",
        "drawing_svg": "prototype-c-drawing.svg", "drawing_png": "prototype-c-drawing.png"}
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in written.values())
    assert cad.step_product_names(written["step"]) == ["prototype-c"]


def test_outputs_are_readable_like_ordinary_files(tmp_path):
    written = cad.write_cad_outputs(record("prototype_a"), tmp_path)
    mask = os.umask(0)
    os.umask(mask)
    for path in written.values():
        assert path.stat().st_mode & 0o777 == 0o666 & ~mask


def test_a_long_design_name_gives_files_named_after_its_first_characters(tmp_path):
    from designer.outputs.part import MAX_FILE_STEM
    from shared_inputs import cad_mutate

    long = cad_mutate("prototype_a", lambda r: r["spec"].update(name="x" * 300))
    written = cad.write_cad_outputs(long, tmp_path)
    assert written["step"].name == "x" * MAX_FILE_STEM + ".step"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in written.values())
