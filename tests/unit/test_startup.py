"""`fpdesign --help` starts fast: building the command line loads no numerical library."""

import subprocess
import sys


def test_the_command_line_is_built_without_numerical_libraries():
    code = ("import sys; from designer.cli import build_parser; build_parser().format_help(); "
            "print(sorted(m for m in ('numpy', 'scipy', 'casadi', 'matplotlib', 'cadquery', 'pint', 'yaml', 'rich') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"
