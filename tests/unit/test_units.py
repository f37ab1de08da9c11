"""Quantities in a spec: a number and one unit, nothing else (docs/spec.md, units)."""

import time

import pytest

from designer.errors import SpecError
from designer.spec import units


@pytest.mark.parametrize("text, kind, si", [
    ("50 N", "force", 50.0), ("2 lbf", "force", 2 * 4.4482216152605), ("0.5 in", "length", 0.0127),
    (".5 mm", "length", 0.5e-3), ("1500 ue", "strain", 1.5e-3), ("1500 µε", "strain", 1.5e-3),
    ("2700 kg/m^3", "density", 2700.0), ("2700 kg / m ** 3", "density", 2700.0), ("1 %", "ratio", 0.01),
    ("120 Ω", "resistance", 120.0), ("1.3 mV", "voltage", 1.3e-3), ("68.9 GPa", "pressure", 68.9e9),
    ("5e-3", "ratio", 5e-3), ("4 kN", "force", 4000.0),
])
def test_a_number_and_a_unit_in_si(text, kind, si):
    # conversion factors: 1 lbf = 4.4482216152605 N and 1 in = 25.4 mm exactly (NIST SP 811)
    assert units.parse(text, kind, "key") == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize("text", ["3 N 4", "N", "2 mm 3", "10**10**10 N", "2**100000 N", "3 * 4 N", "(2+3) N",
                                  "1e99999 N", "N" * 5000])
def test_anything_but_a_number_and_a_unit_is_refused_at_once(text):
    t0 = time.perf_counter()
    with pytest.raises(SpecError) as err:
        units.parse(text, "force", "load.force[1]")
    assert time.perf_counter() - t0 < 1.0
    message = str(err.value)
    assert message.startswith("load.force[1]: ") and "expected a force" in message
    assert len(message) < 300   # a long value is cut, not printed whole


def test_an_overflowing_number_is_not_finite():
    with pytest.raises(SpecError, match="not a finite number"):
        units.parse("1e400 N", "force", "key")
