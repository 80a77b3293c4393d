"""The memory check's model (fibril_hpc/inputs/limits.py) against what a run really holds: the
estimate counts the scene's own active elements, one snapshot and two pillar-state maps per
preload of a grouped path, and bounds the peak resident memory of a real run from above without
overstating it twofold (the model before issue 35's measurement said 1.8-3.0 times the peak at
m >= 2 688)."""

import os
import subprocess
import sys

import pytest

from fibril_hpc import Scene
from fibril_hpc.errors import ConfigError
from fibril_hpc.geometry.grid import Lattice
from fibril_hpc.inputs import limits

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _active(scene):
    lat = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)
    return scene.n_side**2 * lat.elements_per_pillar


@pytest.mark.parametrize("kind", ["F_P", "d_tilde"])
def test_each_preload_of_a_path_adds_one_snapshot(kind):
    one = Scene(n_side=12, preset="fast", **{kind: (0.5,)})
    seven = one.replace(**{kind: tuple(0.5 * 2**i for i in range(7))})
    n = limits.memory_estimate(one)[1]
    # one snapshot, and two pillar states' n x n maps (at the preload, at the pull-off)
    per = limits.SNAPSHOT_BYTES_PER_ELEMENT * _active(one) + 2 * limits.STATE_MAP_BYTES * n * n
    assert limits.memory_estimate(seven)[0] - limits.memory_estimate(one)[0] == 6 * per
    assert limits.state_map_bytes(0, n) == 0
    assert limits.state_map_bytes(1, n) == (2 * 5 + 4) * n * n
    # a caller that knows the path (a campaign's task) overrides the scene's own count
    assert limits.memory_estimate(one, 7)[0] == limits.memory_estimate(seven)[0]
    assert limits.snapshot_bytes(0, 10) == 0
    assert limits.snapshot_bytes(2, 10) == (2 * limits.SNAPSHOT_BYTES_PER_ELEMENT
                                            + limits.SAVED_STATE_BYTES_PER_ELEMENT) * 10


def test_the_estimate_counts_the_pillars_elements_not_the_grid():
    """A sparse brush's coarse level is priced on its footprints (phi of the grid), and a square
    lattice pads to 4 nodes per pillar, so 10^5-10^6 pillars are not refused for memory they do
    not use (1 000 x 1 000 at 3 elements per diameter peaked at 6 005 MiB after three events,
    7.8-8.3 GiB before the kernel transform was built in blocks; once estimated 23 GiB)."""
    scene = Scene(n_side=1000, elements_per_diameter=3)
    need, n, m = limits.memory_estimate(scene)
    assert (n, m) == (7000, 14336)
    assert _active(scene) == 9_000_000 < n * n / 5
    assert 6005 * 2**20 < need < 1.5 * 6005 * 2**20
    block = scene.replace(solver=scene.solver.replace(preconditioner="block"))
    assert need - limits.memory_estimate(block)[0] == limits.lattice_bytes(10**6, 9_000_000, 4)


def test_check_memory_counts_the_paths_preloads():
    scene = Scene(n_side=100, preset="fast")
    one = limits.memory_estimate(scene, 1)[0]
    seven = limits.memory_estimate(scene, 7)[0]
    avail = (one + seven) // 2
    assert limits.check_memory(scene, available=avail, preloads=1) == one
    with pytest.raises(ConfigError, match="fits the"):
        limits.check_memory(scene, available=avail, preloads=7)


def test_a_campaign_task_holds_the_preloads_of_its_path(tmp_path):
    from fibril_hpc.campaign.plan.spec import load_spec

    def spec(**kw):
        grid = {"output": "o.h5", "scene": {"n_side": 4, "preset": "fast"}, "k_tilde": [1.0],
                "sigma_tilde": [0.1], "seeds": 2, **kw}
        path = tmp_path / "g.yaml"
        import yaml

        path.write_text(yaml.safe_dump(grid))
        return load_spec(str(path))

    assert spec(F_P=[0.5, 1.0, 2.0]).path_preloads() == 3
    assert spec(F_P=[0.5, 1.0, 2.0], group_preloads=False).path_preloads() == 1
    auto = spec(F_P="auto")
    assert auto.path_preloads() == len(auto.auto.start) == 7


@pytest.mark.slow
@pytest.mark.parametrize("n_side, epd", [(36, 6), (100, 5.64)])
def test_the_estimate_bounds_a_real_runs_peak_and_stays_close(n_side, epd):
    """benchmarks/scene_memory.py in a fresh process: the peak resident memory of a run stopped
    after three events, against the estimate the check compares with the memory available."""
    env = dict(os.environ, PYTHONPATH=ROOT, OMP_NUM_THREADS="1")
    r = subprocess.run([sys.executable, os.path.join(ROOT, "benchmarks", "scene_memory.py"),
                        str(n_side), str(epd)], capture_output=True, text=True, timeout=300,
                       env=env, cwd=ROOT)
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("n_side="))
    got = dict(kv.split("=", 1) for kv in line.split())
    ratio = float(got["estimate_over_peak"])
    # three events: further below the estimate than a whole run, whose growth it covers
    # (1.37-1.68 measured for these two; runs into the unloading 1.10-1.11)
    assert 1.0 <= ratio <= 1.9, line
