"""``fibril-run``: simulate one scene (from YAML or a built-in) and print, store or plot it."""

from __future__ import annotations

import json
import os
import sys

from .._version import __version__
from ..errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE, ConfigError, DiskFull, StoreError
from .common import Parser, error, interruptible, memory_guard, pipe_safe, setup_logging, versions_text

PROG = "fibril-run"


def _human(result) -> str:
    lines = []
    d = result.discretisation
    s = result.scene
    lines.append(f"fibril-run: {s.n_side}x{s.n_side} pillars, phi={s.phi:g} "
                 f"(discrete {d['phi_discrete']:.4f}), k~={s.k_tilde:g}, sigma~={s.sigma_tilde:g}, "
                 f"seed={s.seed}, adhesion={'yes' if s.adhesion else 'no'}")
    if result.units:
        u = result.units
        lines.append(f"  units: F_c = {u['F_c']:.4g} N, d_c = {u['d_c']:.4g} m, k = k~ x "
                     f"{u['k_unit']:.4g} N/m, L = {u['L']:.4g} m")
    lines.append(f"  grid {d['grid_side']}^2 (FFT {d['fft_size']}^2), "
                 f"{d.get('elements_per_diameter', float('nan')):.2f} elements per pillar diameter "
                 f"({d['elements_per_pillar']} in a pillar's footprint, {d['n_active']} under all "
                 "pillars)")
    for r in result.results:
        if r.status == "ok":
            lines.append(f"  {r.preload_kind}={r.preload:g}: F~_P={r.F_P:.4f} at d~={r.d_tilde_max:.4f}, "
                         f"F~_A={r.F_A:.4f} at d~={r.d_tilde_at_F_A:.4f}, "
                         f"pillars in contact max {r.n_pillars_in_contact_max}")
            if result.units:
                u = result.units
                lines.append(f"    in SI: F_P = {r.F_P * u['F_c']:.4g} N at d = "
                             f"{r.d_tilde_max * u['d_c']:.4g} m, F_A = {r.F_A * u['F_c']:.4g} N "
                             f"at d = {r.d_tilde_at_F_A * u['d_c']:.4g} m")
        else:
            lines.append(f"  {r.preload_kind}={r.preload:g}: FAILED: {r.message}")
    st = result.stats
    lines.append(f"  status {result.status}; {st['wall_s']:.2f} s, {st['cg_iterations']} CG "
                 f"iterations, {st['fft_pairs']} FFT pairs, {st['events']} events")
    if "confirmed_local" in st:         # solver.confirm: local
        lines.append(f"  confirmed locally {st['confirmed_local']}, globally "
                     f"{st['confirmed_global']} relaxations; directions kept locally "
                     f"{st['directions_local']}; force bound {st['force_bound_tilde']:.2g} F~")
    if result.status == "ok" and result.message:
        lines.append(f"  note: {result.message}")
    return "\n".join(lines)


@pipe_safe
@interruptible(PROG, "no file half-written (--out and --plot appear whole or not at all); "
               "rerun the same command to run the scene again")
@memory_guard(PROG)
def main(argv=None) -> int:
    """``fibril-run``: simulate one scene; returns the exit status."""
    p = Parser(prog=PROG, description="Simulate the pull-off of one pillar-array scene.")
    p.add_argument("scene", nargs="?", help="scene YAML file")
    p.add_argument("--builtin", metavar="NAME",
                   help="run a built-in scene instead: default, quick, single-pillar")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--out", metavar="FILE.h5", help="write the full result to HDF5")
    p.add_argument("--plot", metavar="FILE.png", help="draw the curves and contact maps (a PNG file)")
    p.add_argument("--force", action="store_true",
                   help="replace an existing --out/--plot file (never a campaign file, a "
                        "journal or a file a running campaign holds)")
    p.add_argument("--ignore-memory-check", action="store_true",
                   help="run even if the scene's memory estimate exceeds the memory available")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress display on stderr (a bar on a terminal, else a line "
                        "every 10 s)")
    p.add_argument("--version", action="store_true", help="print versions and exit")
    p.add_argument("-v", "--verbose", action="store_true", help="log what happens (INFO)")
    args = p.parse_args(argv)
    if args.version:
        print(f"fibril-hpc {__version__}\n{versions_text()}")
        return EXIT_OK
    setup_logging(args.verbose)
    from ..inputs.config import builtin_scene, load_scene
    from ..inputs.limits import check_memory
    from ..campaign.storage.guard import check_output
    from ..io.files import check_writable

    try:
        if (args.scene is None) == (args.builtin is None):
            raise ConfigError("scene", args.scene, "a scene YAML path or --builtin NAME (one of them)")
        scene = builtin_scene(args.builtin) if args.builtin else load_scene(args.scene)
        for path, field in ((args.out, "--out"), (args.plot, "--plot")):
            if path:
                check_writable(path, field)
                check_output(path, field, args.force)
        if args.plot and not args.plot.lower().endswith(".png"):
            # the figure is a PNG; a name that says otherwise would be a file that lies
            raise ConfigError("--plot", args.plot, "a file name ending in .png")
        if args.out and args.plot and os.path.realpath(args.out) == os.path.realpath(args.plot):
            raise ConfigError("--plot", args.plot, "a file other than --out")
        if not args.ignore_memory_check:
            check_memory(scene)
    except ConfigError as exc:
        return error(PROG, exc, EXIT_USAGE)
    from ..api import simulate
    from ..io.progress import RunProgress

    progress = RunProgress(len(scene.preloads), enabled=not args.no_progress)
    try:
        result = simulate(scene, progress=progress)
    finally:
        progress.close()
    try:
        if args.out:
            from ..io.store import write_result_file

            write_result_file(args.out, result, None if args.force else "--out")
        if args.plot:
            from ..io.plot import plot_result

            plot_result(result, args.plot, None if args.force else "--plot")
    except DiskFull as exc:
        return error(PROG, exc, EXIT_INTERRUPTED)
    except ConfigError as exc:        # --out/--plot created by another command meanwhile
        return error(PROG, exc, EXIT_USAGE)
    except StoreError as exc:
        return error(PROG, exc, EXIT_FAILED)
    if args.json:
        print(json.dumps(result.summary()))
    else:
        print(_human(result))
    return EXIT_OK if result.status == "ok" else EXIT_FAILED


#: the historical name of :func:`main`
run_main = main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
