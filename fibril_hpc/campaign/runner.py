"""Running a campaign: the single writer, job execution, the serial runner, progress, signals.

No mpi4py and no h5py here: the writer goes through :mod:`.store` and :mod:`.journal`; the MPI
master/worker (:mod:`.mpi`) reuses :func:`execute_task` and :class:`CampaignWriter`.
"""

from __future__ import annotations

import fcntl
import logging
import os
import signal
import socket
import sys
import time
import traceback
import uuid

from ..errors import ConfigError, StoreError
from . import journal as _journal

log = logging.getLogger(__name__)

EXIT_OK = 0
EXIT_FAILED_JOBS = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 75          # EX_TEMPFAIL: interrupted, rerun the same command to resume
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1)


class Interrupted(Exception):
    """Raised inside a running job when a stop signal arrives (the job is abandoned)."""


# ---------------------------------------------------------------------------- signals
class StopFlag:
    """Installs handlers for SIGTERM/SIGINT/SIGUSR1 that set a flag; while ``busy`` (a job is
    computing) the handler raises :class:`Interrupted` so the job is abandoned at once."""

    def __init__(self):
        self.stop = False
        self.signum = None
        self.busy = False
        self._old = {}

    def _handler(self, signum, frame):  # noqa: ARG002
        self.stop = True
        self.signum = signum
        if self.busy:
            self.busy = False
            raise Interrupted(f"signal {signal.Signals(signum).name}")

    def install(self):
        for s in STOP_SIGNALS:
            self._old[s] = signal.signal(s, self._handler)
        return self

    def restore(self):
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old = {}


# ---------------------------------------------------------------------------- execution
def _curve_dict(c):
    if c is None:
        return None
    return {"d_tilde": c.d_tilde, "F_tilde": c.F_tilde, "contact_fraction": c.contact_fraction,
            "n_pillars_in_contact": c.n_pillars_in_contact}


def execute_task(task, campaign_hash: str, operators=None, rank: int = 0, stop=None) -> list:
    """Run one task (one ``simulate`` call) and return one record per job. A failure is recorded,
    never raised (except :class:`Interrupted`)."""
    import json

    from ..api import simulate
    from ..config import scene_to_yaml
    from ..results import _json_safe

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
        tb = traceback.extract_tb(exc.__traceback__)
        where = f" ({tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno})" if tb else ""
        error = f"{type(exc).__name__}: {exc}{where}"
        log.warning("task %s raised %s", task.keys, error)
    finally:
        if stop is not None:
            stop.busy = False
    wall = time.perf_counter() - t0
    stats = result.stats if result is not None else {}
    disc = json.dumps(_json_safe(result.discretisation), sort_keys=True) if result else "{}"
    by_preload = {}
    if result is not None:
        for r in result.results:
            by_preload[r.preload] = r
    out = []
    for job in task.jobs:
        rec = {"type": "job", "record_id": uuid.uuid4().hex, "campaign_hash": campaign_hash,
               **job.inputs(), "status": "failed", "message": error,
               "F_P": float("nan"), "F_A": float("nan"), "d_tilde_max": float("nan"),
               "d_tilde_at_F_A": float("nan"), "n_pillars_in_contact_max": 0, "events": 0,
               "wall_s": float(stats.get("wall_s", wall)),
               "cg_iterations": int(stats.get("cg_iterations", 0)),
               "cg_solves": int(stats.get("cg_solves", 0)),
               "fft_pairs": int(stats.get("fft_pairs", 0)),
               "group_size": len(task.jobs), "rank": rank, "host": host,
               "finished": _now(), "scene_yaml": scene_to_yaml(
                   task.scene.replace(**{job.preload_kind: (job.preload,)})),
               "discretisation": disc, "loading": None, "unloading": None}
        r = by_preload.get(job.preload)
        if result is not None and r is None:
            rec["message"] = "the solver returned no result for this preload"
        if r is not None:
            rec.update({"status": "done" if r.status == "ok" else "failed", "message": r.message,
                        "F_P": float(r.F_P), "F_A": float(r.F_A),
                        "d_tilde_max": float(r.d_tilde_max),
                        "d_tilde_at_F_A": float(r.d_tilde_at_F_A),
                        "n_pillars_in_contact_max": int(r.n_pillars_in_contact_max),
                        "events": int(r.events), "loading": _curve_dict(r.loading),
                        "unloading": _curve_dict(r.unloading)})
        out.append(rec)
    return out


def _now():
    from .store import now

    return now()


# ---------------------------------------------------------------------------- writer
class CampaignWriter:
    """The only writer of a campaign file: lock, identity check, journal replay, checkpoints.

    Parameters
    ----------
    spec : CampaignSpec
    extend : bool
        Accept a file written from another grid; its records are kept and this grid's jobs added.
    checkpoint_s : float
        Fold the journal into the HDF5 file at most this often (and at the end).
    """

    def __init__(self, spec, *, extend: bool = False, checkpoint_s: float = 30.0):
        from . import store

        self.spec = spec
        self.path = spec.output
        self.checkpoint_s = checkpoint_s
        self._store = store
        folder = os.path.dirname(self.path) or "."
        if not os.path.isdir(folder):
            raise ConfigError("output", self.path, "a path in an existing folder")
        if not os.access(folder, os.W_OK):
            raise ConfigError("output", self.path, "a path in a writable folder")
        if os.path.isdir(self.path):
            raise ConfigError("output", self.path, "a file path, not a folder")
        extended_from = self._check_identity(extend)   # before anything is written
        self._lock_fd = os.open(self.path + ".lock", os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(self._lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self._lock_fd)
            raise ConfigError("output", self.path,
                              "a file that no other running campaign is writing (it is locked)") \
                from None
        store.clean_temporaries(self.path)
        self.root_attrs = store.root_attrs_for(spec, extended_from)
        _, h5recs = store.read_h5_records(self.path, curves=False)
        self.records = {k: {"status": r.get("status"), "record_id": r.get("record_id")}
                        for k, r in h5recs.items()}
        self.journal = _journal.JournalWriter(_journal.journal_path(self.path))
        self._unpublished = []
        for r in self.journal.replayed:
            if r.get("type") == "job":
                self._remember(r)
        self.journal.replayed = None
        self._last_ckpt = time.monotonic()
        self.checkpoint(force=True)

    def _check_identity(self, extend: bool):
        store = self._store
        if os.path.exists(self.path):
            try:
                root = store.read_root(self.path)
            except StoreError as exc:
                raise ConfigError("output", self.path,
                                  f"a fibril-hpc campaign file or a new name ({exc})") from None
            prev = root.get("campaign_hash")
            history = []
            try:
                import json

                history = json.loads(root.get("extended_from", "[]"))
            except ValueError:
                history = []
            if prev != self.spec.campaign_hash:
                if not extend:
                    raise ConfigError(
                        "output", self.path,
                        f"a file of this grid: it holds campaign {str(prev)[:12]} from another grid"
                        f" (this grid is {self.spec.campaign_hash[:12]}); pass --extend to add "
                        "this grid's jobs to it, or choose another output")
                history.append({"campaign_hash": prev, "campaign_yaml": root.get("campaign_yaml")})
            return history
        jrecs, _ = _journal.read(_journal.journal_path(self.path))
        hashes = {r.get("campaign_hash") for r in jrecs if r.get("type") == "job"}
        other = hashes - {self.spec.campaign_hash}
        if other and not extend:
            raise ConfigError("output", self.path,
                              "a file of this grid: its journal holds records of another grid; "
                              "pass --extend to keep them")
        return []

    def _remember(self, rec):
        old = self.records.get(rec["key"])
        if self._store.newer(rec, old):
            self.records[rec["key"]] = {"status": rec["status"], "record_id": rec["record_id"]}
            self._unpublished.append(rec)

    # -------------------------------------------------------------- queries
    def keys_to_run(self, retry_failed: bool) -> list:
        out = []
        for j in self.spec.jobs:
            r = self.records.get(j.key)
            if r is None or (retry_failed and r["status"] != "done"):
                out.append(j.key)
        return out

    def counts(self) -> dict:
        keys = {j.key for j in self.spec.jobs}
        done = sum(1 for k in keys if self.records.get(k, {}).get("status") == "done")
        failed = sum(1 for k in keys if self.records.get(k, {}).get("status") == "failed")
        return {"jobs": len(keys), "done": done, "failed": failed,
                "pending": len(keys) - done - failed}

    # -------------------------------------------------------------- writing
    def add(self, records) -> None:
        for rec in records:
            self.journal.append(rec)
            self._remember(rec)
        self.checkpoint()

    def checkpoint(self, force: bool = False) -> None:
        if not force and (not self._unpublished
                          or time.monotonic() - self._last_ckpt < self.checkpoint_s):
            return
        recs = []
        for r in self._unpublished:
            r = dict(r)
            r.pop("type", None)
            recs.append(r)
        t0 = time.monotonic()
        self._store.checkpoint(self.path, self.root_attrs, recs)
        self.journal.reset()
        self._unpublished = []
        self._last_ckpt = time.monotonic()
        # a checkpoint copies the file: keep its cost below ~10 % of the run however big it gets
        self.checkpoint_s = max(self.checkpoint_s, 10.0 * (self._last_ckpt - t0))

    def close(self) -> None:
        try:
            self.checkpoint(force=bool(self._unpublished))
        finally:
            self.journal.close()
            try:
                fcntl.flock(self._lock_fd, fcntl.LOCK_UN)
            finally:
                os.close(self._lock_fd)


# ---------------------------------------------------------------------------- progress
class Progress:
    """A live progress line with an ETA (carriage return on a terminal, a line every
    ``every_s`` seconds otherwise) on stderr."""

    def __init__(self, total_jobs: int, workers: int, stream=None, every_s: float = 10.0,
                 enabled: bool = True):
        self.total = total_jobs
        self.workers = max(1, workers)
        self.stream = stream or sys.stderr
        self.tty = getattr(self.stream, "isatty", lambda: False)()
        self.every_s = every_s
        self.enabled = enabled
        self.t0 = time.monotonic()
        self.done = self.failed = 0
        self.task_walls = []
        self._last = 0.0
        self.running = 0

    def update(self, records, running: int = 0, force: bool = False):
        for r in records:
            if r["status"] == "done":
                self.done += 1
            else:
                self.failed += 1
        if records:
            self.task_walls.append(records[0]["wall_s"] / max(1, len(records)))
        self.running = running
        self.show(force)

    def line(self) -> str:
        finished = self.done + self.failed
        left = self.total - finished
        el = time.monotonic() - self.t0
        if finished:
            rate = finished / el
            eta = left / rate if rate > 0 else float("inf")
            eta_s = time.strftime("%H:%M:%S", time.gmtime(eta)) if eta < 8.6e5 else ">10 d"
        else:
            eta_s = "?"
        return (f"fibril-campaign: {finished}/{self.total} jobs ({self.done} done, "
                f"{self.failed} failed, {self.running} running) "
                f"elapsed {time.strftime('%H:%M:%S', time.gmtime(el))} ETA {eta_s}")

    def show(self, force=False):
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            if force or now - self._last >= 0.5:
                self.stream.write("\r" + self.line() + "\x1b[K")
                self.stream.flush()
                self._last = now
        elif force or now - self._last >= self.every_s:
            self.stream.write(self.line() + "\n")
            self.stream.flush()
            self._last = now

    def finish(self):
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()


# ---------------------------------------------------------------------------- serial
def order_tasks(tasks) -> list:
    """Expensive-looking tasks first (more preloads, larger preload, smaller sigma~, softer
    pillars), which shortens the tail of a dynamically scheduled campaign."""
    return sorted(tasks, key=lambda t: (-len(t.jobs), -max(j.preload for j in t.jobs),
                                        t.jobs[0].sigma_tilde, t.jobs[0].k_tilde,
                                        t.jobs[0].index))


def run_serial(spec, *, extend=False, retry_failed=False, checkpoint_s=30.0, progress=True,
               max_tasks=None) -> int:
    """Run the pending jobs of ``spec`` in this process. Returns the exit status."""
    from ..model import OperatorCache

    writer = CampaignWriter(spec, extend=extend, checkpoint_s=checkpoint_s)
    stop = StopFlag().install()
    interrupted = False
    try:
        todo = writer.keys_to_run(retry_failed)
        tasks = order_tasks(spec.tasks(todo))
        c = writer.counts()
        log.info("campaign %s: %d jobs, %d to run", spec.campaign_hash[:12], c["jobs"], len(todo))
        prog = Progress(len(todo), 1, enabled=progress)
        ops = OperatorCache()
        for n, task in enumerate(tasks):
            if stop.stop or (max_tasks is not None and n >= max_tasks):
                interrupted = stop.stop
                break
            try:
                recs = execute_task(task, spec.campaign_hash, ops, 0, stop)
            except Interrupted:
                interrupted = True
                break
            writer.add(recs)
            prog.update(recs, running=0)
        interrupted = interrupted or stop.stop
        partial = max_tasks is not None and len(tasks) > max_tasks
        prog.show(force=True)
        prog.finish()
    finally:
        stop.busy = False
        try:
            writer.close()
        finally:
            stop.restore()
    if interrupted or partial:
        print(f"fibril-campaign: interrupted ({signal_name(stop.signum)}); finished results are in "
              f"{spec.output}; rerun the same command to resume", file=sys.stderr)
        return EXIT_INTERRUPTED
    c = writer.counts()
    return EXIT_OK if c["failed"] == 0 and c["pending"] == 0 else EXIT_FAILED_JOBS


def signal_name(signum) -> str:
    return signal.Signals(signum).name if signum else "stop"
