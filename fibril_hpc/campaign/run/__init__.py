"""Running a campaign: one task, the serial runner, the MPI master/worker.

Owns :mod:`.planner` (what runs next: the tasks of a fixed grid, or the rounds of ``F_P:
auto`` read back from the file), :mod:`.execute` (one task: one ``simulate`` call, one record
per job), :mod:`.runner`
(serial, and the task order), :mod:`.mpi` (master/worker: the only mpi4py import of the
package), :mod:`.launcher` (which MPI launcher started us), :mod:`.control` (stop signals,
exit statuses) and :mod:`.progress`.

May import: :mod:`fibril_hpc.campaign.storage` and below, the core's API and model.
Independent of :mod:`fibril_hpc.campaign.analysis` (neither imports the other).
"""
