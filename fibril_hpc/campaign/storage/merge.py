"""Merging campaign files into a new one: :func:`merge_files`.

What is refused (one :class:`~fibril_hpc.errors.StoreError` line, nothing written):

- a file of another layout version (``format_version``) than this code writes;
- files of different scenes (the grids' fixed scene fields, resource options such as
  ``solver.fft_threads`` aside): their records are not one study;
- a key done in two files with different numbers (F~_P, F~_A, the other results or the curves),
  named with both files, unless ``on_conflict`` says which wins (``first``, ``last``) or
  ``prefer`` names the file whose record wins.

Policy otherwise: per job key a done record wins over a failed one, and the first done record
found is kept (files are read in the order given). Only records that the files vouch for are
copied (see :mod:`.h5read`): foreign members and journal frames never; records without a
checksum (*unchecked*) only with ``include_unchecked``, and then without one (``merge`` never
gives a record a checksum it did not have). The root attributes come from the first file; files
of several grids get a ``merged-`` campaign hash, and every source is listed in ``merged_from``.
"""

from __future__ import annotations

import json
import os

import numpy as np
import yaml

from ...errors import StoreError
from ..plan.keys import KEY_EXCLUDED_SOLVER, campaign_hash_of
from .record import BRANCHES
from .store import FORMAT_VERSION, newer, read_snapshot, write_merged

#: the result fields two records of one job must agree on
RESULT_FIELDS = ("status", "F_P", "F_A", "d_tilde_max", "d_tilde_at_F_A",
                 "n_pillars_in_contact_max", "events", "jumps", "F_jump",
                 "d_machine_tilde_at_F_A")
ON_CONFLICT = ("refuse", "first", "last")


def _scene_of(meta: dict, path: str) -> dict:
    """The fixed scene fields of a file's grid (resource options left out)."""
    try:
        scene = dict((yaml.safe_load(meta.get("campaign_yaml") or "") or {}).get("scene") or {})
    except (yaml.YAMLError, AttributeError, TypeError, ValueError):
        raise StoreError(f"{path}: its grid (campaign_yaml) cannot be read") from None
    solver = scene.get("solver")
    if isinstance(solver, dict):
        scene["solver"] = {k: v for k, v in solver.items() if k not in KEY_EXCLUDED_SOLVER}
    return scene


def _same(a: dict, b: dict) -> bool:
    """Whether two records of one key hold the same numbers (bitwise; NaN equals NaN)."""
    for k in RESULT_FIELDS:
        if repr(a.get(k)) != repr(b.get(k)):
            return False
    for br in BRANCHES:
        ca, cb = a.get(br), b.get(br)
        if (ca is None) != (cb is None):
            return False
        if ca is not None and (set(ca) != set(cb) or not all(
                np.array_equal(ca[n], cb[n], equal_nan=ca[n].dtype.kind == "f") for n in ca)):
            return False
    return True


def _first_diff(a: dict, b: dict) -> str:
    for k in RESULT_FIELDS:
        if repr(a.get(k)) != repr(b.get(k)):
            return f"{k} {a.get(k)!r} and {b.get(k)!r}"
    return "their curves differ"


def merge_records(files, on_conflict: str = "refuse", prefer: str | None = None,
                  include_unchecked: bool = False) -> tuple[dict, dict, set, dict]:
    """(root attributes, {key: record}, keys written without a checksum, counts) of the merge
    of ``files`` (nothing is written); see the module docstring for what is refused."""
    if on_conflict not in ON_CONFLICT:
        raise StoreError(f"on_conflict: got {on_conflict!r}; allowed: {', '.join(ON_CONFLICT)}")
    prefer = None if prefer is None else os.path.abspath(prefer)
    merged: dict = {}
    origin: dict = {}          # key -> file its record came from
    unsigned: set = set()
    counts = {"foreign": 0, "unchecked_left_out": 0, "conflicts": 0}
    sources = []
    first = first_scene = None
    for f in files:
        snap = read_snapshot(f)
        meta = snap.root
        if meta.get("format_version") != FORMAT_VERSION:
            raise StoreError(f"{f}: layout version {meta.get('format_version')!r}, not "
                             f"{FORMAT_VERSION}; merge only files of this layout")
        scene = _scene_of(meta, f)
        if first is None:
            first, first_scene, first_file = meta, scene, f
        elif scene != first_scene:
            diff = sorted(k for k in set(scene) | set(first_scene)
                          if scene.get(k) != first_scene.get(k))
            raise StoreError(f"{first_file} and {f} hold different scenes ({', '.join(diff[:4])}"
                             f" differ); merge only shards of one scene")
        counts["foreign"] += len(snap.foreign)
        sources.append({"file": os.path.abspath(f), "campaign_hash": meta.get("campaign_hash"),
                        "campaign_yaml": meta.get("campaign_yaml")})
        for k, r in snap.records.items():
            if k in snap.unchecked_keys and not include_unchecked:
                counts["unchecked_left_out"] += 1
                continue
            old = merged.get(k)
            if old is not None and old.get("status") == "done" and r.get("status") == "done":
                if _same(old, r):
                    continue
                counts["conflicts"] += 1
                pick = _resolve(k, old, r, origin[k], f, on_conflict, prefer)
                if pick is old:
                    continue
            elif not newer(r, old) or (old or {}).get("status") == "done":
                continue
            merged[k] = r
            origin[k] = f
            if k in snap.unchecked_keys:
                unsigned.add(k)
            else:
                unsigned.discard(k)
    hashes = sorted({s["campaign_hash"] for s in sources})
    root = {k: v for k, v in first.items() if k not in ("created", "updated")}
    if len(hashes) > 1:
        root["campaign_hash"] = "merged-" + campaign_hash_of(hashes)[:52]
    root["merged_from"] = json.dumps(sources)
    root["n_jobs"] = len(merged)
    return root, merged, unsigned, counts


def _resolve(key, old, new, old_file, new_file, on_conflict, prefer):
    """The record that wins a conflict (or the one-line refusal naming both files)."""
    if prefer is not None and prefer in (os.path.abspath(old_file), os.path.abspath(new_file)):
        return old if os.path.abspath(old_file) == prefer else new
    if on_conflict == "first":
        return old
    if on_conflict == "last":
        return new
    raise StoreError(f"job {key} is done with different numbers in {old_file} and {new_file} "
                     f"({_first_diff(old, new)}); pass --prefer FILE or --on-conflict first|last "
                     "to say which wins")


def merge_files(files, output: str, on_conflict: str = "refuse", prefer: str | None = None,
                include_unchecked: bool = False) -> dict:
    """Write the merge of ``files`` to the new file ``output``; returns counts: jobs, foreign
    (left out), unchecked_left_out, conflicts (resolved by ``on_conflict``/``prefer``)."""
    root, merged, unsigned, counts = merge_records(files, on_conflict, prefer, include_unchecked)
    write_merged(output, root, list(merged.values()), unsigned=unsigned)
    return {"jobs": len(merged), **counts}


__all__ = ["merge_files", "merge_records", "ON_CONFLICT"]
