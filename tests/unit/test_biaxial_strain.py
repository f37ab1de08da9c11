"""A biaxial sensor's gauge strain: the side features' factor against 3-D (docs/model.md §9)."""

import importlib.util
from pathlib import Path

import pytest

from designer.model import corrections
from designer.model.biaxial import BIAXIAL_STRAIN, biaxial_strain_factor
from designer.result.designfile import rebuild

# The 3-D study of benchmarks/biaxial_strain.md (the normal mesh, F along -Z; within 0.002 of the
# fine mesh where run): each station's 3-D gauge strain over the model's on the biaxial bar, over
# the same ratio on its single-axis twin (the same record with axes 1: no side features). R1-R4,
# X1-X3, L1, L2 round bars with flats, T1 a tube with flats, Q1-Q4 and L3 squares with slots.
BIAXIAL_OVER_TWIN_3D = {
    "R1": (0.9984, 0.9984), "R2": (0.9993, 0.9988), "R3": (0.9964, 0.9959), "R4": (0.9982, 0.9973),
    "T1": (1.0003, 1.0011), "X1": (0.9902, 0.9894, 0.9845), "X2": (0.9922, 0.9920, 0.9892),
    "X3": (0.9877, 0.9868, 0.9798), "L1": (0.9746, 0.9791, 0.9726), "L2": (1.0009, 0.9986, 0.9987),
    "Q1": (0.9901, 0.9899), "Q2": (0.9948, 0.9943), "Q3": (0.9827, 0.9823), "Q4": (0.9935, 0.9924),
    "L3": (0.9959, 0.9961)}


def _study():
    path = Path(__file__).resolve().parents[2] / "benchmarks" / "biaxial_strain.py"
    spec = importlib.util.spec_from_file_location("biaxial_strain", path)
    study = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(study)
    return study


@pytest.mark.parametrize("name", list(BIAXIAL_OVER_TWIN_3D))
def test_a_biaxial_sensor_s_side_features_lower_its_gauge_strain_as_in_3d(name):
    """The model takes off the side features' whole second moment; in 3-D a short feature shows
    only part of that step (a Ø18.3 mm bar with 7.5 mm flats read 2.1-2.7 % below its twin, with
    18 mm flats 0.1 %). The side features' factor meets that ratio at every station of the study
    within its room (the law's largest left-out error, which the gauge-strain limit and the
    accuracy targets keep on top of the single-axis fits'); without it (a factor of 1) the model
    missed L1 by 2.7 %."""
    study = _study()
    _, biaxial = rebuild(study.design(name, 2))
    _, twin = rebuild(study.design(name, 1))
    g, g1 = biaxial.geometry, twin.geometry
    room = BIAXIAL_STRAIN[g.section][2]
    factor = float(biaxial_strain_factor(g))
    assert biaxial_strain_factor(g1) == 1.0
    assert corrections.strain_allowance(g, corrections.load()) == pytest.approx(
        corrections.strain_allowance(g1, corrections.load()) + room, rel=1e-12)
    for measured in BIAXIAL_OVER_TWIN_3D[name]:
        assert abs(factor - measured) <= room, (factor, measured)
    # the corrected model's factors on each station are the twin's times the side features'
    table = corrections.load()
    for f2, f1 in zip(corrections.strain_factors(g, table), corrections.strain_factors(g1, table)):
        assert float(f2) == pytest.approx(float(f1) * factor, rel=1e-12)
