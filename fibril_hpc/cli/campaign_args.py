"""The argument parser of ``fibril-campaign`` (:mod:`.campaign` runs the subcommands)."""

from __future__ import annotations

from .common import Parser, add_version

ON_CONFLICT = ("refuse", "first", "last")
UNCHECKED_HELP = ("also take records without a checksum (nothing vouches for them: written "
                  "before checksums existed, or stripped of theirs)")
FORCE_HELP = ("replace existing output files (never a campaign file, a journal or a file a "
              "running campaign holds)")
SUBCOMMANDS = ("run", "status", "report", "export", "merge", "verify", "salvage", "example")
PROG = "fibril-campaign"


def parser() -> Parser:
    """The argument parser of ``fibril-campaign`` (every subcommand and option)."""
    p = Parser(prog=PROG, description="Parameter campaigns of fibril-hpc into one resumable "
                "HDF5 file (serial, or master/worker under mpirun/srun).")
    add_version(p)
    sub = p.add_subparsers(dest="cmd", parser_class=Parser)
    r = sub.add_parser("run", help="run (or resume) a campaign (the default command)")
    # optional for argparse, required by cmd_run: `fibril-campaign --bogus` then names the
    # unknown option instead of "the following arguments are required: grid"
    r.add_argument("grid", nargs="?", help="campaign grid YAML")
    r.add_argument("--output", metavar="FILE.h5",
                   help="output file (default: the grid's 'output', relative to its folder)")
    r.add_argument("--dry-run", action="store_true",
                   help="print jobs and estimated cost, or refuse as the run would (exit 2); "
                        "run nothing")
    r.add_argument("--retry-failed", action="store_true", help="rerun jobs recorded as failed")
    r.add_argument("--extend", action="store_true",
                   help="accept an output file written from another grid and add this grid's jobs")
    r.add_argument("--checkpoint-s", type=float, default=30.0, metavar="S",
                   help="publish finished records into the HDF5 file at most every S seconds "
                        "(they are safe in the journal meanwhile; default 30)")
    r.add_argument("--grace-s", type=float, default=120.0, metavar="S",
                   help="on a stop signal, wait at most S seconds for jobs in flight (MPI)")
    r.add_argument("--fft-threads", type=int, default=None, metavar="N",
                   help="override solver.fft_threads of every job (threads per rank; not part of "
                        "the job keys), e.g. $SLURM_CPUS_PER_TASK")
    r.add_argument("--no-progress", action="store_true", help="no progress line")
    r.add_argument("--ignore-memory-check", action="store_true",
                   help="run even if one job's memory estimate exceeds the memory available")
    r.add_argument("--serial", action="store_true",
                   help="never initialise MPI, even under a launcher (one rank only)")
    r.add_argument("--shard", metavar="I/N",
                   help="run only shard I of N (0 <= I < N: whole loading paths, a stable "
                        "rule over their keys) into OUTPUT.shard-I-of-N.h5, for `merge` to "
                        "join; default under `sbatch --array`: from SLURM_ARRAY_TASK_ID and "
                        "SLURM_ARRAY_TASK_COUNT")
    r.add_argument("-v", "--verbose", action="store_true", help="log what happens (INFO)")
    s = sub.add_parser("status", help="progress of a campaign file (safe while it is written)")
    s.add_argument("file", help="campaign HDF5 file")
    s.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    rp = sub.add_parser("report", help="plateau, c, c0, alpha, beta, sigma_c: tables, figures, "
                                       "README.md and report.html (docs/report.md)")
    rp.add_argument("file", help="campaign HDF5 file")
    rp.add_argument("--out", required=True, metavar="DIR",
                    help="folder for README.md, report.html, the CSV tables and the figures")
    rp.add_argument("--n-boot", type=int, default=400, metavar="N",
                    help="bootstrap resamples over seeds for the seed intervals (default 400)")
    rp.add_argument("--include-unchecked", action="store_true", help=UNCHECKED_HELP)
    rp.add_argument("--force", action="store_true",
                    help="write into an existing folder that holds other files than an earlier "
                         "report (" + FORCE_HELP + ")")
    rp.add_argument("--where", action="append", default=[], metavar="NAME=VALUE",
                    help="a grid sweeping lab fields (tip, heights, ...; not n_side or k_machine, "
                         "which have their own reading): read the jobs with this swept value "
                         "(repeatable, one per field; a field not named reads its first "
                         "listed value), e.g. --where tip_radius=4")
    e = sub.add_parser("export", help="one row per job (CSV, Parquet) or the whole campaign "
                       "with its curves (netCDF)")
    e.add_argument("file", help="campaign HDF5 file")
    e.add_argument("--csv", metavar="OUT.csv", help="write a CSV file")
    e.add_argument("--parquet", metavar="OUT.parquet",
                   help="write a Parquet file (needs pandas and pyarrow: the 'report' extra)")
    e.add_argument("--netcdf", metavar="OUT.nc",
                   help="write a netCDF-4 file over (k_tilde, sigma_tilde, preload, seed; n_side "
                        "first when the grid sweeps it) with the curves (needs xarray and "
                        "h5netcdf: the 'netcdf' extra)")
    e.add_argument("--include-unchecked", action="store_true", help=UNCHECKED_HELP)
    e.add_argument("--force", action="store_true", help=FORCE_HELP)
    m = sub.add_parser("merge", help="merge campaign files into a new one")
    m.add_argument("files", nargs="+", help="campaign files (shards) of one grid")
    m.add_argument("-o", "--output", required=True, metavar="ALL.h5",
                   help="the merged file (new; none of the inputs)")
    m.add_argument("--on-conflict", choices=ON_CONFLICT, default="refuse",
                   help="a key done in two files with different numbers: refuse (default), or "
                        "keep the first or the last file's record")
    m.add_argument("--prefer", metavar="FILE",
                   help="on such a conflict, the record of FILE (one of the files) wins")
    m.add_argument("--include-unchecked", action="store_true",
                   help=UNCHECKED_HELP + " (copied without a checksum)")
    v = sub.add_parser("verify", help="check every record of a file against its checksum")
    v.add_argument("file", help="campaign HDF5 file")
    sv = sub.add_parser("salvage", help="copy every readable, verified record into a new file")
    sv.add_argument("file", help="damaged campaign HDF5 file (read only)")
    sv.add_argument("-o", "--output", required=True, metavar="NEW.h5",
                    help="the new file with every readable, verified record")
    sv.add_argument("--keep-unchecked", action="store_true",
                    help="also copy records written before checksums existed")
    ex = sub.add_parser("example", help="print a shipped grid or Slurm script (no NAME: list "
                        "them), e.g. `fibril-campaign example demo > grid.yaml`")
    ex.add_argument("name", nargs="?", help="the example: demo, paper, machine, report_example, "
                    "finite_size, campaign.sbatch, array.sbatch, chain.sh")
    ex.add_argument("-o", "--output", metavar="FILE",
                    help="write it to FILE (a new file; scripts made executable), not stdout")
    return p
