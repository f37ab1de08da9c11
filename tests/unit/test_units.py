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


# ----------------------------------------------------------------- the YAML a spec may be written in

SPEC = """\
load: {force: [1 N, 20 N], position: [100 mm, 300 mm]}
electronics: {excitation: 5 V, gain: 500, noise: 1 mV}
"""


@pytest.mark.parametrize("text, message", [
    (SPEC + "bridge: half\nbridge: full\n", "line 4: the key 'bridge' is given twice (first at line 3)"),
    ("load: &l {force: [1 N, 20 N], position: [100 mm, 300 mm]}\nelectronics: {excitation: 5 V, noise: 1 mV}\n"
     "name: *l\n", "line 3: YAML aliases (*l) are not allowed"),
    (SPEC + "name: " + "[" * 500 + "]" * 500 + "\n", "nested more than 20 levels deep"),
    (SPEC + "name: " + "x" * 1_100_000 + "\n", "a spec or catalogue file is at most 1 MB"),
])
def test_a_spec_in_yaml_a_spec_never_needs_is_refused(text, message):
    from designer.spec.reader import parse_spec_text

    t0 = time.perf_counter()
    with pytest.raises(SpecError) as err:
        parse_spec_text(text, source="spec.yaml")
    assert time.perf_counter() - t0 < 1.0
    assert str(err.value).startswith("spec.yaml: ") and message in str(err.value)
    assert len(str(err.value)) < 300


def test_an_alias_bomb_is_refused_before_it_expands():
    from designer.spec.reader import parse_spec_text

    bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(8))
    t0 = time.perf_counter()
    with pytest.raises(SpecError, match="aliases"):
        parse_spec_text(bomb)
    assert time.perf_counter() - t0 < 1.0


@pytest.mark.parametrize("text, kind, message", [
    ("1e300 N", "force", "between 1e-09 N and 1e+06 N"),
    ("1e6 km", "length", "between 1e-09 m and 100 m"),
    ("1e300 V", "voltage", "between 1e-15 V and 1000 V"),
    (1e300, "ratio", "between 1e-12 and 1e+10"),
    ("1e-30 N", "force", "between 1e-09 N and 1e+06 N"),
])
def test_magnitudes_beyond_what_fpdesign_handles_name_the_range(text, kind, message):
    with pytest.raises(SpecError) as err:
        units.parse(text, kind, "key")
    assert str(err.value).startswith("key: ") and "outside what fpdesign handles" in str(err.value)
    assert message in str(err.value)


def test_zero_stays_allowed_where_a_key_allows_it():
    assert units.parse_positive("0 mm", "length", "limits.load_clearance", allow_zero=True) == 0.0


@pytest.mark.parametrize("trouble", ["unwritable", "half-written"])
def test_the_units_are_the_same_whatever_becomes_of_pint_s_cache(tmp_path, trouble):
    # The registry keeps pint's parsed definitions in the user's cache folder (XDG_CACHE_HOME);
    # a folder that cannot be written, or a cache file cut short by another run, leaves it reading
    # the definitions itself. Reference: NIST SP 811 factors, as above, in a fresh process each.
    import os
    import subprocess
    import sys

    cache = tmp_path / "cache"
    if trouble == "unwritable":
        cache.write_text("a file where the cache folder would be")
    code = ("from designer.spec import units; print(units.parse('2 lbf', 'force', 'k'), "
            "units.parse('0.5 in', 'length', 'k'), units.parse('1500 ue', 'strain', 'k'))")
    env = dict(os.environ, XDG_CACHE_HOME=str(cache))
    first = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True).stdout
    if trouble == "half-written":
        pickles = list((cache / "pint").glob("*.pickle"))
        assert pickles, "the first run wrote pint's cache"
        for path in pickles:
            path.write_bytes(path.read_bytes()[:100])
    again = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True).stdout
    for out in (first, again):
        force, length, strain = map(float, out.split())
        assert force == pytest.approx(2 * 4.4482216152605, rel=1e-12)
        assert length == pytest.approx(0.0127, rel=1e-12) and strain == pytest.approx(1.5e-3, rel=1e-12)


@pytest.mark.parametrize("text, kind", [
    ("2 rad", "ratio"), ("5 deg", "ratio"), ("3 sr", "ratio"), ("128 count", "ratio"), ("0.1 rad", "strain"),
    ("60 rpm", "frequency"), ("100 rad/s", "frequency"), ("2 turn/s", "frequency"),
])
def test_angles_revolutions_and_counts_are_refused_not_read_as_numbers(text, kind):
    """pint's radian, steradian and count are units of no dimension: it converts '2 rad' to the
    plain number 2 and, since 1 revolution = 2 pi rad, '60 rpm' to 2 pi Hz (60 rpm is one cycle a
    second, 1 Hz) and '100 rad/s' to 100 Hz (an angular frequency of 100 rad/s is 100 / 2 pi =
    15.9 Hz). A spec never needs one, so each is refused naming the key and what is allowed."""
    what = "a count" if "count" in text else "an angle"
    with pytest.raises(SpecError) as err:
        units.parse(text, kind, "limits.min_frequency")
    assert str(err.value) == (f"limits.min_frequency: {text!r} has the wrong units: it holds {what}, which "
                              f"fpdesign does not convert; expected {units.KINDS[kind][2]}")


@pytest.mark.parametrize("text, kind", [("40 dB", "ratio"), ("20 decibel", "ratio"), ("3 Np", "ratio"),
                                        ("1 octave", "ratio"), ("10 dBm", "voltage")])
def test_logarithmic_units_are_refused_not_read_as_power_ratios(text, kind):
    """pint reads dB as a power ratio, 10^(dB/10): '40 dB' of gain became 10 000 where an amplifier's
    40 dB is a voltage gain of 100 (20 log10 100); which ratio a user means is not in the text, so
    it is refused, naming the key and the unit."""
    with pytest.raises(SpecError) as err:
        units.parse(text, kind, "electronics.gain")
    message = str(err.value)
    assert message.startswith(f"electronics.gain: {text!r} has a logarithmic unit (")
    assert message.endswith(units.KINDS[kind][2])


@pytest.mark.parametrize("text, kind, si", [("128 dimensionless", "ratio", 128.0), ("3 mm/m", "ratio", 0.003),
                                            ("5 ppm", "ratio", 5e-6), ("100 Hz", "frequency", 100.0)])
def test_plain_ratios_and_frequencies_still_read(text, kind, si):
    assert units.parse(text, kind, "key") == pytest.approx(si, rel=1e-12)


def test_a_plain_number_named_dimensionless_is_no_frequency():
    """'128 dimensionless' is a plain number: a ratio, never 128 Hz."""
    with pytest.raises(SpecError, match="'128 dimensionless' has the wrong units; expected a frequency"):
        units.parse("128 dimensionless", "frequency", "limits.min_frequency")
