"""The serial campaign runner: :func:`run_serial` and the task order :func:`order_tasks`.

The MPI master/worker (:mod:`.mpi`) shares the order, :func:`~.execute.execute_task` and
:class:`~fibril_hpc.campaign.storage.writer.CampaignWriter` with it.
"""

from __future__ import annotations

import logging
import sys
from collections import deque

from ...errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, DiskFull, Interruption
from ...model import OperatorCache
from ..storage.writer import CampaignWriter
from .control import Interrupted, StopFlag, interrupted_message
from .execute import execute_task
from .planner import make_planner
from .progress import finished_line, for_planner, nothing_to_run

log = logging.getLogger(__name__)


def order_tasks(tasks) -> list:
    """Expensive-looking tasks first (larger brushes, more preloads, larger preload, smaller
    sigma~, softer pillars), which shortens the tail of a dynamically scheduled campaign."""
    return sorted(tasks, key=lambda t: (-t.scene.n_side, -len(t.jobs),
                                        -max(j.preload for j in t.jobs),
                                        t.jobs[0].sigma_tilde, t.jobs[0].k_tilde,
                                        t.jobs[0].index))


def run_serial(spec, *, extend=False, retry_failed=False, checkpoint_s=30.0, progress=True,
               max_tasks=None) -> int:
    """Run the pending jobs of ``spec`` in this process.

    Parameters
    ----------
    spec : CampaignSpec
    extend, retry_failed, checkpoint_s
        As in :class:`~fibril_hpc.campaign.storage.writer.CampaignWriter` and ``fibril-campaign run``.
    progress : bool
        Show the progress line on stderr.
    max_tasks : int, optional
        Stop (as if interrupted) after this many tasks.

    Returns
    -------
    int
        The exit status: ``EXIT_OK``, ``EXIT_FAILED`` or ``EXIT_INTERRUPTED``.
    """
    try:
        writer = CampaignWriter(spec, extend=extend, checkpoint_s=checkpoint_s)
    except DiskFull as exc:               # no room for even the first checkpoint
        print(f"fibril-campaign: {exc}", file=sys.stderr)
        return EXIT_INTERRUPTED
    stop = StopFlag().install()
    interrupted = False
    full = None
    try:
        planner = make_planner(spec, writer, retry_failed)
        tasks = deque(order_tasks(planner.initial()))
        n_todo = sum(len(t.jobs) for t in tasks)
        log.info("campaign %s: %d to run", spec.campaign_hash[:12], n_todo)
        prog = for_planner(planner, n_todo, 1, progress and bool(n_todo))
        ops = OperatorCache()
        n = 0
        while tasks:
            if stop.stop or (max_tasks is not None and n >= max_tasks):
                interrupted = stop.stop
                break
            task = tasks.popleft()
            n += 1
            prog.set_running(len(task.jobs))      # the line, when due, as this task starts
            try:
                recs = execute_task(task, spec.campaign_hash, ops, 0, stop)
            except Interrupted:
                interrupted = True
                break
            try:
                writer.add(recs)
            except Interruption as exc:   # a full disk (this task's records are lost) or a
                # published file changed under us (they are in the journal)
                full = exc
                break
            more = planner.after(task, recs)      # F_P: auto: the path's next round
            tasks.extend(more)
            prog.total += sum(len(t.jobs) for t in more)
            prog.count(recs)
        interrupted = interrupted or stop.stop
        partial = bool(tasks)
        prog.set_running(0, force=True)
        prog.finish()
    finally:
        stop.busy = False
        try:
            writer.close()
        except Interruption as exc:       # the records stay in the journal
            full = full or exc
        finally:
            stop.restore()
    if full is not None:
        print(f"fibril-campaign: {full}", file=sys.stderr)
        return EXIT_INTERRUPTED
    if interrupted or partial:
        print(interrupted_message(spec.output, stop.signum), file=sys.stderr)
        return EXIT_INTERRUPTED
    c = planner.counts()
    print(finished_line(spec.output, c) if n_todo else nothing_to_run(spec.output, c),
          file=sys.stderr)
    return EXIT_OK if c["failed"] == 0 and c["pending"] == 0 else EXIT_FAILED


__all__ = ["run_serial", "order_tasks"]
