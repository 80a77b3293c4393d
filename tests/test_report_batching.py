"""The report names the groups loaded in batches wider than today's bound (a tenth of the brush's
length spread), by what their records say: the scene's load_merge_spread, or a record finished
before the bound existed (tests/data/real18_k1.h5 was made on 2026-11-24, before it)."""

import os

import pytest

from fibril_hpc import load_campaign
from fibril_hpc.campaign.analysis import batching
from fibril_hpc.campaign.analysis.report_data import build

FIXTURE = os.path.join(os.path.dirname(__file__), "data", "real18_k1.h5")


def _job(sigma=0.07, finished="2026-11-24T19:23:19+00:00", spread=None, lem=0.1):
    solver = f"solver:\n  load_event_merge: {lem}\n" + (
        f"  load_merge_spread: {spread}\n" if spread is not None else "")
    return {"status": "done", "k_tilde": 1.0, "sigma_tilde": sigma, "finished": finished,
            "scene_yaml": f"n_side: 18\nsigma_tilde: {sigma}\n" + solver}


def test_a_record_is_coarse_only_where_its_batch_exceeded_the_bound_by_what_it_records():
    assert batching.coarse_loading(_job())                              # before the bound
    assert not batching.coarse_loading(_job(finished="2026-11-26T10:00:00+00:00"))
    assert not batching.coarse_loading(_job(finished=None))             # unknown: not named
    assert not batching.coarse_loading(_job(sigma=2.1))                 # 0.1 d_c < 0.1 s there
    assert not batching.coarse_loading(_job(sigma=0.07, lem=0.005))     # 0.005 d_c < 0.1 s
    assert batching.coarse_loading(_job(sigma=0.07, lem=0.01))          # 0.01 d_c > 0.1 s
    # set in the scene: the record says so whatever its date
    late = "2026-11-26T10:00:00+00:00"
    assert batching.coarse_loading(_job(finished=late, spread=100.0))
    assert not batching.coarse_loading(_job(finished=late, spread=0.1))
    assert not batching.coarse_loading(_job(finished=late, spread=0.01))
    assert not batching.coarse_loading({"status": "done", "sigma_tilde": 0.07})


def test_the_older_real_file_has_its_smooth_groups_named_on_the_page():
    c = load_campaign(FIXTURE, curves=False)
    assert batching.coarse_groups(c.jobs) == [(1.0, 0.07), (1.0, 0.164), (1.0, 0.384),
                                             (1.0, 0.898)]
    d = build(c, FIXTURE, n_boot=20)
    assert d.coarse == [(1.0, 0.07), (1.0, 0.164), (1.0, 0.384), (1.0, 0.898)]
    said = [n for n in d.notes if "batches wider than" in n]
    assert len(said) == 1 and "(1, 0.07), (1, 0.164), (1, 0.384), (1, 0.898)" in said[0]
    assert "(1, 2.1)" not in said[0] and "Rerun" in said[0]


@pytest.mark.parametrize("finished", ["2026-11-26T10:00:00+00:00", None])
def test_records_after_the_bound_or_without_a_time_are_not_named(finished):
    c = load_campaign(FIXTURE, curves=False)
    for j in c.jobs:
        j["finished"] = finished
    assert batching.coarse_groups(c.jobs) == []
