"""The brush size of a job record: ``n_side``, which a record holds in its stored scene only.

A record's fields (:class:`~fibril_hpc.campaign.storage.record.JobRecord`) are a contract with
every file ever written, and ``n_side`` is not among them: every record written by any version
stores its resolved single-preload scene (``scene_yaml``, every field, ``n_side`` included), so
the brush size is read from there. A reader of a grid that sweeps ``n_side`` (``sweep:``) needs
it to keep the brush sizes apart; a record without a stored scene has none (None).
"""

from __future__ import annotations

import re

#: the top-level ``n_side:`` line of a stored scene (``yaml.safe_dump`` of ``Scene.to_dict``)
_N_SIDE_LINE = re.compile(r"^n_side: *([0-9]+) *$", re.MULTILINE)


def scene_n_side(scene_yaml) -> int | None:
    """``n_side`` of a stored scene text, or None when the text names none."""
    if not isinstance(scene_yaml, str) or not scene_yaml:
        return None
    m = _N_SIDE_LINE.search(scene_yaml)
    if m is not None:
        return int(m.group(1))
    import yaml

    try:
        d = yaml.safe_load(scene_yaml)
    except yaml.YAMLError:
        return None
    v = d.get("n_side") if isinstance(d, dict) else None
    return v if isinstance(v, int) and not isinstance(v, bool) else None


def record_n_side(rec: dict) -> int | None:
    """The brush size of a job record: its ``n_side`` entry when it has one (a record read by
    :func:`~fibril_hpc.campaign.analysis.data.load_campaign`), else its stored scene's."""
    v = rec.get("n_side")
    if isinstance(v, int) and not isinstance(v, bool):
        return v
    return scene_n_side(rec.get("scene_yaml"))


__all__ = ["scene_n_side", "record_n_side"]
