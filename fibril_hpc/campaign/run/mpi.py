"""mpi4py master/worker (the only module that imports mpi4py; imported lazily by the CLI).

Rank 0 is the master and the only writer: it hands out tasks one at a time (dynamic scheduling:
job costs differ by orders of magnitude), writes every returned record, and polls with
``Iprobe`` plus a short sleep so that it does not spin the core its workers need. Workers run
:func:`~fibril_hpc.campaign.run.execute.execute_task` (the very code path of the serial runner, so
results are bitwise identical) with one :class:`~fibril_hpc.model.OperatorCache` each.

Stop signals (SIGTERM/SIGINT/SIGUSR1) on any rank stop the hand-out; a worker that is computing
when it is signalled abandons its job. The master waits up to ``grace_s`` for jobs in flight,
publishes everything, tells the workers to exit, and every rank exits with status 75.

A full disk (:class:`~fibril_hpc.errors.DiskFull` from the journal or a checkpoint) is handled
like a stop signal: the hand-out stops, the results still arriving cannot be written and are
dropped, every rank exits with 75 and one line names the path and the operation. So is a
published file changed under the writer (:class:`~fibril_hpc.errors.PublishedFileChanged`: cut
short, emptied or replaced by another program), except that the results still arriving go to
the journal; the line says how to recover (``salvage``). Any other
error on the master aborts the whole world (``MPI_Abort``) so that no worker waits for ever.
"""

from __future__ import annotations

import logging
import sys
import time
from collections import deque

from ...errors import (
    EXIT_FAILED,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_USAGE,
    DiskFull,
    Interruption,
    PublishedFileChanged,
)
from ...model import OperatorCache
from ..storage.writer import CampaignWriter
from .control import Interrupted, StopFlag, interrupted_message
from .execute import execute_task
from .planner import make_planner
from .progress import finished_line, for_planner, nothing_to_run
from .runner import order_tasks

log = logging.getLogger(__name__)

TAG_TASK = 11
TAG_RESULT = 12
POLL_S = 0.02


def world():
    """Initialise MPI (lazily) and return COMM_WORLD."""
    from mpi4py import MPI

    return MPI.COMM_WORLD


def _wait_message(comm, source, tag):
    """The next message from ``source`` with ``tag``, polled (a blocked recv burns a core)."""
    from mpi4py import MPI

    status = MPI.Status()
    while not comm.Iprobe(source=source, tag=tag, status=status):
        time.sleep(POLL_S)
    return comm.recv(source=status.Get_source(), tag=tag)


def run_master(comm, spec, *, extend=False, retry_failed=False, checkpoint_s=30.0,
               progress=True, grace_s=120.0) -> int:
    """Rank 0: the single writer; hands out tasks one at a time and writes every record.

    Returns the exit status that every rank exits with.
    """
    try:
        writer = CampaignWriter(spec, extend=extend, checkpoint_s=checkpoint_s)
    except Exception as exc:
        # a full disk is an interruption on every rank (75); anything else is a usage error
        comm.bcast(("error", EXIT_INTERRUPTED if isinstance(exc, DiskFull) else EXIT_USAGE),
                   root=0)
        raise exc
    comm.bcast(("ok", spec.campaign_hash), root=0)
    try:
        return _serve(comm, spec, writer, retry_failed, progress, grace_s)
    except Exception as exc:  # noqa: BLE001 - never leave workers waiting for ever
        print(f"fibril-campaign: error: {type(exc).__name__}: {exc}", file=sys.stderr)
        sys.stderr.flush()
        comm.Abort(EXIT_FAILED)
        raise  # pragma: no cover - Abort does not return


def _serve(comm, spec, writer, retry_failed, progress, grace_s) -> int:
    """Hand out tasks, write results; stop on a signal or a full disk; release every worker."""
    from mpi4py import MPI

    size = comm.Get_size()
    stop = StopFlag().install()
    code = EXIT_OK
    busy: dict = {}
    full = None
    n_todo = 0
    queue: deque = deque()
    try:
        planner = make_planner(spec, writer, retry_failed)
        queue = deque(order_tasks(planner.initial()))
        n_todo = sum(len(t.jobs) for t in queue)
        prog = for_planner(planner, n_todo, size - 1, progress and bool(n_todo))
        idle = deque(range(1, size))
        while idle and queue and not stop.stop:
            r = idle.popleft()
            busy[r] = queue.popleft()
            comm.send(("task", busy[r]), dest=r, tag=TAG_TASK)
        prog.set_running(_jobs(busy))
        status = MPI.Status()
        stop_since = None
        while busy:
            if comm.Iprobe(source=MPI.ANY_SOURCE, tag=TAG_RESULT, status=status):
                src = status.Get_source()
                recs = comm.recv(source=src, tag=TAG_RESULT)
                task = busy.pop(src, None)
                if recs is None:          # the worker was signalled and abandoned its job
                    stop.stop = True
                elif full is None or isinstance(full, PublishedFileChanged):
                    try:
                        writer.add(recs)        # after a PublishedFileChanged: journal only
                        prog.count(recs)
                    except Interruption as exc:  # stop handing out (a full disk: jobs in
                        full, stop.stop = full or exc, True    # flight are lost)
                    else:
                        more = planner.after(task, recs)      # F_P: auto: the path's next round
                        queue.extend(more)
                        prog.total += sum(len(t.jobs) for t in more)
                idle.append(src)
                while idle and queue and not stop.stop:
                    r = idle.popleft()
                    busy[r] = queue.popleft()
                    comm.send(("task", busy[r]), dest=r, tag=TAG_TASK)
                prog.set_running(_jobs(busy))
                continue
            if stop.stop:
                if stop_since is None:
                    stop_since = time.monotonic()
                    if full is None:
                        log.warning("stop requested: waiting for %d job(s) in flight",
                                    len(busy))
                elif time.monotonic() - stop_since > grace_s:
                    break
            time.sleep(POLL_S)
            prog.show()
            if full is None:
                try:
                    writer.checkpoint()
                except Interruption as exc:
                    full, stop.stop = exc, True
        prog.set_running(_jobs(busy), force=True)   # 0, or the jobs the grace period gave up
        prog.finish()
        if stop.stop or queue:
            code = EXIT_INTERRUPTED
        else:
            c = planner.counts()
            code = EXIT_OK if c["failed"] == 0 and c["pending"] == 0 else EXIT_FAILED
    finally:
        stop.busy = False
        try:
            writer.close()
        except Interruption as exc:       # the records stay in the journal
            full = full or exc
            code = EXIT_INTERRUPTED
        finally:
            stop.restore()
    if full is not None:
        print(f"fibril-campaign: {full}", file=sys.stderr)
    elif code == EXIT_INTERRUPTED:
        print(interrupted_message(spec.output, stop.signum), file=sys.stderr)
    else:
        c = planner.counts()
        print(finished_line(spec.output, c) if n_todo else nothing_to_run(spec.output, c),
              file=sys.stderr)
    for r in range(1, size):
        if r not in busy:
            comm.send(("stop", code), dest=r, tag=TAG_TASK)
    if busy:
        print(f"fibril-campaign: {len(busy)} job(s) still running after {grace_s:g} s; "
              "aborting them (they are pending in the file)", file=sys.stderr)
        sys.stderr.flush()
        comm.Abort(EXIT_INTERRUPTED)
    return code


def _jobs(busy: dict) -> int:
    """Jobs in flight: those of every task handed out to a worker and not yet back."""
    return sum(len(t.jobs) for t in busy.values())


def run_worker(comm) -> int:
    """A worker rank: run the tasks the master sends until it says stop; returns the exit status."""
    status, value = comm.bcast(None, root=0)
    if status != "ok":
        return value
    campaign_hash = value
    rank = comm.Get_rank()
    stop = StopFlag().install()
    ops = OperatorCache()
    try:
        while True:
            kind, payload = _wait_message(comm, 0, TAG_TASK)
            if kind == "stop":
                return payload
            try:
                recs = execute_task(payload, campaign_hash, ops, rank, stop)
            except Interrupted:
                recs = None
            comm.send(recs, dest=0, tag=TAG_RESULT)
    finally:
        stop.busy = False
        stop.restore()


def run_mpi(comm, spec, **kw) -> int:
    """Master on rank 0, workers elsewhere; every rank returns the same exit status."""
    if comm.Get_rank() == 0:
        return run_master(comm, spec, **kw)
    return run_worker(comm)


__all__ = ["run_mpi", "run_master", "run_worker", "world"]
