"""Shared test helpers: the repository root and this folder on sys.path (for shared_inputs.py),
and the example specs.

Layout: unit/ (one module or function at a time), validation/ (against the paper, textbooks
and Monte Carlo, each test naming its source), e2e/ (whole commands). Tests marked ``slow``
(FEA, bench, whole commands, 3-D CAD solids, the optimiser against the reference search) are
left out by ``python -m pytest -m "not slow"``."""

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
for folder in (ROOT, ROOT / "tests"):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))


@pytest.fixture(scope="session")
def examples() -> Path:
    """The folder of the paper's prototypes as spec files."""
    return ROOT / "examples"


@pytest.fixture(scope="module")
def proto_b() -> dict:
    """Prototype B's design.json as the plot tests read it (tests/data/plot_prototype_b.json)."""
    from designer.result.designfile import load_design

    return load_design(ROOT / "tests" / "data" / "plot_prototype_b.json")


@pytest.fixture(scope="module")
def proto_c() -> dict:
    """Prototype C's design.json as the plot tests read it (tests/data/plot_prototype_c.json)."""
    from designer.result.designfile import load_design

    return load_design(ROOT / "tests" / "data" / "plot_prototype_c.json")


@pytest.fixture(autouse=True)
def shipped_catalogue():
    """Each test starts and ends with the shipped catalogue alone in force: a spec with a user
    catalogue (``catalogue:``) puts it in force for the process (designer.spec.catalogue.use)."""
    from designer.spec import catalogue

    catalogue.use(())
    yield
    catalogue.use(())
