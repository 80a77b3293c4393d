"""``fibril-campaign``: run | status | report | export | merge (the logic lives in ``campaign/``).

A user mistake is one line on stderr and exit status 2 with nothing written. Exit statuses of a
run: 0 every job done, 1 some jobs failed (recorded with their reason), 2 bad input,
75 interrupted (rerun the same command to resume).
"""

from __future__ import annotations

import json
import os
import sys

from ..campaign.run.launcher import launcher_rank
from ..errors import (
    EXIT_FAILED,
    EXIT_INTERRUPTED,
    EXIT_OK,
    EXIT_USAGE,
    ConfigError,
    DamagedFileError,
    Interruption,
    StoreError,
    UnknownLayoutError,
)
from ..io.files import check_output_folder, check_writable, make_new_folder
from .campaign_args import PROG, SUBCOMMANDS, parser
from .common import OUT_OF_MEMORY, error, interruptible, pipe_safe, setup_logging



@pipe_safe
@interruptible(PROG, "files are written whole or not at all; rerun the same command (a run "
               "resumes)", EXIT_INTERRUPTED)   # a run handles its own stop signals (run.control)
def main(argv=None) -> int:
    """``fibril-campaign``; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] not in SUBCOMMANDS and argv[0] not in ("-h", "--help", "--version"):
        argv = ["run"] + argv
    p = parser()
    if not argv:                       # one line (the usage would wrap over several)
        return error(PROG, "give a grid YAML (fibril-campaign grid.yaml) or a subcommand: "
                     + ", ".join(SUBCOMMANDS))
    args = p.parse_args(argv)
    setup_logging(getattr(args, "verbose", False))
    try:
        return {"run": cmd_run, "status": cmd_status, "report": cmd_report,
                "export": cmd_export, "merge": cmd_merge, "verify": cmd_verify,
                "salvage": cmd_salvage, "example": cmd_example}[args.cmd](args)
    except ConfigError as exc:
        return error(PROG, exc) if launcher_rank() == 0 else EXIT_USAGE
    except Interruption as exc:        # a full disk: rerun once there is room
        return error(PROG, exc, EXIT_INTERRUPTED) if launcher_rank() == 0 else EXIT_INTERRUPTED
    except (DamagedFileError, UnknownLayoutError) as exc:
        return error(PROG, exc) if launcher_rank() == 0 else EXIT_USAGE
    except StoreError as exc:
        return error(PROG, exc, EXIT_FAILED) if launcher_rank() == 0 else EXIT_FAILED
    except MemoryError:
        return error(PROG, OUT_OF_MEMORY) if launcher_rank() == 0 else EXIT_USAGE


def _existing(path, field) -> dict:
    """The root attributes of an existing campaign file (read once, checked)."""
    from ..campaign.storage.store import read_root

    if not os.path.isfile(path):
        raise ConfigError(field, path, "an existing campaign file")
    try:
        return read_root(path)         # a damaged file: DamagedFileError, one line, exit 2
    except (DamagedFileError, UnknownLayoutError):
        raise
    except StoreError:
        with open(path, "rb") as fh:
            hdf5 = fh.read(8) == b"\x89HDF\r\n\x1a\n"
        raise ConfigError(field, path, "a fibril-hpc campaign HDF5 file" + (
            f" (if this is a damaged one, `fibril-campaign salvage {path} -o NEW.h5` copies "
            "every record that reads and verifies)" if hdf5 else "")) from None


# ------------------------------------------------------------------------------------ run
def cmd_run(args) -> int:
    """Run (or resume) a campaign, or print its plan with ``--dry-run``."""
    from ..campaign.plan.shard import parse_shard, shard_spec
    from ..campaign.plan.spec import load_spec
    from ..campaign.run.launcher import connect

    if args.grid is None:
        raise ConfigError("grid", None, "a grid YAML file (fibril-campaign grid.yaml)")
    for name in ("checkpoint_s", "grace_s"):
        v = getattr(args, name)
        if not (v >= 0 and v < 1e7):
            raise ConfigError("--" + name.replace("_", "-"), v, "a number of seconds in [0, 1e7)")
    if args.fft_threads is not None and not 1 <= args.fft_threads <= 1024:
        raise ConfigError("--fft-threads", args.fft_threads, "an integer in [1, 1024]")
    shard = parse_shard(args.shard)
    spec = load_spec(args.grid, args.output)
    if shard is not None and shard[1] > 1:
        spec = shard_spec(spec, *shard, output=spec.output if args.output else None)
        if launcher_rank() == 0:
            print(f"fibril-campaign: shard {shard[0]}/{shard[1]}: "
                  + (f"{len(spec.lines())} search lines" if spec.search else
                     f"{len(spec.jobs)} jobs" if spec.auto is None else
                     f"{len(spec.paths())} F_P: auto paths") + f" into {spec.output}",
                  file=sys.stderr)
    if args.fft_threads is not None:
        spec.base = spec.base.replace(solver=spec.base.solver.replace(
            fft_threads=args.fft_threads))
    if not args.ignore_memory_check:
        from ..inputs.limits import check_memory

        # before any operator is built; a grid sweeping n_side: its largest brush (the base)
        check_memory(spec.base, field="sweep.n_side" if "n_side" in spec.sweep else "scene",
                     preloads=spec.path_preloads())
    comm = connect(serial=args.serial)
    rank = 0 if comm is None else comm.Get_rank()
    if args.dry_run:
        from ..campaign.storage.writer import check_output

        check_output(spec, args.extend)   # what the run would refuse, the dry run refuses
        if rank == 0:
            _print_plan(spec, args.retry_failed)
        return EXIT_OK
    kw = dict(extend=args.extend, retry_failed=args.retry_failed, checkpoint_s=args.checkpoint_s,
              progress=not args.no_progress)
    if comm is None:
        from ..campaign.run.runner import run_serial

        return run_serial(spec, **kw)
    from ..campaign.run.mpi import run_mpi

    return run_mpi(comm, spec, grace_s=args.grace_s, **kw)


def _print_plan(spec, retry_failed: bool) -> None:
    from ..campaign.analysis.status import plan, search_cost_line, search_plan_line
    from ..campaign.plan.estimate import AUTO_LATER_TASKS
    from ..inputs.limits import available_memory, memory_estimate

    pl = plan(spec, retry_failed)
    swept = "".join(f" x {len(v)} sweep.{k}" for k, v in spec.sweep.items())
    if spec.search:
        print(search_plan_line(spec))
    elif spec.auto is None:
        print(f"campaign {spec.campaign_hash[:12]}: {len(spec.jobs)} jobs "
              f"({len(spec.k_tilde)} k_tilde x {len(spec.sigma_tilde)} sigma_tilde x "
              f"{len(spec.preloads)} {spec.preload_kind} x {len(spec.seeds)} seeds{swept}), "
              f"{spec.n_tasks()} loading paths")
    else:
        a = spec.auto
        print(f"campaign {spec.campaign_hash[:12]}: F_P auto, {len(spec.paths())} loading paths "
              f"({len(spec.k_tilde)} k_tilde x {len(spec.sigma_tilde)} sigma_tilde x "
              f"{len(spec.seeds)} seeds{swept}); round 0: F_P = "
              f"{', '.join(f'{x:g}' for x in a.start)}; "
              f"up to {a.rounds - 1} more rounds until {a.below} preloads lie below the kink and "
              f"{a.above} above it (the counts below are round 0's)")
    print(f"output {spec.output}: {pl.done} done, {pl.failed} failed, {len(pl.to_run)} to run "
          f"in {pl.n_tasks} simulate calls")
    sizes = "" if len(spec.n_sides) < 2 else (
        f"n_side {', '.join(map(str, spec.n_sides))}; the largest: ")
    print(f"grid: {sizes}{spec.base.n_side}x{spec.base.n_side} pillars, FFT {pl.fft_size}^2, "
          f"{pl.elements_per_diameter:.2f} elements per pillar diameter ({pl.elements_per_pillar} in "
          f"a pillar's footprint), {pl.fft_pair_s * 1e3:.3f} ms per FFT "
          f"pair with {spec.base.solver.threads} thread(s)")
    need = memory_estimate(spec.base, spec.path_preloads())[0]
    avail = available_memory()
    print(f"memory: about {need / 2**30:.2g} GiB per rank (estimated"
          + (f"; {avail / 2**30:.1f} GiB available now" if avail is not None else "") + ")")
    est = pl.estimate_s
    print(f"estimated cost ({pl.how}): {est / 3600:.3g} core-hours "
          f"x {spec.base.solver.threads} thread(s) per rank "
          f"(~{est / 60:.3g} min on one rank)"
          + (" for round 0" if spec.auto is not None else ""))
    if pl.later_s:
        tot = est + pl.later_s
        print(f"with the later F_P auto rounds (expected: {AUTO_LATER_TASKS:g} more loading paths "
              f"per path, measured): about {tot / 3600:.3g} core-hours (~{tot / 60:.3g} min on "
              "one rank)")
    if spec.search and pl.n_tasks:
        print(search_cost_line(spec, (est + pl.later_s) / pl.n_tasks))


# ------------------------------------------------------------------------------------ status
def cmd_status(args) -> int:
    """Print the done/failed/pending counts of a campaign file (safe while it is written)."""
    from ..campaign.analysis.status import file_status

    _existing(args.file, "file")
    st = file_status(args.file)
    meta, tot = st.meta, st.totals
    if args.json:
        print(json.dumps({"file": args.file, "campaign_hash": meta.get("campaign_hash"),
                          "updated": meta.get("updated"), **tot,
                          "in_journal": st.in_journal, "corrupt": st.corrupt,
                          "unchecked_keys": st.unchecked, "foreign": sorted(st.foreign),
                          "by_k_tilde": {repr(k): v for k, v in st.by_k_tilde.items()},
                          **({"by_n_side_k_tilde": [{"n_side": n, "k_tilde": k, **v} for (n, k), v
                                                    in st.by_n_side.items()]}
                             if st.by_n_side else {})}))
        return EXIT_OK
    print(f"{args.file}: campaign {str(meta.get('campaign_hash'))[:12]}, "
          f"updated {meta.get('updated')}"
          + (f", {st.in_journal} record(s) in the journal" if st.in_journal else ""))
    walls = st.done_wall_s
    print(f"  {tot['done']} done, {tot['failed']} failed, {tot['pending']} pending"
          + (f" ({len(st.corrupt)} of them corrupt in the file: `verify` lists them, resume "
             "recomputes them)" if st.corrupt else "")
          + (f"; {sum(walls):.1f} s of compute in done jobs" if walls else ""))
    if tot["unchecked"]:
        print(f"  {tot['unchecked']} unchecked (no checksum: nothing vouches for them; left out "
              "of reports and exports unless --include-unchecked)")
    if st.foreign:
        print(f"  {len(st.foreign)} foreign member(s) of /jobs (links or data from elsewhere, "
              "or keys of no job of this grid): never counted; `verify` lists them")
    if st.by_n_side:                   # a grid sweeping the brush size: by (n_side, k~)
        print(f"  {'n_side':>6} {'k_tilde':>10} {'done':>6} {'failed':>6} {'pending':>7}")
        for (n, k), d in st.by_n_side.items():
            print(f"  {'?' if n is None else n:>6} {k:>10g} {d['done']:>6} {d['failed']:>6} "
                  f"{d['pending']:>7}")
    else:
        print(f"  {'k_tilde':>10} {'done':>6} {'failed':>6} {'pending':>7}")
        for k, d in st.by_k_tilde.items():
            print(f"  {k:>10g} {d['done']:>6} {d['failed']:>6} {d['pending']:>7}")
    for r in st.failed[:5]:
        size = f"n_side={r.get('n_side')}, " if st.by_n_side else ""
        print(f"  failed {r['key']} ({size}k~={r['k_tilde']:g}, sigma~={r['sigma_tilde']:g}, "
              f"{r['preload_kind']}={r['preload']:g}, seed={r['seed']}): {r['message']}")
    return EXIT_OK


# ------------------------------------------------------------------------------------ export
def cmd_export(args) -> int:
    """Write one row per job as CSV and/or Parquet."""
    from ..campaign.analysis import export as ex
    from ..campaign.storage.guard import check_output

    _existing(args.file, "file")
    if not (args.csv or args.parquet or args.netcdf):
        raise ConfigError("export", "no output given", "--csv OUT.csv, --parquet OUT.parquet "
                          "and/or --netcdf OUT.nc")
    outs = [(opt, path) for opt, path in (("--csv", args.csv), ("--parquet", args.parquet),
                                          ("--netcdf", args.netcdf)) if path]
    for opt, path in outs:
        check_writable(path, opt)
        check_output(path, opt, force=args.force)
    if len({os.path.realpath(p) for _, p in outs}) < len(outs):
        raise ConfigError(outs[-1][0], outs[-1][1], "a file other than the other outputs")
    if args.parquet and not ex.parquet_available():
        raise ConfigError("--parquet", args.parquet,
                          "a Parquet output with pandas and pyarrow installed "
                          "(pip install 'fibril-hpc[report]'), or --csv")
    if args.netcdf and not ex.netcdf_available():
        raise ConfigError("--netcdf", args.netcdf, "a netCDF output with xarray and h5netcdf "
                          "installed (pip install 'fibril-hpc[netcdf]'), or --csv")
    export_csv, export_parquet = ex.export_csv, ex.export_parquet
    def new(opt):                     # without --force: a new file, checked as it is written
        return None if args.force else opt

    if args.csv:
        n = export_csv(args.file, args.csv, include_unchecked=args.include_unchecked,
                       exclusive=new("--csv"))
        print(f"{args.csv}: {n} jobs")
    if args.parquet:
        n = export_parquet(args.file, args.parquet, include_unchecked=args.include_unchecked,
                           exclusive=new("--parquet"))
        print(f"{args.parquet}: {n} jobs")
    if args.netcdf:
        n = ex.export_netcdf(args.file, args.netcdf, include_unchecked=args.include_unchecked,
                             exclusive=new("--netcdf"))
        print(f"{args.netcdf}: {n} jobs")
    return EXIT_OK


# ------------------------------------------------------------------------------------ merge
def cmd_merge(args) -> int:
    """Merge campaign files into a new one."""
    from ..campaign.storage.guard import check_new
    from ..campaign.storage.merge import merge_files

    for f in args.files:
        _existing(f, "files")
    check_writable(args.output, "--output")
    check_new(args.output, "--output")
    if len(set(map(os.path.abspath, args.files))) != len(args.files):
        raise ConfigError("files", args.files, "distinct files")
    if args.prefer is not None and os.path.abspath(args.prefer) not in map(os.path.abspath,
                                                                           args.files):
        raise ConfigError("--prefer", args.prefer, "one of the files being merged")
    n = merge_files(args.files, args.output, on_conflict=args.on_conflict, prefer=args.prefer,
                    include_unchecked=args.include_unchecked)
    left = [f"{n[k]} {what}" for k, what in (("foreign", "foreign left out"),
                                             ("unchecked_left_out", "unchecked left out"),
                                             ("conflicts", "conflict(s) resolved")) if n[k]]
    print(f"{args.output}: {n['jobs']} jobs from {len(args.files)} files"
          + (f" ({', '.join(left)})" if left else ""))
    return EXIT_OK


# ------------------------------------------------------------------------------------ verify
def cmd_verify(args) -> int:
    """Check every record; exit 0 when every record is verified, 1 when records or journal
    frames are damaged, unchecked or foreign, 2 when the HDF5 structure cannot be read."""
    from ..campaign.storage.verify import verify_file

    _existing(args.file, "file")       # not a campaign file: one line, exit 2 (not "damaged")
    v = verify_file(args.file)
    if v.damaged:
        return error(PROG, v.damaged)
    for line in v.lines():
        print(line)
    return EXIT_OK if v.clean else EXIT_FAILED


def cmd_example(args) -> int:
    """``fibril-campaign example [NAME] [-o FILE]``: the shipped grids and Slurm scripts."""
    from .. import examples
    from ..campaign.storage.guard import check_new

    if args.name is None:
        for name in examples.names():
            print(f"{name:20s} {examples.summary(name)}")
        return EXIT_OK
    name = examples.resolve(args.name)
    if name is None:
        raise ConfigError("name", args.name, "one of " + ", ".join(examples.names()))
    text = examples.text(name)
    if args.output is None:
        sys.stdout.write(text)
        return EXIT_OK
    from ..io.files import check_writable, write_text_atomically

    check_writable(args.output, "--output")
    check_new(args.output, "--output")
    write_text_atomically(args.output, text, "writing the example", exclusive="--output")
    if examples.is_script(name):
        os.chmod(args.output, 0o755)
    print(f"{args.output}: {name}", file=sys.stderr)
    return EXIT_OK


def cmd_salvage(args) -> int:
    """Copy every readable, verified record into a new file to resume from."""
    from ..campaign.storage.guard import check_new
    from ..campaign.storage.verify import salvage_file
    from ..campaign.storage.writer import has_second_copies

    if not os.path.isfile(args.file) and not has_second_copies(args.file):   # a damaged, cut or
        raise ConfigError("file", args.file, "an existing campaign file")  # deleted one is
    # what salvage is for
    check_writable(args.output, "--output")
    check_new(args.output, "--output")
    n = salvage_file(args.file, args.output, keep_unchecked=args.keep_unchecked)
    print(f"{args.output}: {n['copied']} record(s) copied ({n['from_journal']} from the journal);"
          f" {n['corrupt']} corrupt, {n['foreign']} foreign and {n['unchecked_left_out']} "
          "unchecked left out; rerun the "
          f"campaign with --output {args.output} to recompute what is missing")
    return EXIT_OK


# ------------------------------------------------------------------------------------ report
def cmd_report(args) -> int:
    """Write the plots and the alpha, beta, sigma_c table."""
    from ..campaign.analysis.report import write_report
    from ..campaign.storage.guard import check_report_folder
    from ..campaign.analysis.variants import parse_where, swept_lab_fields

    root = _existing(args.file, "file")
    check_output_folder(args.out, "--out")
    check_report_folder(args.out, "--out", force=args.force)
    if not 20 <= args.n_boot <= 100000:
        raise ConfigError("--n-boot", args.n_boot, "an integer in [20, 100000]")
    parse_where(args.where, swept_lab_fields(root), "--where")       # before writing anything
    if not os.path.isdir(args.out):    # a new folder: made atomically (one of two racing wins)
        make_new_folder(args.out, "--out")
    if not os.access(args.out, os.W_OK):
        raise ConfigError("--out", args.out, "a writable folder")
    files = write_report(args.file, args.out, n_boot=args.n_boot,
                         include_unchecked=args.include_unchecked, where=args.where)
    for f in files:
        print(f)
    return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
