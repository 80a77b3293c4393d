"""Running one task of a campaign: one ``simulate`` call, one
:class:`~fibril_hpc.campaign.storage.record.JobRecord` per job.

The serial runner and the MPI workers both call :func:`execute_task`, so their results are
bitwise identical.
"""

from __future__ import annotations

import json
import logging
import math
import socket
import time
import traceback
import uuid

from ...api import simulate
from ...inputs.config import scene_to_yaml
from ...io.results import json_safe
from ..storage.record import JobRecord, curve_dict
from ..storage.store import now
from .control import Interrupted

log = logging.getLogger(__name__)


def _error_text(exc: BaseException) -> str:
    tb = traceback.extract_tb(exc.__traceback__)
    where = f" ({tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno})" if tb else ""
    return f"{type(exc).__name__}: {exc}{where}"


def execute_task(task, campaign_hash: str, operators=None, rank: int = 0, stop=None) -> list:
    """Run one task and return one record (a plain dict, see :class:`JobRecord`) per job.

    Parameters
    ----------
    task : Task
        The jobs of one loading path.
    campaign_hash : str
        The grid the records belong to.
    operators : OperatorCache, optional
        Reused across the tasks of one process.
    rank : int
        Recorded with each record.
    stop : StopFlag, optional
        While the task computes, a stop signal raises :class:`~.control.Interrupted`.

    Returns
    -------
    list of dict
        A failure is recorded (status ``failed`` and its reason), never raised; only
        :class:`~.control.Interrupted` propagates.
    """
    host = socket.gethostname()
    t0 = time.perf_counter()
    result = None
    error = ""
    try:
        if stop is not None:
            stop.busy = True
            if stop.stop:
                raise Interrupted("stop requested")
        result = simulate(task.scene, operators=operators)
    except Interrupted:
        raise
    except Exception as exc:  # noqa: BLE001 - recorded as a failed job with its reason
        error = _error_text(exc)
        log.warning("task %s raised %s", task.keys, error)
    finally:
        if stop is not None:
            stop.busy = False
    wall = time.perf_counter() - t0
    stats = result.stats if result is not None else {}
    disc = json.dumps(json_safe(result.discretisation), sort_keys=True) if result else "{}"
    by_preload = {r.preload: r for r in result.results} if result is not None else {}
    out = []
    for job in task.jobs:
        rec = JobRecord(
            **job.inputs(), record_id=uuid.uuid4().hex, campaign_hash=campaign_hash,
            status="failed", message=error,
            wall_s=float(stats.get("wall_s", wall)),
            cg_iterations=int(stats.get("cg_iterations", 0)),
            cg_solves=int(stats.get("cg_solves", 0)),
            fft_pairs=int(stats.get("fft_pairs", 0)),
            group_size=len(task.jobs), rank=rank, host=host, finished=now(),
            scene_yaml=scene_to_yaml(task.scene.replace(**{job.preload_kind: (job.preload,)})),
            discretisation=disc,
            k_machine=None if math.isinf(task.scene.k_machine) else float(task.scene.k_machine))
        if "confirmed_local" in stats:          # solver.confirm: local (record.py: else absent)
            rec.confirmed_local = int(stats["confirmed_local"])
            rec.confirmed_global = int(stats["confirmed_global"])
            rec.force_bound_tilde = float(stats["force_bound_tilde"])
        r = by_preload.get(job.preload)
        if result is not None and r is None:
            rec.message = "the solver returned no result for this preload"
        if r is not None:
            rec.status = "done" if r.status == "ok" else "failed"
            rec.message = r.message
            rec.F_P, rec.F_A = float(r.F_P), float(r.F_A)
            rec.d_tilde_max = float(r.d_tilde_max)
            rec.d_tilde_at_F_A = float(r.d_tilde_at_F_A)
            rec.n_pillars_in_contact_max = int(r.n_pillars_in_contact_max)
            rec.events = int(r.events)
            rec.loading, rec.unloading = curve_dict(r.loading), curve_dict(r.unloading)
            if r.jumps is not None:             # a compliant machine (record.py: else absent)
                rec.jumps, rec.F_jump = int(r.jumps), float(r.F_jump)
                rec.d_machine_tilde_at_F_A = float(r.d_machine_tilde_at_F_A)
        out.append(rec.to_dict())
    return out


__all__ = ["execute_task"]
