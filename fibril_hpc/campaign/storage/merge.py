"""Merging campaign files into a new one: :func:`merge_files`.

Policy: per job key a done record wins over a failed one, and the first done record found is
kept (files are read in the order given). The root attributes come from the first file; files of
several grids get a ``merged-`` campaign hash, and every source is listed in ``merged_from``.
"""

from __future__ import annotations

import json
import os

from ..plan.spec import campaign_hash_of
from .store import newer, read_records, write_merged


def merge_records(files) -> tuple[dict, dict]:
    """(root attributes, {key: record}) of the merge of ``files`` (nothing is written)."""
    merged: dict = {}
    sources = []
    first = None
    for f in files:
        meta, recs, _ = read_records(f)
        first = first or meta
        sources.append({"file": os.path.abspath(f), "campaign_hash": meta.get("campaign_hash"),
                        "campaign_yaml": meta.get("campaign_yaml")})
        for k, r in recs.items():
            if newer(r, merged.get(k)) and not (merged.get(k, {}).get("status") == "done"):
                merged[k] = r
    hashes = sorted({s["campaign_hash"] for s in sources})
    root = {k: v for k, v in first.items() if k not in ("created", "updated")}
    if len(hashes) > 1:
        root["campaign_hash"] = "merged-" + campaign_hash_of(hashes)[:52]
    root["merged_from"] = json.dumps(sources)
    root["n_jobs"] = len(merged)
    return root, merged


def merge_files(files, output: str) -> int:
    """Write the merge of ``files`` to the new file ``output``; returns the number of jobs."""
    root, merged = merge_records(files)
    write_merged(output, root, list(merged.values()))
    return len(merged)


__all__ = ["merge_files", "merge_records"]
