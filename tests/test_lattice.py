"""The lattice step is the one definition of pitch, footprint and phi_discrete that the scaling,
the pillar grid and the campaign estimate share."""

import math

import pytest

from fibril_hpc import Scene
from fibril_hpc.geometry.grid import Lattice, build_pillar_grid
from fibril_hpc.model import build_scene_model, scene_scaling


@pytest.mark.parametrize("phi,epd", [(0.16, 8), (0.16, 5), (0.3, 6.5), (0.05, 12)])
def test_lattice_is_what_the_grid_and_scaling_use(phi, epd):
    lat = Lattice.of(3, phi, epd)
    assert lat.pitch % 2 == 1 and lat.pitch >= 3
    assert lat.phi_discrete == len(lat.footprint) / lat.pitch**2
    # the discrete filling ratio approaches the nominal one (a staircase disc)
    assert abs(lat.phi_discrete / phi - 1) < 0.5
    grid = build_pillar_grid(3, phi, epd, 0.0, 0)
    assert (grid.pitch, grid.footprint, grid.n) == (lat.pitch, lat.footprint, lat.grid_side)
    assert grid.geometry.n_active == 9 * lat.elements_per_pillar
    scaling, pitch, fp = scene_scaling(Scene(n_side=3, phi=phi, elements_per_diameter=epd))
    assert (pitch, fp) == (lat.pitch, lat.footprint) and scaling.phi == lat.phi_discrete


def test_model_normalises_with_the_lattice():
    scene = Scene(n_side=2, elements_per_diameter=5, work_of_adhesion=2.0)
    model = build_scene_model(scene)
    lat = Lattice.of(2, scene.phi, 5)
    assert model.scaling == lat.scaling(2.0)
    assert math.isclose(model.geometry.h * lat.grid_side, 1.0)
