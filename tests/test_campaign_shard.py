"""Shards of a campaign (fibril-campaign --shard I/N, Slurm job arrays), merged equal to a serial
run; whole loading paths, F_P: auto paths with all their rounds."""

import os

import pytest
from campaign_helpers import TINY, results_by_key, same_numbers, write_grid

from fibril_hpc import ConfigError, load_campaign
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.plan.shard import parse_shard, shard_output, shard_spec
from fibril_hpc.cli.campaign import main

AUTO = dict(TINY, k_tilde=[1, 0.01], sigma_tilde=[0.3], seeds=2, output="auto.h5",
            F_P={"auto": {"start": [0.01, 0.25, 1.0], "rounds": 3}})


@pytest.mark.parametrize("text, env, want", [
    ("1/4", {}, (1, 4)), ("0/1", {}, (0, 1)), (None, {}, None),
    (None, {"SLURM_ARRAY_TASK_ID": "3", "SLURM_ARRAY_TASK_COUNT": "4"}, (3, 4)),
    (None, {"SLURM_ARRAY_TASK_ID": "4", "SLURM_ARRAY_TASK_COUNT": "4",
            "SLURM_ARRAY_TASK_MIN": "1"}, (3, 4)),
    ("2/4", {"SLURM_ARRAY_TASK_ID": "3", "SLURM_ARRAY_TASK_COUNT": "4"}, (2, 4)),
])
def test_parse_shard(text, env, want):
    assert parse_shard(text, env) == want


@pytest.mark.parametrize("text", ["4/4", "-1/2", "1", "a/b", "1/0", "1/2/3"])
def test_bad_shard_is_one_line(text, capsys):
    with pytest.raises(ConfigError, match="^--shard: "):
        parse_shard(text, {})
    assert main(["run", "nothing.yaml", f"--shard={text}"]) == 2
    assert capsys.readouterr().err.startswith("fibril-campaign: error: --shard: ")


def test_shards_are_disjoint_whole_paths_covering_the_grid(tmp_path):
    spec = load_spec(write_grid(tmp_path, seeds=3))               # 12 paths of 2 preloads
    parts = [shard_spec(spec, i, 5) for i in range(5)]
    keys = [{j.key for j in p.jobs} for p in parts]
    assert sum(map(len, keys)) == len(spec.jobs) == len(set().union(*keys))
    assert all(p.campaign_hash == spec.campaign_hash for p in parts)
    for p in parts:
        assert all(len(t.jobs) == 2 for t in p.tasks())              # paths never split
        assert abs(len(p.tasks()) - 12 / 5) < 1
    assert parts[1].output == shard_output(spec.output, 1, 5)
    assert parts[1].output.endswith("tiny.shard-1-of-5.h5")
    again = shard_spec(load_spec(write_grid(tmp_path, dict(TINY, seeds=3, k_tilde=[0.01, 1]),
                                            name="reordered.yaml")), 1, 5)
    assert {j.key for j in again.jobs} == keys[1]                    # the rule: keys, not order


def test_merged_shards_equal_a_serial_run(tmp_path):
    grid = write_grid(tmp_path)
    assert main([grid, "--no-progress"]) == 0
    env = {"SLURM_ARRAY_TASK_COUNT": "3", "SLURM_ARRAY_TASK_MIN": "1"}
    for i in (1, 2, 3):                                   # as `sbatch --array=1-3` runs them
        os.environ.update(env, SLURM_ARRAY_TASK_ID=str(i))
        try:
            assert main([grid, "--no-progress"]) == 0
        finally:
            for k in (*env, "SLURM_ARRAY_TASK_ID"):
                os.environ.pop(k, None)
    shards = sorted(str(p) for p in tmp_path.glob("tiny.shard-*-of-3.h5"))
    assert len(shards) == 3
    sizes = [len(load_campaign(s, curves=False)) for s in shards]
    assert sum(sizes) == 16 and min(sizes) > 0
    merged = str(tmp_path / "all.h5")
    assert main(["merge", *shards, "-o", merged]) == 0
    serial, joined = results_by_key(str(tmp_path / "tiny.h5")), results_by_key(merged)
    assert set(serial) == set(joined) and same_numbers(serial, joined) == []
    assert load_campaign(merged).meta["campaign_hash"] == \
        load_campaign(str(tmp_path / "tiny.h5")).meta["campaign_hash"]
    assert main([grid, "--output", merged, "--no-progress"]) == 0   # nothing left to run


@pytest.mark.slow
def test_auto_shards_keep_every_round_of_a_path(tmp_path):
    grid = write_grid(tmp_path, AUTO)
    assert main([grid, "--no-progress"]) == 0
    for i in (0, 1):
        assert main([grid, "--shard", f"{i}/2", "--no-progress"]) == 0
    shards = [str(tmp_path / f"auto.shard-{i}-of-2.h5") for i in (0, 1)]
    paths = [{(j["k_tilde"], j["sigma_tilde"], j["seed"]) for j in load_campaign(s).jobs}
             for s in shards]
    assert paths[0] and paths[1] and not paths[0] & paths[1]
    merged = str(tmp_path / "all.h5")
    assert main(["merge", *shards, "-o", merged]) == 0
    serial, joined = results_by_key(str(tmp_path / "auto.h5")), results_by_key(merged)
    assert set(serial) == set(joined) and same_numbers(serial, joined) == []
