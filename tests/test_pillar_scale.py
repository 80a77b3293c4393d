"""benchmarks/pillar_scale.py's grids: the same pillars at every size, and the far field asked
for (the 100 x 100 rough rows ran under ``far_field: multipole``; docs/finite-size.md)."""

import math

import pytest

from benchmarks.pillar_scale import grid_of
from fibril_hpc.campaign.plan.spec import spec_from_dict


@pytest.mark.parametrize("far_field", ["exact", "multipole"])
def test_a_size_s_grid_is_a_valid_campaign_of_the_reference_pillars(far_field):
    grid = grid_of(100, [1.0, 0.01], [0.5], 18, 3, "fast", 0.16, far_field=far_field)
    spec = spec_from_dict(grid)
    assert spec.base.n_side == 100
    assert spec.base.solver.far_field == far_field
    assert grid["k_tilde"] == pytest.approx([0.18, 0.0018])
    assert grid["sigma_tilde"] == pytest.approx([0.5 * math.sqrt(0.18)])
    # the reference's grid text carries no far_field, so its job keys are those of old files
    assert ("far_field" in grid["scene"]["solver"]) == (far_field != "exact")
    assert (far_field in grid["description"]) == (far_field != "exact")
