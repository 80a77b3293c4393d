"""CSV export of a campaign: one row per job, the columns of :data:`.record.COLUMNS`."""

from __future__ import annotations

import csv
import os

from .data import load_campaign
from .record import COLUMNS


def _csv_value(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else v


def export_csv(path: str, out: str) -> int:
    """Write the jobs of the campaign file ``path`` to ``out`` (atomically); returns the rows."""
    c = load_campaign(path, curves=False)
    tmp = out + ".part"
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for j in c.jobs:
            w.writerow([_csv_value(j.get(col)) for col in COLUMNS])
    os.replace(tmp, out)
    return len(c.jobs)


__all__ = ["export_csv"]
