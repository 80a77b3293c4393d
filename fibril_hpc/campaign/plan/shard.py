"""Disjoint shards of a campaign grid, for Slurm job arrays (``fibril-campaign --shard I/N``).

Shard I of N runs the loading paths whose rank, in the order of their keys, is I modulo N: a
path (the jobs sharing k~, sigma~ and seed, and the swept lab values, when ``group_preloads``;
else one job) is never split, so a path's preloads still share one loading, and every ``F_P:
auto`` path keeps all its rounds in one shard; a search grid (``sigma_tilde: auto``, ``seeds:
auto``) is split by line (k~ and n_side), whose rounds read all its groups. A path's key is the
smallest key of its jobs (``F_P: auto``: the path key of
:meth:`~.spec.CampaignSpec.path_key`; a line's: :meth:`~.spec.CampaignSpec.line_key`), so the rule depends on
the grid alone, not on the order of its lists or on what has run. Each shard writes its own
file (``<output>.shard-I-of-N.h5`` unless ``--output`` is given) under the campaign hash of the
whole grid; ``fibril-campaign merge`` joins the shards into the file a single run would have
written.

Under a Slurm job array (``sbatch --array=0-3``) the shard is read from the environment:
I = SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN, N = SLURM_ARRAY_TASK_COUNT.
"""

from __future__ import annotations

import dataclasses
import os

from ...errors import ConfigError

SHARD_ALLOWED = "I/N with integers 0 <= I < N <= 100000 (e.g. 0/4 ... 3/4)"


def parse_shard(text: str | None, environ=None) -> tuple[int, int] | None:
    """(I, N) from ``--shard I/N``, else from a Slurm job array's environment, else None."""
    env = os.environ if environ is None else environ
    field = "--shard"
    if text is None:
        if not (env.get("SLURM_ARRAY_TASK_ID") and env.get("SLURM_ARRAY_TASK_COUNT")):
            return None
        field = "SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT"
        try:
            i = int(env["SLURM_ARRAY_TASK_ID"]) - int(env.get("SLURM_ARRAY_TASK_MIN", "0") or 0)
            text = f"{i}/{int(env['SLURM_ARRAY_TASK_COUNT'])}"
        except ValueError:
            raise ConfigError(field, env["SLURM_ARRAY_TASK_ID"], SHARD_ALLOWED) from None
    parts = str(text).split("/")
    try:
        i, n = (int(p) for p in parts)
    except ValueError:
        raise ConfigError(field, text, SHARD_ALLOWED) from None
    if not (1 <= n <= 100000 and 0 <= i < n):
        raise ConfigError(field, text, SHARD_ALLOWED + " (a job array's indices must be "
                          "contiguous, e.g. --array=0-3)" if field != "--shard" else
                          SHARD_ALLOWED)
    return i, n


def shard_output(output: str, i: int, n: int) -> str:
    """The default output of shard ``i`` of ``n``: ``results.h5`` -> ``results.shard-1-of-4.h5``."""
    stem, ext = os.path.splitext(output)
    return f"{stem}.shard-{i}-of-{n}{ext}"


def _path_of(spec, job):
    if not spec.group_preloads:
        return job.key
    return (job.k_tilde, job.sigma_tilde, job.seed, job.extra)


def shard_spec(spec, i: int, n: int, output: str | None = None):
    """The shard ``i`` of ``n`` of ``spec`` (module docstring): its own paths or jobs, the
    campaign hash of the whole grid, and ``output`` (default :func:`shard_output`)."""
    whole = spec.campaign_hash
    out = output or shard_output(spec.output, i, n)
    if spec.search:                      # a line's rounds decide over all its sigma~ and seeds
        lines = sorted(spec.lines(whole=True), key=spec.line_key)
        mine = frozenset(ln for r, ln in enumerate(lines) if r % n == i)
        return dataclasses.replace(spec, only_lines=mine, grid_hash=whole, output=out)
    if spec.auto is not None:
        paths = sorted(spec.paths(whole=True), key=spec.path_key)
        mine = frozenset(p for r, p in enumerate(paths) if r % n == i)
        return dataclasses.replace(spec, only_paths=mine, grid_hash=whole, output=out)
    groups: dict = {}
    for job in spec.jobs:
        groups.setdefault(_path_of(spec, job), []).append(job.key)
    ranked = sorted(groups, key=lambda g: min(groups[g]))
    mine = {g for r, g in enumerate(ranked) if r % n == i}
    jobs = [j for j in spec.jobs if _path_of(spec, j) in mine]
    return dataclasses.replace(spec, jobs=jobs, grid_hash=whole, output=out)


__all__ = ["parse_shard", "shard_spec", "shard_output"]
