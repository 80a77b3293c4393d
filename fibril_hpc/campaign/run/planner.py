"""What a campaign runs next: the tasks of a fixed grid, or the rounds of ``F_P: auto``.

The serial runner and the MPI master ask a planner for the first tasks (:meth:`initial`) and,
after each finished task, for its follow-ups (:meth:`after`). A fixed grid has none, so it runs
exactly as it always did; an ``F_P: auto`` grid follows each path round by round
(:mod:`fibril_hpc.campaign.plan.auto`).
"""

from __future__ import annotations

from ..plan import search
from ..plan.auto import path_todo, results_by_path
from ..storage import store


class FixedPlanner:
    """Every pending job of the grid, grouped into loading paths; no follow-ups."""

    fixed = True          # the grid's job count is known in advance

    def __init__(self, spec, writer, retry_failed: bool):
        self.spec = spec
        self.writer = writer
        self.todo = writer.keys_to_run(retry_failed)

    def initial(self) -> list:
        """The tasks of every pending job."""
        return self.spec.tasks(self.todo)

    def after(self, task, records) -> list:  # noqa: ARG002 - same interface as AutoPlanner
        """No follow-ups: a fixed grid knows all its jobs in advance."""
        return []

    def counts(self) -> dict:
        """Done, failed and pending jobs of the grid."""
        return self.writer.counts()


class AutoPlanner:
    """The rounds of ``F_P: auto``, replayed from the file's records (see
    :mod:`fibril_hpc.campaign.plan.auto`)."""

    fixed = False         # the job count grows round by round

    def __init__(self, spec, writer, retry_failed: bool):
        self.spec = spec
        self.auto = spec.auto
        self.retry_failed = retry_failed
        _, recs = store.read_h5_records(spec.output, curves=False)   # the writer folded the journal
        self.done, self.failed = results_by_path(recs.values(), spec.paths(), spec.record_path)

    def _task(self, path):
        todo, _ = path_todo(self.auto, self.done[path], False, self.failed[path])
        return [self.spec.auto_task(path, todo)] if todo else []

    def initial(self) -> list:
        """The current round of every unfinished path (replayed from the records)."""
        out = []
        for path in self.spec.paths():
            todo, _ = path_todo(self.auto, self.done[path], self.retry_failed, self.failed[path])
            if todo:
                out.append(self.spec.auto_task(path, todo))
        return out

    def after(self, task, records) -> list:
        """The next round of the path of ``task`` given its new ``records`` (or nothing)."""
        path = self.spec.path_of_job(task.jobs[0])
        for r in records:
            p = float(r["preload"])
            if r["status"] == "done":
                self.done[path][p] = (float(r["F_P"]), float(r["F_A"]))
                self.failed[path].discard(p)
            else:
                self.failed[path].add(p)
        return self._task(path)

    def counts(self) -> dict:
        """Done and failed jobs so far (an auto grid has no pending count)."""
        done = sum(len(d) for d in self.done.values())
        failed = sum(len(f - set(self.done[p])) for p, f in self.failed.items())
        return {"jobs": done + failed, "done": done, "failed": failed, "pending": 0}


class SearchPlanner:
    """The rounds of a search grid (``sigma_tilde: auto``, ``seeds: auto``), replayed line by
    line from the file's records (:mod:`fibril_hpc.campaign.plan.search`). A path is handed out
    once until its task comes back: a line's replay lists the paths of its unfinished groups,
    some of them still running."""

    fixed = False

    def __init__(self, spec, writer, retry_failed: bool):   # noqa: ARG002 - the others' interface
        self.spec = spec
        self.retry_failed = retry_failed
        _, recs = store.read_h5_records(spec.output, curves=False)
        self.done, self.failed = search.results(spec, recs.values())
        self.running: set = set()
        self.cache: dict = {}            # finished groups' readings (they never change)

    def _line_tasks(self, line, retry: bool) -> list:
        rp = search.replay_line(self.spec, line, self.done, self.failed, retry, self.cache)
        out = [self.spec.auto_task(path, pre) for path, pre in rp.todo
               if path not in self.running]
        self.running.update(self.spec.path_of_job(t.jobs[0]) for t in out)
        return out

    def initial(self) -> list:
        """Every line's current round (replayed from the records)."""
        return [t for line in self.spec.lines() for t in self._line_tasks(line, self.retry_failed)]

    def after(self, task, records) -> list:
        """What the line of ``task`` runs next given its new ``records``."""
        path = self.spec.path_of_job(task.jobs[0])
        self.running.discard(path)
        for r in records:
            p = float(r["preload"])
            if r["status"] == "done":
                self.done.setdefault(path, {})[p] = (float(r["F_P"]), float(r["F_A"]))
                self.failed.get(path, set()).discard(p)
            else:
                self.failed.setdefault(path, set()).add(p)
        return self._line_tasks((path[0],) + tuple(path[3:]), False)

    def counts(self) -> dict:
        """Done and failed jobs so far (a search grid has no pending count)."""
        done = sum(len(d) for d in self.done.values())
        failed = sum(len(f - set(self.done.get(p, {}))) for p, f in self.failed.items())
        return {"jobs": done + failed, "done": done, "failed": failed, "pending": 0}


def make_planner(spec, writer, retry_failed: bool):
    """The planner of ``spec``: :class:`SearchPlanner` for a search grid, :class:`AutoPlanner`
    for ``F_P: auto``, else :class:`FixedPlanner`."""
    cls = SearchPlanner if spec.search else AutoPlanner if spec.auto is not None else FixedPlanner
    return cls(spec, writer, retry_failed)


__all__ = ["FixedPlanner", "AutoPlanner", "SearchPlanner", "make_planner"]
