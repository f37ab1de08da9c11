"""The example spec of the paper's Prototype B states the paper's numbers.

Reference: Noh et al. 2025 (shared/reference/noh2025-force-position-cantilever.txt), Table 1
(dimensions and bridge positions) and section 4.3 (1.3 mV noise; 200-2000 g at 15-45 cm).
"""

from __future__ import annotations

import pytest

from designer.spec import reader as spec_module

GF = 9.80665e-3  # N per gram-force


def test_the_prototype_b_example_is_the_papers_table_1(examples):
    # Noh et al. 2025, Table 1 (Prototype B) and section 4.3 (1.3 mV, 200-2000 g, 15-45 cm).
    s = spec_module.load_spec(examples / "prototype-b.yaml")
    assert s.design.material == "2024-T3"
    assert (s.design.section.width, s.design.section.height) == pytest.approx((12.7e-3, 12.7e-3), rel=1e-12)
    assert s.design.stations == pytest.approx((0.020, 0.100), rel=1e-12)
    assert s.design.feature.kind == "hole" and s.design.feature.diameter == pytest.approx(9.5e-3, rel=1e-12)
    assert s.free_length == pytest.approx(0.450, rel=1e-12)
    assert s.sigma_v == pytest.approx(1.3e-3, rel=1e-12)
    assert (s.load.force_min, s.load.force_max) == pytest.approx((200 * GF, 2000 * GF), rel=1e-12)
    assert (s.load.position_min, s.load.position_max) == pytest.approx((0.150, 0.450), rel=1e-12)
    assert s.bridge_factor == 2
