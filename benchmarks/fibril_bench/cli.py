"""Arguments, the section table, and the JSON result of the benchmark."""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import subprocess
import sys
import time

from fibril_hpc.io.results import software_versions

from ..common import git_state
from .campaign_section import section_campaign
from .memory import ROOT, section_memory
from .peers import section_peers
from .solver_sections import section_cg, section_curves, section_fft, section_opts
from .table import format_table, table_rows
from .timing import FLAG, PIN_ENV, FloorCache, loadavg

#: every section, by name; ``opts`` (minutes) runs only when named in ``--only``
SECTIONS = {"fft": section_fft, "cg": section_cg, "curves": section_curves,
            "memory": section_memory, "campaign": section_campaign, "peers": section_peers,
            "opts": section_opts}
DEFAULT_SECTIONS = ("fft", "cg", "curves", "memory", "campaign", "peers")
CHILD_FLAG = "FIBRIL_BENCH_PINNED"

#: (n_side, pitches) of the grid-size sweep; pitch p gives N = n_side p, m = padded_size(N)
FULL = {"n_side": 18, "pitches": (9, 15, 17, 29, 35), "peer_pitches": (15, 29), "runs": 3,
        "peer_runs": 3, "d_tilde": 1.5}
QUICK = {"n_side": 6, "pitches": (7, 9), "peer_pitches": (9,), "runs": 2, "peer_runs": 2,
         "d_tilde": 1.5}


def _versions() -> dict:
    v = dict(software_versions())
    v["python"] = platform.python_version()
    for mod in ("ContactMechanics", "tamaas", "muGrid"):
        try:
            v[mod] = getattr(__import__(mod), "__version__", "")
        except Exception:  # noqa: BLE001
            v[mod] = None
    return v


def run(args, log=print) -> dict:
    """Run the selected sections; write and return the JSON result."""
    cfg = dict(QUICK if args.quick else FULL)
    cfg["clock"] = args.clock
    cfg["peer_tol"] = args.tol
    cfg["curve_n_side"] = 3 if args.quick else 18
    cfg["memory_pitches"] = (cfg["pitches"][-1],) if args.quick else (15, 29)
    cfg["campaign"] = ({"n_side": 2, "epd": 4, "k_tilde": [1], "sigma_tilde": [0.5],
                        "F_P": [1],
                        "seeds": 2, "reps": 1, "timeout_s": 300, "mpi": False}
                       if args.quick else
                       {"n_side": 6, "epd": 6, "k_tilde": [1, 0.01], "F_P": [1, 3],
                        "sigma_tilde": [0.3, 1], "seeds": 3, "reps": 2, "timeout_s": 900,
                        "mpi": True})
    if args.runs:
        cfg["runs"] = cfg["peer_runs"] = args.runs
    if args.pitches:
        cfg["pitches"] = tuple(args.pitches)
    if args.peer_pitches:
        cfg["peer_pitches"] = tuple(args.peer_pitches)
    sections = DEFAULT_SECTIONS if not args.only else tuple(args.only.split(","))
    bad = [s for s in sections if s not in SECTIONS]
    if bad:
        raise SystemExit(f"fibril-bench: unknown section {bad[0]!r} "
                         f"(known: {', '.join(SECTIONS)})")
    floors = FloorCache(args.planner, max(3, cfg["runs"]), args.clock)
    started = _dt.datetime.now(_dt.UTC)
    res = {"meta": {"command": " ".join(["fibril-bench"] + list(args.argv)),
                    "mode": "quick" if args.quick else "full",
                    "started_utc": started.strftime("%Y-%m-%dT%H:%M:%SZ"),
                    "host": platform.node(), "cpus": os.cpu_count(),
                    "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                    else None,
                    "loadavg_start": loadavg(), "threads": PIN_ENV,
                    "fftw_planner": FLAG[args.planner], "clock": args.clock, "config": cfg,
                    "versions": _versions(), "git": git_state()}}
    cfg["presets"] = [("fast", None), ("default", None)]
    if args.accurate:
        cfg["presets"].append(("accurate", args.accurate_cap))
    for s in sections:
        t0 = time.perf_counter()
        load0 = loadavg()
        res[s] = SECTIONS[s](cfg, floors, log)
        res["meta"].setdefault("section_wall_s", {})[s] = time.perf_counter() - t0
        res["meta"].setdefault("section_load", {})[s] = {"start": load0, "end": loadavg()}
    res["floors"] = {str(m): {k: v for k, v in f.items()} for m, f in floors.data.items()}
    res["meta"]["loadavg_end"] = loadavg()
    res["meta"]["finished_utc"] = _dt.datetime.now(_dt.UTC).strftime(
        "%Y-%m-%dT%H:%M:%SZ")
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"bench-{started.strftime('%Y-%m-%d-%H%M%S')}"
                        f"{'-quick' if args.quick else ''}.json")
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        json.dump(res, fh, indent=1, default=float)
    os.replace(tmp, path)
    res["meta"]["json"] = path
    return res


def parse_args(argv):
    """The benchmark's arguments (``args.argv`` keeps the command line)."""
    ap = argparse.ArgumentParser(prog="python -m benchmarks.fibril_bench",
                                 description="The developer benchmark of fibril-hpc.")
    ap.add_argument("--quick", action="store_true", help="small grids, seconds (smoke run)")
    ap.add_argument("--out", default=os.path.join(ROOT, "benchmarks", "results"), metavar="DIR",
                    help="folder of the JSON file (default: benchmarks/results)")
    ap.add_argument("--only", default=None, metavar="S1,S2",
                    help="sections to run, of: " + ", ".join(DEFAULT_SECTIONS) + " (default: all), "
                         "and 'opts' (optimisation experiments of benchmarks/NOTES.md, "
                         "minutes; only when named)")
    ap.add_argument("--planner", choices=tuple(FLAG), default="estimate",
                    help="FFTW planner flag of the floor and of fibril's plans (default estimate, "
                         "fibril's default)")
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                    help="clock of the reported times and ratios: this process's CPU time "
                         "(default; robust on a shared machine) or wall time (both recorded)")
    ap.add_argument("--runs", type=int, default=None, help="repetitions (median reported)")
    ap.add_argument("--pitches", type=int, nargs="+", default=None,
                    help="pitches (elements) of the grid-size sweep (odd)")
    ap.add_argument("--peer-pitches", type=int, nargs="+", default=None)
    ap.add_argument("--tol", type=float, default=1e-8,
                    help="tolerance given to every code in the peer comparison (default 1e-8)")
    ap.add_argument("--accurate", action="store_true",
                    help="also the 'accurate' preset curve (long; capped by --accurate-cap)")
    ap.add_argument("--accurate-cap", type=float, default=1800.0, metavar="S")
    ap.add_argument("--no-pin", action="store_true",
                    help="do not re-run in a child with one thread per library")
    args = ap.parse_args(argv)
    args.argv = list(argv)
    return args


def main(argv=None) -> int:
    """Run the benchmark (in a child pinned to one thread per library unless ``--no-pin``)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parse_args(argv)
    if not args.no_pin and os.environ.get(CHILD_FLAG) != "1":
        env = dict(os.environ, **PIN_ENV)
        env[CHILD_FLAG] = "1"
        return subprocess.call([sys.executable, "-m", "benchmarks.fibril_bench"] + argv, env=env,
                               cwd=ROOT)
    try:
        import numba

        numba.set_num_threads(1)
    except Exception:  # noqa: BLE001 - numba without threading layer
        pass
    log = lambda msg: print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr,  # noqa: E731
                            flush=True)
    res = run(args, log)
    m = res["meta"]
    print(f"fibril bench ({m['mode']}), {m['started_utc']} - {m['finished_utc']}, "
          f"{m['cpus']} CPUs, load average {m['loadavg_start']} -> {m['loadavg_end']}, "
          f"one thread per library, FFTW {m['fftw_planner']}, times are {m['clock']} "
          f"{'(CPU time of the bench process)' if m['clock'] == 'cpu' else 'time'}")
    print(format_table(table_rows(res)))
    print(f"JSON: {m['json']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
