"""A campaign with ``solver: {confirm: local}`` (the opt-in local confirmation, issue 35): the
runner hands the option to the solver unchanged, the records carry it in their scene, and its
job keys differ from the reference grid's (confirm enters keys only when set)."""

import yaml
from campaign_helpers import write_grid

from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.plan.keys import key_fields
from fibril_hpc.campaign.run import execute
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage.store import read_records

GRID = {"output": "confirm.h5",
        "scene": {"n_side": 3, "elements_per_diameter": 5,
                  "solver": {"fft_threads": 1, "max_wall_s": 120, "confirm": "local"}},
        "k_tilde": [0.01], "sigma_tilde": [0.5], "F_P": [0.3, 1.0], "seeds": 1}


def test_confirm_local_campaign_runs_and_keeps_the_option(tmp_path, monkeypatch):
    seen = []
    run = execute.simulate

    def spy(scene, **kw):           # what the runner hands the solver, and what it did
        r = run(scene, **kw)
        seen.append((scene.solver.confirm, r.stats.get("confirmed_local", 0)))
        stats.append(r.stats)
        return r

    stats = []

    monkeypatch.setattr(execute, "simulate", spy)
    spec = load_spec(write_grid(tmp_path, GRID))
    assert run_serial(spec, progress=False) == 0
    assert seen and all(c == "local" for c, _ in seen)
    assert sum(n for _, n in seen) > 0          # states were kept without a global solve
    _, recs, _ = read_records(spec.output, curves=False)
    assert set(recs) == {j.key for j in spec.jobs} and len(recs) == 2
    for r in recs.values():
        assert r["status"] == "done"
        assert yaml.safe_load(r["scene_yaml"])["solver"]["confirm"] == "local"
        # how its simulate call confirmed, and the bound it carries (record.py)
        st = stats[0]
        assert (r["confirmed_local"], r["confirmed_global"]) == (st["confirmed_local"],
                                                                  st["confirmed_global"])
        assert r["force_bound_tilde"] == st["force_bound_tilde"] > 0

    ref = dict(GRID, scene=dict(GRID["scene"], solver={"fft_threads": 1, "max_wall_s": 120}))
    ref_spec = load_spec(write_grid(tmp_path, ref, name="ref.yaml"))
    # the same jobs under the reference confirmation: other keys, no confirm in their scene
    assert len(ref_spec.jobs) == len(spec.jobs)
    assert not {j.key for j in ref_spec.jobs} & {j.key for j in spec.jobs}
    assert "confirm" not in key_fields(ref_spec.task_scene(ref_spec.jobs[:1]))["solver"]
    assert key_fields(spec.task_scene(spec.jobs[:1]))["solver"]["confirm"] == "local"
    # a reference record stores none of the local confirmation's fields (the layout of old files)
    ref_spec.output = str(tmp_path / "ref.h5")
    assert run_serial(ref_spec, progress=False) == 0
    _, ref_recs, _ = read_records(ref_spec.output, curves=False)
    for r in ref_recs.values():
        assert not {"confirmed_local", "confirmed_global", "force_bound_tilde"} & set(r)
