"""Shared test helpers: the repository root on sys.path and the example specs."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


@pytest.fixture(scope="session")
def examples() -> Path:
    """The folder of the paper's prototypes as spec files."""
    return ROOT / "examples"
