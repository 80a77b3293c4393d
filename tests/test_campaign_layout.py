"""The campaign file layout and job keys are a contract: a file written by fibril-hpc 0.1.0
(tests/data/campaign_v1.h5, 2 of the 4 jobs of tests/data/campaign_v1.yaml done) must keep
opening, reading and resuming, and new records must be written with exactly the same names and
types."""

from __future__ import annotations

import os
import shutil

import h5py
import numpy as np

from fibril_hpc import load_campaign
from fibril_hpc.campaign import load_spec

DATA = os.path.join(os.path.dirname(__file__), "data")

# pinned from the file written by the 0.1.0 code path (never derive these from the package)
ROOT_ATTRS = {"campaign_hash", "campaign_yaml", "created", "definitions", "extended_from",
              "fibril_hpc_version", "format_version", "key_definition", "layout", "n_jobs",
              "program", "updated", "versions"}
JOB_ATTRS = {
    "key": str, "record_id": str, "campaign_hash": str, "k_tilde": float, "sigma_tilde": float,
    "preload_kind": str, "preload": float, "seed": int, "status": str, "message": str,
    "F_P": float, "F_A": float, "d_tilde_max": float, "d_tilde_at_F_A": float,
    "n_pillars_in_contact_max": int, "events": int, "wall_s": float, "cg_iterations": int,
    "cg_solves": int, "fft_pairs": int, "group_size": int, "rank": int, "host": str,
    "finished": str, "scene_yaml": str, "discretisation": str}
CURVES = {"d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact"}
# added by issue 11 (compliant loading machine): stored ONLY in records of a job whose machine is
# compliant (k_machine < inf), so every rigid-machine record keeps exactly JOB_ATTRS and CURVES
MACHINE_ATTRS = {"k_machine": float, "jumps": int, "F_jump": float,
                 "d_machine_tilde_at_F_A": float}
MACHINE_CURVES = {"d_machine_tilde"}
# added by issue 35: stored ONLY in records of a job solved with solver.confirm: local
CONFIRM_ATTRS = {"confirmed_local": int, "confirmed_global": int, "force_bound_tilde": float}
KEYS = ["52d55445e650803d", "6cdb31efcacc928f", "9a5a5bc296898b92", "03f94282c0d232fd"]
DONE_IN_FIXTURE = {"9a5a5bc296898b92", "03f94282c0d232fd"}
CAMPAIGN_HASH = "673945ce0c7e0c12a6d676aa9c92a731dba3875c381a754498ccb8226d599000"


def _kind(v):
    if isinstance(v, (bytes, str)):
        return str
    if isinstance(v, (np.integer, int)):
        return int
    if isinstance(v, (np.floating, float)):
        return float
    return type(v)


def check_layout(path, keys):
    with h5py.File(path, "r") as fh:
        assert set(fh.attrs) == ROOT_ATTRS
        assert fh.attrs["program"] == "fibril-hpc campaign"
        assert int(fh.attrs["format_version"]) == 1
        assert set(fh["jobs"]) == set(keys)
        for k in keys:
            g = fh["jobs"][k]
            kinds = {a: _kind(v) for a, v in g.attrs.items()}
            # the one addition since 0.1.0: records written now carry a checksum (issue 12);
            # old records have none, and old readers ignore it
            assert kinds.pop("checksum", str) is str
            assert kinds == JOB_ATTRS, k
            assert g.attrs["key"] == k
            if g.attrs["status"] == "done":
                for br in ("loading", "unloading"):
                    assert set(g[br]) == CURVES
                    assert g[br]["d_tilde"].dtype == np.float64
                    assert g[br]["n_pillars_in_contact"].dtype.kind == "i"


def test_job_keys_and_hash_are_unchanged():
    spec = load_spec(os.path.join(DATA, "campaign_v1.yaml"))
    assert [j.key for j in spec.jobs] == KEYS
    assert spec.campaign_hash == CAMPAIGN_HASH


def test_fixture_layout_and_reader():
    path = os.path.join(DATA, "campaign_v1.h5")
    check_layout(path, DONE_IN_FIXTURE)
    # its records predate checksums: unchecked, so left out unless asked for (issue 18)
    assert len(load_campaign(path)) == 0
    c = load_campaign(path, include_unchecked=True)
    assert c.unchecked == DONE_IN_FIXTURE
    assert {j["key"] for j in c.jobs} == DONE_IN_FIXTURE
    for j in c.jobs:
        assert j["status"] == "done" and j["F_A"] > 0 and j["F_P"] > 0
        assert len(j["unloading"]["F_tilde"]) > 2
    assert set(c.table) >= {"key", "F_P", "F_A", "status", "wall_s", "record_id"}


def test_old_file_resumes_with_same_layout(tmp_path):
    from fibril_hpc.campaign.run.runner import run_serial

    for name in ("campaign_v1.yaml", "campaign_v1.h5"):
        shutil.copy(os.path.join(DATA, name), tmp_path / name)
    before = {j["key"]: j for j in load_campaign(str(tmp_path / "campaign_v1.h5"),
                                                 include_unchecked=True).jobs}
    spec = load_spec(str(tmp_path / "campaign_v1.yaml"))
    assert run_serial(spec, progress=False) == 0
    path = str(tmp_path / "campaign_v1.h5")
    check_layout(path, KEYS)
    after = {j["key"]: j for j in load_campaign(path, include_unchecked=True).jobs}
    for k, old in before.items():      # the finished jobs are not recomputed (nor re-signed)
        assert after[k]["record_id"] == old["record_id"]
        assert repr(after[k]["F_A"]) == repr(old["F_A"])
    assert all(after[k]["status"] == "done" for k in KEYS)
    assert load_campaign(path, include_unchecked=True).unchecked == set(before)


def test_record_schema_derives_every_list():
    from fibril_hpc.campaign.storage.record import (
        COLUMNS,
        CURVE_KEYS,
        OPTIONAL_CURVE_KEYS,
        SCALAR_KEYS,
        JobRecord,
    )

    assert set(SCALAR_KEYS) == set(JOB_ATTRS) | set(MACHINE_ATTRS) | set(CONFIRM_ATTRS)
    assert set(CURVE_KEYS) == CURVES and set(OPTIONAL_CURVE_KEYS) == MACHINE_CURVES
    # the CSV header / load_campaign table of 0.1.0, in its order, then (deliberately, issue 11)
    # the compliant machine's columns appended at the end, then issue 35's local confirmation's:
    # a reader of the old columns by position still finds them where they were
    assert COLUMNS == ("key", "k_tilde", "sigma_tilde", "preload_kind", "preload", "seed",
                       "status", "message", "F_P", "F_A", "d_tilde_max", "d_tilde_at_F_A",
                       "n_pillars_in_contact_max", "events", "wall_s", "cg_iterations",
                       "cg_solves", "fft_pairs", "group_size", "rank", "host", "finished",
                       "record_id", "k_machine", "jumps", "F_jump", "d_machine_tilde_at_F_A",
                       "confirmed_local", "confirmed_global", "force_bound_tilde")
    with h5py.File(os.path.join(DATA, "campaign_v1.h5"), "r") as fh:
        g = fh["jobs"]["9a5a5bc296898b92"]
        stored = {k: v for k, v in g.attrs.items()}
    rec = JobRecord.from_dict(stored).to_dict()
    assert rec.pop("type") == "job"
    assert {k for k, v in rec.items() if v is not None} == set(stored)
