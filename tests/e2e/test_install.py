"""The installed command works from any folder (the README's first command).

conftest.py puts the source tree on sys.path for the other tests; these run the installed
console script in a clean folder, so a module or data file missing from the package fails here.
"""

import json
import os
import shutil
import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow


def _fpdesign():
    path = shutil.which("fpdesign") or os.path.join(os.path.dirname(sys.executable), "fpdesign")
    if not os.path.exists(path):
        pytest.fail("the fpdesign command is not installed: run `python -m pip install \".[test]\"` first")
    return path


def _clean_env():
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    return env


def test_installed_command_lists_every_command(tmp_path):
    out = subprocess.run([_fpdesign(), "--help"], cwd=tmp_path, env=_clean_env(), capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    for command in ("optimize", "evaluate", "simulate", "materials", "export", "plot", "plan", "calibrate",
                    "measure", "verify"):
        assert command in out.stdout


def test_installed_catalogue_reads_from_any_folder(tmp_path):
    out = subprocess.run([_fpdesign(), "materials", "--json"], cwd=tmp_path, env=_clean_env(),
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert len(data["materials"]) >= 8 and len(data["gauges"]) >= 3
