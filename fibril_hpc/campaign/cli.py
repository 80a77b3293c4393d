"""``fibril-campaign``: run | status | report | export | merge.

A user mistake is one line on stderr and exit status 2 with nothing written. Exit statuses of a
run: 0 every job done, 1 some jobs failed (recorded with their reason), 2 bad input,
75 interrupted (rerun the same command to resume).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys

from ..cli import EXIT_USAGE, _Parser
from ..errors import ConfigError, StoreError

SUBCOMMANDS = ("run", "status", "report", "export", "merge")
PROG = "fibril-campaign"


def _err(msg: str, code: int = EXIT_USAGE) -> int:
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    return code


def _parser() -> _Parser:
    p = _Parser(prog=PROG, description="Parameter campaigns of fibril-hpc into one resumable "
                "HDF5 file (serial, or master/worker under mpirun/srun).")
    sub = p.add_subparsers(dest="cmd", parser_class=_Parser)
    r = sub.add_parser("run", help="run (or resume) a campaign (the default command)")
    r.add_argument("grid", help="campaign grid YAML")
    r.add_argument("--output", metavar="FILE.h5",
                   help="output file (default: the grid's 'output', relative to its folder)")
    r.add_argument("--dry-run", action="store_true", help="print jobs and estimated cost; run nothing")
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
    r.add_argument("--serial", action="store_true",
                   help="never initialise MPI, even under a launcher (one rank only)")
    r.add_argument("-v", "--verbose", action="store_true")
    s = sub.add_parser("status", help="progress of a campaign file (safe while it is written)")
    s.add_argument("file")
    s.add_argument("--json", action="store_true")
    rp = sub.add_parser("report", help="plots and the alpha, beta, sigma_c table")
    rp.add_argument("file")
    rp.add_argument("--out", required=True, metavar="DIR")
    rp.add_argument("--law", default="min", choices=("min", "tanh"),
                    help="law fitted per (k~, sigma~): min (F~_A = min(c F~_P, plateau), the "
                         "default) or tanh (plateau tanh(c F~_P / plateau)); README, 'Report'")
    rp.add_argument("--n-boot", type=int, default=400, metavar="N",
                    help="bootstrap resamples over seeds for the intervals (default 400)")
    e = sub.add_parser("export", help="one CSV row per job")
    e.add_argument("file")
    e.add_argument("--csv", required=True, metavar="OUT.csv")
    m = sub.add_parser("merge", help="merge campaign files into a new one")
    m.add_argument("files", nargs="+")
    m.add_argument("-o", "--output", required=True, metavar="ALL.h5")
    return p


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] not in SUBCOMMANDS and argv[0] not in ("-h", "--help"):
        argv = ["run"] + argv
    p = _parser()
    if not argv:
        p.print_usage(sys.stderr)
        return _err("give a grid YAML (fibril-campaign grid.yaml) or a subcommand: "
                    + ", ".join(SUBCOMMANDS))
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO if getattr(args, "verbose", False) else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return {"run": cmd_run, "status": cmd_status, "report": cmd_report,
                "export": cmd_export, "merge": cmd_merge}[args.cmd](args)
    except BrokenPipeError:            # e.g. `fibril-campaign status f.h5 | head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except ConfigError as exc:
        return _err(str(exc)) if _launcher_rank() == 0 else EXIT_USAGE
    except StoreError as exc:
        return _err(str(exc), 1) if _launcher_rank() == 0 else 1


def _launcher_rank() -> int:
    """This process's rank as the launcher announced it (0 without a launcher): only rank 0
    prints a user error, so that mpirun -n N shows it once."""
    for var in ("PMI_RANK", "OMPI_COMM_WORLD_RANK", "PMIX_RANK", "SLURM_PROCID"):
        v = os.environ.get(var, "")
        if v.isdigit():
            return int(v)
    return 0


def _existing(path, field):
    if not os.path.isfile(path):
        raise ConfigError(field, path, "an existing campaign file")
    from .store import is_campaign_file

    if not is_campaign_file(path):
        raise ConfigError(field, path, "a fibril-hpc campaign HDF5 file")


def _out_file(path, field):
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise ConfigError(field, path, "a path in an existing, writable folder")
    if os.path.isdir(path):
        raise ConfigError(field, path, "a file path, not a folder")


# ------------------------------------------------------------------------------------ run
def cmd_run(args) -> int:
    from .spec import load_spec

    for name in ("checkpoint_s", "grace_s"):
        v = getattr(args, name)
        if not (v >= 0 and v < 1e7):
            raise ConfigError("--" + name.replace("_", "-"), v, "a number of seconds in [0, 1e7)")
    if args.fft_threads is not None and not 1 <= args.fft_threads <= 1024:
        raise ConfigError("--fft-threads", args.fft_threads, "an integer in [1, 1024]")
    spec = load_spec(args.grid, args.output)
    if args.fft_threads is not None:
        spec.base = spec.base.replace(solver=spec.base.solver.replace(
            fft_threads=args.fft_threads))
    comm = None
    if not args.serial:
        from .mpi import launcher_size, under_launcher

        if under_launcher():
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
            if comm.Get_size() == 1:
                comm = None
    rank = 0 if comm is None else comm.Get_rank()
    if args.dry_run:
        if rank == 0:
            _dry_run(spec, args)
        return 0
    kw = dict(extend=args.extend, retry_failed=args.retry_failed, checkpoint_s=args.checkpoint_s,
              progress=not args.no_progress)
    if comm is None:
        from .runner import run_serial

        return run_serial(spec, **kw)
    from .mpi import run_mpi

    return run_mpi(comm, spec, grace_s=args.grace_s, **kw)


def _dry_run(spec, args):
    from .estimate import fft_pair_seconds, task_seconds
    from .store import read_records

    todo = {j.key for j in spec.jobs}
    done = failed = 0
    walls = []
    if os.path.exists(spec.output):
        try:
            meta, recs, _ = read_records(spec.output, curves=False)
        except StoreError:
            recs = {}
        for k, r in recs.items():
            if r.get("status") == "done":
                done += k in todo
                walls.append(float(r.get("wall_s", 0.0)) / max(1, int(r.get("group_size", 1))))
                todo.discard(k)
            elif r.get("status") == "failed":
                failed += k in todo
                if not args.retry_failed:
                    todo.discard(k)
    tasks = spec.tasks(todo)
    pair_s, m, epp = fft_pair_seconds(spec.base)
    est = sum(task_seconds(t.scene, len(t.jobs), pair_s, epp) for t in tasks)
    how = "model"
    if walls:
        est = sum(walls) / len(walls) * len(todo)
        how = f"measured mean of {len(walls)} finished jobs"
    print(f"campaign {spec.campaign_hash[:12]}: {len(spec.jobs)} jobs "
          f"({len(spec.k_tilde)} k_tilde x {len(spec.sigma_tilde)} sigma_tilde x "
          f"{len(spec.preloads)} {spec.preload_kind} x {len(spec.seeds)} seeds), "
          f"{len(spec.tasks())} loading paths")
    print(f"output {spec.output}: {done} done, {failed} failed, {len(todo)} to run "
          f"in {len(tasks)} simulate calls")
    print(f"grid: {spec.base.n_side}x{spec.base.n_side} pillars, FFT {m}^2, {epp} elements per "
          f"pillar, {pair_s * 1e3:.3f} ms per FFT pair with {spec.base.solver.threads} thread(s)")
    print(f"estimated cost ({how}): {est / 3600:.3g} core-hours "
          f"x {spec.base.solver.threads} thread(s) per rank "
          f"(~{est / 60:.3g} min on one rank)")


# ------------------------------------------------------------------------------------ status
def cmd_status(args) -> int:
    from .data import load_campaign
    from .spec import spec_from_dict

    _existing(args.file, "file")
    c = load_campaign(args.file, curves=False)
    import yaml

    grid_keys = None
    try:
        resolved = yaml.safe_load(c.meta.get("campaign_yaml", ""))
        scene = resolved.pop("scene")
        resolved["scene"] = scene
        resolved["output"] = os.path.abspath(args.file)
        spec = spec_from_dict(resolved)
        grid_keys = {j.key: j for j in spec.jobs}
    except Exception:  # noqa: BLE001 - a merged file may hold several grids
        spec = None
    by_k: dict = {}
    recs = {j["key"]: j for j in c.jobs}
    keys = set(recs) | set(grid_keys or ())
    for k in keys:
        r = recs.get(k)
        kt = r["k_tilde"] if r else grid_keys[k].k_tilde
        st = r["status"] if r else "pending"
        d = by_k.setdefault(kt, {"done": 0, "failed": 0, "pending": 0})
        d[st if st in d else "failed"] += 1
    tot = {s: sum(d[s] for d in by_k.values()) for s in ("done", "failed", "pending")}
    walls = [r["wall_s"] / max(1, r.get("group_size", 1)) for r in c.jobs
             if r["status"] == "done"]
    if args.json:
        print(json.dumps({"file": args.file, "campaign_hash": c.meta.get("campaign_hash"),
                          "updated": c.meta.get("updated"), **tot,
                          "in_journal": c.pending_in_journal,
                          "by_k_tilde": {repr(k): v for k, v in sorted(by_k.items())}}))
        return 0
    print(f"{args.file}: campaign {str(c.meta.get('campaign_hash'))[:12]}, "
          f"updated {c.meta.get('updated')}"
          + (f", {c.pending_in_journal} record(s) in the journal" if c.pending_in_journal else ""))
    print(f"  {tot['done']} done, {tot['failed']} failed, {tot['pending']} pending"
          + (f"; {sum(walls):.1f} s of compute in done jobs" if walls else ""))
    print(f"  {'k_tilde':>10} {'done':>6} {'failed':>6} {'pending':>7}")
    for k, d in sorted(by_k.items()):
        print(f"  {k:>10g} {d['done']:>6} {d['failed']:>6} {d['pending']:>7}")
    fails = [r for r in c.jobs if r["status"] == "failed"][:5]
    for r in fails:
        print(f"  failed {r['key']} (k~={r['k_tilde']:g}, sigma~={r['sigma_tilde']:g}, "
              f"{r['preload_kind']}={r['preload']:g}, seed={r['seed']}): {r['message']}")
    return 0


# ------------------------------------------------------------------------------------ export
def cmd_export(args) -> int:
    import csv

    from .data import COLUMNS, load_campaign

    _existing(args.file, "file")
    _out_file(args.csv, "--csv")
    c = load_campaign(args.file, curves=False)
    tmp = args.csv + ".part"
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        for j in c.jobs:
            w.writerow([_csv_value(j.get(col)) for col in COLUMNS])
    os.replace(tmp, args.csv)
    print(f"{args.csv}: {len(c.jobs)} jobs")
    return 0


def _csv_value(v):
    if isinstance(v, float):
        return repr(v)
    return "" if v is None else v


# ------------------------------------------------------------------------------------ merge
def cmd_merge(args) -> int:
    from .store import newer, read_records, write_merged

    for f in args.files:
        _existing(f, "files")
    _out_file(args.output, "--output")
    if os.path.exists(args.output):
        raise ConfigError("--output", args.output, "a new file name (it exists)")
    if len(set(map(os.path.abspath, args.files))) != len(args.files):
        raise ConfigError("files", args.files, "distinct files")
    merged: dict = {}
    sources = []
    first = None
    for f in args.files:
        meta, recs, _ = read_records(f)
        first = first or meta
        sources.append({"file": os.path.abspath(f), "campaign_hash": meta.get("campaign_hash"),
                        "campaign_yaml": meta.get("campaign_yaml")})
        for k, r in recs.items():
            if newer(r, merged.get(k)) and not (merged.get(k, {}).get("status") == "done"):
                merged[k] = r
    hashes = sorted({s["campaign_hash"] for s in sources})
    root = {k: v for k, v in first.items() if k not in ("created", "updated")}
    if len(hashes) > 1:
        from .spec import campaign_hash_of

        root["campaign_hash"] = "merged-" + campaign_hash_of(hashes)[:52]
    root["merged_from"] = json.dumps(sources)
    root["n_jobs"] = len(merged)
    write_merged(args.output, root, list(merged.values()))
    print(f"{args.output}: {len(merged)} jobs from {len(args.files)} files")
    return 0


# ------------------------------------------------------------------------------------ report
def cmd_report(args) -> int:
    from .report import write_report

    _existing(args.file, "file")
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise ConfigError("--out", args.out, "a folder (it is a file)")
    parent = os.path.dirname(os.path.abspath(args.out))
    if not os.path.isdir(parent):
        raise ConfigError("--out", args.out, "a folder whose parent exists")
    if not 20 <= args.n_boot <= 100000:
        raise ConfigError("--n-boot", args.n_boot, "an integer in [20, 100000]")
    os.makedirs(args.out, exist_ok=True)
    files = write_report(args.file, args.out, law=args.law, n_boot=args.n_boot)
    for f in files:
        print(f)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
