"""Whether this process was started by an MPI launcher, and connecting to its world.

One table of the environment variables that launchers set (MPICH/Hydra ``PMI_*``, Open MPI,
PMIx, Slurm ``srun``). No mpi4py at import; :func:`connect` initialises MPI only under a launcher.
"""

from __future__ import annotations

import os

from ...errors import ConfigError

#: variables announcing the number of ranks, in the order they are trusted
SIZE_VARS = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "SLURM_STEP_NUM_TASKS")
#: variables announcing this process's rank
RANK_VARS = ("PMI_RANK", "OMPI_COMM_WORLD_RANK", "PMIX_RANK", "SLURM_PROCID")
#: any of these means "started by a launcher"
MARKER_VARS = ("PMI_SIZE", "PMI_RANK", "OMPI_COMM_WORLD_SIZE", "PMIX_RANK",
               "SLURM_STEP_NUM_TASKS", "HYDI_CONTROL_FD", "PMI_FD")


def launcher_size(environ=None) -> tuple[str, int] | None:
    """(variable, ranks) that the launcher announced, or None when none is visible."""
    env = os.environ if environ is None else environ
    for var in SIZE_VARS:
        v = env.get(var)
        if v and v.strip().isdigit():
            return var, int(v)
    return None


def launcher_rank(environ=None) -> int:
    """This process's rank as the launcher announced it (0 without a launcher).

    Only rank 0 prints a user error, so that ``mpirun -n N`` shows it once.
    """
    env = os.environ if environ is None else environ
    for var in RANK_VARS:
        v = env.get(var, "")
        if v.isdigit():
            return int(v)
    return 0


def under_launcher(environ=None) -> bool:
    """Whether a launcher started this process."""
    env = os.environ if environ is None else environ
    return any(v in env for v in MARKER_VARS)


def connect(serial: bool = False):
    """The MPI world to run a campaign on, or None to run serially.

    None when ``serial``, without a launcher, or in a world of one rank. Raises a
    :class:`ConfigError` when mpi4py is missing under a launcher, or when the launcher announced
    N ranks but mpi4py sees another number (a launcher of another MPI library: every rank would
    run the whole campaign alone).
    """
    if serial or not under_launcher():
        return None
    try:
        from .mpi import world

        comm = world()
    except ImportError:
        raise ConfigError("mpi4py", "not installed",
                          "pip install 'fibril-hpc[mpi]' to run under a launcher, or "
                          "--serial") from None
    announced = launcher_size()
    if announced and announced[1] > 1 and comm.Get_size() != announced[1]:
        raise ConfigError(
            "launcher", f"{announced[0]}={announced[1]}",
            f"an MPI world of that size, but mpi4py sees {comm.Get_size()} rank(s): the "
            "launcher does not match mpi4py's MPI library (every rank would run alone); "
            "use the mpirun of the same MPI (pip mpich: the venv's mpirun; site MPI: "
            "pip install 'fibril-hpc[mpi-site]' built against it)")
    return None if comm.Get_size() == 1 else comm


__all__ = ["connect", "launcher_size", "launcher_rank", "under_launcher", "SIZE_VARS",
           "RANK_VARS", "MARKER_VARS"]
