"""The package's own YAML files (designer.spec.strict_yaml.load_shipped): read with libyaml's
parser where PyYAML has it, to the same content as PyYAML's pure-Python safe loader gives."""

import statistics
import time

import pytest
import yaml

from designer.spec import strict_yaml
from designer.spec.catalogue import data_folder

SHIPPED = sorted(p.name for p in data_folder().glob("*.yaml"))


@pytest.mark.parametrize("name", SHIPPED)
def test_a_shipped_file_reads_as_the_pure_python_safe_loader_reads_it(name):
    text = (data_folder() / name).read_text(encoding="utf-8")
    assert strict_yaml.load_shipped(text) == yaml.load(text, Loader=yaml.SafeLoader)  # noqa: S506


def test_a_key_given_twice_in_a_shipped_file_is_refused_with_both_lines():
    with pytest.raises(strict_yaml.StrictYamlError, match=r"line 3: the key 'name' is given twice \(first at line 1\)"):
        strict_yaml.load_shipped("name: a\nsource: b\nname: c\n")


@pytest.mark.skipif(not yaml.__with_libyaml__, reason="PyYAML without libyaml: the pure-Python parser either way")
def test_the_shipped_stock_table_reads_at_least_twice_as_fast_as_a_user_s_file():
    # measured 0.005 s against 0.038 s on a 2-core machine; 2x leaves room for a noisy one
    text = (data_folder() / "stock.yaml").read_text(encoding="utf-8")

    def seconds(load):
        t = time.perf_counter()
        load(text)
        return time.perf_counter() - t

    shipped, strict = zip(*[(seconds(strict_yaml.load_shipped), seconds(strict_yaml.load)) for _ in range(5)])
    assert statistics.median(strict) > 2 * statistics.median(shipped)
