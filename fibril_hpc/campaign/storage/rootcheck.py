"""Whether the root attributes a reader relies on are whole: :func:`root_problem` (no h5py,
no MPI).

Every record carries its own checksum, but the root of a campaign file does not: a flipped
byte in ``campaign_hash`` makes a resume take the file for another grid's, one in
``campaign_yaml`` makes ``merge`` refuse it and readers misname its axes. The stored hash must be
the hash of the stored grid (for a merged file: of the merged grids), the grid must parse and
rebuild, the earlier grids of ``extended_from`` likewise, and the layout version must be one this
code knows (an unknown one is refused on reading: :class:`~fibril_hpc.errors.UnknownLayoutError`).

The repair of a damaged root that works (tested in tests/test_verify_root.py):
``fibril-campaign salvage FILE -o NEW.h5`` (it keeps every record that verifies and takes the
campaign hash from the records), then rerunning the grid with ``--output NEW.h5``, whose first
checkpoint writes the root again (:data:`REPAIR`).
"""

from __future__ import annotations

import json

from ..plan.keys import campaign_hash_of
from .grids import rebuild_problem, rebuilt_hash

#: attribute a salvage writes when the root did not read whole
ROOT_LOST = "root_lost"


def repair(path: str) -> str:
    """The repair of a damaged root, as a sentence naming ``path``."""
    return (f"`fibril-campaign salvage {path} -o NEW.h5`, then rerun its grid with --output "
            "NEW.h5 (its first checkpoint writes the root again)")


def _external(problem: str) -> bool:
    """Whether a grid fails to rebuild only for want of a file outside the campaign file (a
    measured height file moved away): not damage, and nothing to check its hash against."""
    p = problem.lower()
    return "no such file" in p or "not found" in p or "does not exist" in p


def _grid_problem(what: str, y, h, current: bool = True) -> str:
    """What is wrong with one stored grid and its hash. An earlier grid (``current`` False)
    that parses but does not validate is not taken for damage: a grid an older version wrote
    may use what this version no longer accepts."""
    if not isinstance(y, str) or not y:
        return f"{what}: no stored grid"
    problem = rebuild_problem(y)
    if problem:
        parsed = not problem.startswith(("it does not parse", "it is not a mapping"))
        if _external(problem) or (parsed and not current):
            return ""
        return f"{what}: the stored grid does not rebuild ({problem})"
    if rebuilt_hash(y) != h:
        return (f"{what}: the stored campaign hash {str(h)[:16]} is not the hash of the stored "
                f"grid ({str(rebuilt_hash(y))[:16]}): one of them is damaged")
    return ""


def _listed(root: dict, attr: str):
    try:
        items = json.loads(root.get(attr) or "[]")
    except (ValueError, TypeError):
        return None
    if not isinstance(items, list) or not all(isinstance(i, dict) for i in items):
        return None
    return items


def root_problem(root: dict) -> str:
    """What is wrong with the root attributes ``root`` of a campaign file that its readers rely
    on ("" when nothing is)."""
    if ROOT_LOST in root:
        return "its root attributes were lost (a salvaged file): rerun its grid with --output " \
               "on this file to write them again"
    if root.get("format_version") is None:
        return "it has no layout version (format_version)"
    for attr in ("extended_from", "merged_from"):
        if _listed(root, attr) is None:
            return f"{attr} does not parse (a JSON list of grids)"
    h = root.get("campaign_hash")
    merged = _listed(root, "merged_from")
    if isinstance(h, str) and h.startswith("merged-") and merged:
        hashes = sorted({str(s.get("campaign_hash")) for s in merged})
        if h != "merged-" + campaign_hash_of(hashes)[:52]:
            return "the stored campaign hash is not the hash of the merged grids (merged_from)"
        for s in merged:
            p = _grid_problem("merged_from", s.get("campaign_yaml"), s.get("campaign_hash"),
                              current=False)
            if p:
                return p
    else:
        p = _grid_problem("campaign_yaml", root.get("campaign_yaml"), h)
        if p:
            return p
    for s in _listed(root, "extended_from"):
        p = _grid_problem("extended_from", s.get("campaign_yaml"), s.get("campaign_hash"),
                          current=False)
        if p:
            return p
    return ""


__all__ = ["root_problem", "repair", "ROOT_LOST"]
