"""``python -m designer.cli``: the fpdesign command."""

from designer.cli import run

run()
