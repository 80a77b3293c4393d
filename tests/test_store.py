"""The single-run HDF5 file (``fibril-run --out``) reads back into the result that wrote it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fibril_hpc import Scene, StoreError, simulate
from fibril_hpc.io.store import read_result_file, write_result_file


def _same(a, b):
    return a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b))


def test_result_file_round_trip(tmp_path):
    res = simulate(Scene(n_side=2, elements_per_diameter=5, k_tilde=0.01, sigma_tilde=0.5,
                         F_P=(0.3, 1.0), seed=1))
    path = str(tmp_path / "r.h5")
    write_result_file(path, res)
    back = read_result_file(path)
    assert back.scene == res.scene and back.status == res.status == "ok"
    assert back.stats == res.stats and back.discretisation == res.discretisation
    assert np.array_equal(back.xi, res.xi) and np.array_equal(back.zeta_tilde, res.zeta_tilde)
    assert len(back.results) == len(res.results) == 2
    for x, y in zip(back.results, res.results):
        assert all(_same(x.summary()[k], v) for k, v in y.summary().items())
        for br in ("loading", "unloading"):
            cx, cy = getattr(x, br), getattr(y, br)
            assert all(np.array_equal(getattr(cx, f), getattr(cy, f))
                       for f in ("d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact"))
        for st in ("at_preload", "at_pulloff"):
            sx, sy = getattr(x, st), getattr(y, st)
            assert sx.d_tilde == sy.d_tilde
            assert np.array_equal(sx.contact_map, sy.contact_map)
            assert np.array_equal(sx.pressure_map, sy.pressure_map)
        assert np.array_equal(x.let_go_d_tilde, y.let_go_d_tilde, equal_nan=True)
    assert back.main.F_A == res.main.F_A > 0


def test_reading_a_non_result_file_is_one_error(tmp_path):
    bad = tmp_path / "x.h5"
    bad.write_text("not hdf5")
    with pytest.raises(StoreError, match="cannot open"):
        read_result_file(str(bad))
