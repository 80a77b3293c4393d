"""``fibril-accuracy``: what accuracy costs in time.

Measures the error of F~_A and F~_P (or, for force-controlled preloads, of the indentation d~_max
that reaches F~_P) and the wall/CPU time as each accuracy knob varies, one at a time and combined
(the presets), and writes ``accuracy.csv`` (one row per run), ``accuracy.md`` (the tables) and
``pareto.png`` (error against time, with the Pareto front).

Cases (every run single-threaded, ``fft_threads = 1``, so that times are comparable):

``pillar``
    one rigid, flat-ended pillar (``n_side = 1``), displacement preload d~ = 1. Exact: Kendall,
    F~_A = phi_d^(1/4), and the punch stiffness, F~_P = phi_d^(1/2) d~ (phi_d: discrete filling
    ratio of the very run, so the exact values follow the discrete footprint).
``brush6``
    a rough, spring-backed 6 x 6 brush (k~ = 0.01, sigma~ = 0.5, seed 0, displacement preload
    d~ = 18, about F~_P = 4, so that F~_P is an output). No closed form: the reference is the
    case's finest run (tight knobs if such a run exists at that resolution, else the default
    knobs, whose own knob error the study measures separately and finds far below the resolution
    error); its uncertainty is the largest deviation of the runs at >= 2/3 of its resolution.
``brush18``
    the default 18 x 18 scene (k~ = 0.01, sigma~ = 0.5, seed 0, F~_P = 4: force-controlled, so
    the preload-side error is that of d~_max). Reference as for ``brush6`` (finest affordable:
    its uncertainty is large, see the tables).

Every row also carries the "knob error": the difference from the tight-knob run at the same
resolution, which separates the solver-knob error from the discretisation error.

``--quick`` checks the machinery in well under a minute (tiny grids, CI); the full mode is for a
person (the 18 x 18 case takes hours at its finest grids: select cases with ``--cases``). Rows
already in ``accuracy.csv`` of the output folder are reused with ``--resume``, so a long study can
be run case by case. A bad argument is one line on stderr, exit status 2, nothing written.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import time

from .errors import ConfigError

#: Tight knobs of reference runs: solve every pass fully, merge no unloading events. Loading
#: batches stay at the default (load_event_merge 1e-2): the study measures that 0 changes
#: neither F~_A nor F~_P (to 1e-9) while it costs ~10x the events.
TIGHT = {"cg_tol": 1e-11, "relax_tol": 1e-11, "event_merge": 0.0, "load_event_merge": 1e-2,
         "detach_policy": "all"}

#: Knob values varied one at a time (the others at the ``default`` preset's values).
KNOB_VALUES = {
    "cg_tol": [1e-4, 1e-6, 1e-10],
    "relax_tol": [1e-3, 1e-8],
    "event_merge": [0.0, 1e-3, 1e-2, 1e-1],
    "load_event_merge": [0.0, 1e-1],
    "detach_policy": ["worst"],
}

CASES = {
    "pillar": {"scene": dict(n_side=1, k_tilde=math.inf, sigma_tilde=0.0, d_tilde=1.0),
               "exact": True,
               "full": dict(epd=[6, 8, 10, 12, 14, 16, 20, 24, 28, 32], knob_epd=8),
               "quick": dict(epd=[6, 8, 12], knob_epd=6)},
    "brush6": {"scene": dict(n_side=6, k_tilde=0.01, sigma_tilde=0.5, seed=0, d_tilde=18.0),
               "exact": False,
               "full": dict(epd=[6, 8, 10, 12, 14, 16, 20], knob_epd=8, ref_epd=[]),
               "quick": dict(epd=[5, 6], knob_epd=5, ref_epd=[8])},
    "brush18": {"scene": dict(n_side=18, k_tilde=0.01, sigma_tilde=0.5, seed=0, F_P=4.0),
                "exact": False,
                "full": dict(epd=[6, 8, 10], knob_epd=6, ref_epd=[],
                             knobs={"cg_tol": [1e-6], "event_merge": [1e-2]}),
                "quick": None},
}
#: The quick brush is smaller than brush6 (CI): 3 x 3 pillars, same physics.
QUICK_SCENES = {"brush6": dict(n_side=3, k_tilde=0.01, sigma_tilde=0.5, seed=0, d_tilde=1.5)}

FIELDS = ["case", "kind", "knob", "value", "epd_target", "epd", "phi_discrete", "F_A", "F_P",
          "d_max", "F_A_exact", "F_P_exact", "wall_s", "cpu_s", "cg_iterations", "events",
          "status", "code", "when"]


def code_version() -> str:
    """The code that ran: git commit (``+wip`` when fibril_hpc has uncommitted changes), else the
    package version. Timings depend on it; the physics must not."""
    import subprocess

    from . import __version__

    here = os.path.dirname(os.path.abspath(__file__))
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=here, text=True,
                              capture_output=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "."], cwd=here, text=True,
                               capture_output=True, timeout=10).stdout.strip()
        return head + ("+wip" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "fibril_hpc " + __version__


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # noqa: D401
        self.exit(2, f"{self.prog}: error: {message}\n")


def _run(scene_kw: dict, epd: float, knobs: dict) -> dict:
    from . import Scene, simulate
    from .presets import preset_values

    solver = {**preset_values("default")["solver"], **knobs, "fft_threads": 1}
    scene = Scene(**scene_kw, elements_per_diameter=epd, solver=solver)
    c0 = time.process_time()
    r = simulate(scene)
    cpu = time.process_time() - c0
    m = r.main
    phi = r.discretisation["phi_discrete"]
    return {"epd_target": epd, "epd": r.discretisation["elements_per_diameter"],
            "phi_discrete": phi, "F_A": m.F_A, "F_P": m.F_P, "d_max": m.d_tilde_max,
            "wall_s": r.stats["wall_s"], "cpu_s": cpu, "cg_iterations": r.stats["cg_iterations"],
            "events": r.stats["events"], "status": r.status}


def plan(case: str, quick: bool) -> list[tuple]:
    """(kind, knob, value, epd, knobs) of every run of a case, cheapest first."""
    from .presets import PRESETS

    spec = CASES[case]["quick" if quick else "full"]
    runs = []
    for e in spec["epd"]:
        runs.append(("resolution", "elements_per_diameter", e, e, {}))
    for knob, values in spec.get("knobs", KNOB_VALUES).items():
        if quick and knob not in ("cg_tol", "event_merge", "detach_policy"):
            continue
        for v in values[:1] if quick else values:
            runs.append(("knob", knob, v, spec["knob_epd"], {knob: v}))
    runs.append(("tight", "tight", "tight", spec["knob_epd"], dict(TIGHT)))
    for name, p in PRESETS.items():
        e = p["elements_per_diameter"]
        if quick:
            e = min(e, max(spec["epd"]))
        if case == "brush18" and e > max(spec["epd"]):
            continue        # hours at 16 elements per diameter: not measured
        runs.append(("preset", "preset", name, e, dict(p["solver"])))
    for e in spec.get("ref_epd", []):
        runs.append(("reference", "tight", "tight", e, dict(TIGHT)))
        if e != spec["knob_epd"]:
            runs.append(("tight", "tight", "tight", e, dict(TIGHT)))
    seen, out = set(), []
    for r in runs:
        key = (r[0], r[1], str(r[2]), float(r[3]))
        ref_key = ("reference", "tight", "tight", float(r[3]))
        if key not in seen and not (r[0] == "tight" and ref_key in seen):
            seen.add(key)
            out.append(r)
    # cheapest first (cost ~ epd^3, tight knobs ~2x, one-at-a-time detachment ~3x), so that an
    # interrupted study has its cheap rows
    cost = {"tight": 2.0, "detach_policy": 3.0}
    return sorted(out, key=lambda r: float(r[3]) ** 3 * cost.get(r[1], 1.0))


def _key(row) -> tuple:
    return (row["case"], row["kind"], row["knob"], str(row["value"]), float(row["epd_target"]))


def read_rows(path: str) -> list[dict]:
    if not os.path.exists(path):
        return []
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        for k in FIELDS:
            if k in ("case", "kind", "knob", "value", "status", "code", "when"):
                continue
            r[k] = float(r[k]) if r.get(k) not in (None, "") else math.nan
    return rows


def write_csv(path: str, rows: list[dict]) -> None:
    tmp = path + ".part"
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.10g}" if isinstance(r[k], float) else r.get(k, ""))
                        for k in FIELDS})
    os.replace(tmp, path)


def _effective(epd, knobs) -> tuple:
    """Identity of a run: resolution and every accuracy knob it resolves to."""
    from .presets import preset_values

    eff = {**preset_values("default")["solver"], **knobs}
    return (float(epd),) + tuple(sorted((k, str(v)) for k, v in eff.items()))


def _knobs_of(row) -> dict:
    from .presets import PRESETS

    if row["kind"] == "preset":
        return dict(PRESETS[row["value"]]["solver"])
    if row["knob"] == "tight":
        return dict(TIGHT)
    if row["kind"] == "knob":
        v = row["value"]
        return {row["knob"]: v if row["knob"] == "detach_policy" else float(v)}
    return {}


CODE = [""]


def run_case(case: str, quick: bool, rows: list[dict], csv_path: str, log=print) -> None:
    """Run every planned run of ``case`` not yet in ``rows``; a run whose resolution and knobs
    equal an earlier one's (e.g. the ``default`` preset and the default-knob resolution row) is
    not repeated: its row reuses that run's numbers and times."""
    scene_kw = dict(QUICK_SCENES.get(case, CASES[case]["scene"]) if quick else CASES[case]["scene"])
    have = {_key(r) for r in rows}
    done = {_effective(r["epd_target"], _knobs_of(r)): r for r in rows if r["case"] == case}
    for kind, knob, value, epd, knobs in plan(case, quick):
        key = (case, kind, knob, str(value), float(epd))
        if key in have:
            continue
        if kind == "tight" and (case, "reference", "tight", "tight", float(epd)) in have:
            continue
        same = done.get(_effective(epd, knobs))
        res = ({k: same[k] for k in ("epd_target", "epd", "phi_discrete", "F_A", "F_P", "d_max",
                                     "wall_s", "cpu_s", "cg_iterations", "events", "status")}
               if same is not None else _run(scene_kw, epd, knobs))
        row = {"case": case, "kind": kind, "knob": knob, "value": str(value), **res,
               "F_A_exact": math.nan, "F_P_exact": math.nan,
               "code": same.get("code", "") if same is not None else CODE[0],
               "when": (same.get("when", "") if same is not None
                        else time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()))}
        if CASES[case]["exact"]:
            row["F_A_exact"] = res["phi_discrete"] ** 0.25
            row["F_P_exact"] = math.sqrt(res["phi_discrete"]) * scene_kw["d_tilde"]
        rows.append(row)
        have.add(key)
        done.setdefault(_effective(epd, knobs), row)
        write_csv(csv_path, rows)
        log(f"{case:8s} {kind:10s} {knob:22s} {str(value):8s} epd {res['epd']:6.2f}  "
            f"F_A {res['F_A']:.6f}  F_P {res['F_P']:.6f}  d_max {res['d_max']:.6f}  "
            f"{res['wall_s']:8.2f} s  {res['status']}")


# -- analysis -------------------------------------------------------------------------------
def reference(rows: list[dict], case: str) -> dict | None:
    """The reference of a non-exact case: its finest run with tight or default knobs (tight
    preferred at equal resolution; the knob error of default knobs is measured separately and is
    far below the resolution error); uncertainty = largest deviation of the other such runs at
    >= 2/3 of its resolution."""
    tight = [r for r in rows if r["case"] == case and r["status"] == "ok"
             and (r["knob"] == "tight" or r["kind"] == "resolution")]
    if not tight:
        return None
    ref = max(tight, key=lambda r: (round(r["epd"], 6), r["knob"] == "tight"))
    near = [r for r in tight if r["epd"] < ref["epd"] - 1e-9 and r["epd"] >= 2 / 3 * ref["epd"]]
    unc = {}
    for q in ("F_A", "F_P", "d_max"):
        dev = [abs(r[q] / ref[q] - 1) for r in near if ref[q] != 0]
        unc[q] = max(dev) if dev else math.nan
    return {"row": ref, "unc": unc, "near": sorted({round(r["epd"], 2) for r in near})}


def add_errors(rows: list[dict]) -> dict:
    """Relative errors (signed) against the exact value or the case's reference, and the knob
    error against the tight run at the same resolution. Returns the references."""
    refs = {}
    for case in sorted({r["case"] for r in rows}):
        exact = CASES.get(case, {}).get("exact", False)
        ref = None if exact else reference(rows, case)
        refs[case] = ref
        tight = {round(r["epd"], 6): r for r in rows
                 if r["case"] == case and r["knob"] == "tight" and r["status"] == "ok"}
        for r in rows:
            if r["case"] != case:
                continue
            for q in ("F_A", "F_P", "d_max"):
                r["err_" + q] = math.nan
                r["kerr_" + q] = math.nan
            if r["status"] != "ok":
                continue
            if exact:
                r["err_F_A"] = r["F_A"] / r["F_A_exact"] - 1
                r["err_F_P"] = r["F_P"] / r["F_P_exact"] - 1
            elif ref is not None and r is not ref["row"]:
                for q in ("F_A", "F_P", "d_max"):
                    if ref["row"][q] != 0:
                        r["err_" + q] = r[q] / ref["row"][q] - 1
            t = tight.get(round(r["epd"], 6))
            if t is not None and t is not r:
                for q in ("F_A", "F_P", "d_max"):
                    if t[q] != 0:
                        r["kerr_" + q] = r[q] / t[q] - 1
    return refs


def _preload_err(r) -> float:
    """The preload-side error: F~_P for displacement preloads, d~_max for force preloads."""
    displacement = "d_tilde" in CASES.get(r["case"], {}).get("scene", {})
    return r["err_F_P"] if displacement else r["err_d_max"]


def _pct(x) -> str:
    return "" if not math.isfinite(x) else f"{100 * x:+.2f} %"


def _unc(x) -> str:
    return "unknown" if not math.isfinite(x) else f"±{100 * x:.2f} %"


def markdown(rows: list[dict], refs: dict, quick: bool, versions: dict) -> str:
    out = ["# fibril-accuracy: error against time", ""]
    out.append(f"Mode: {'quick (machinery check, tiny grids)' if quick else 'full'}; every run "
               "single-threaded (fft_threads = 1); times are wall seconds of `simulate` "
               "(model build included) and CPU seconds of the process, one run each, on a shared "
               "machine (treat them as +-20 %). "
               + "Versions: " + ", ".join(f"{k} {versions.get(k, '')}" for k in
                                          ("fibril_hpc", "numpy", "numba", "pyfftw", "fftw")))
    codes = {}
    for r in rows:
        codes.setdefault(r.get("code") or "unrecorded", []).append(r.get("when") or "")
    out.append("")
    out.append("Code that ran (timings depend on it, results must not): " + "; ".join(
        f"`{c}` {len(w)} rows" + (f" ({', '.join(sorted({x for x in w if x}))})" if any(w) else "")
        for c, w in codes.items()) + ".")
    out.append("")
    out.append("Errors are relative and signed. `pillar`: against Kendall (F~_A = phi_d^(1/4)) and "
               "the punch stiffness (F~_P = phi_d^(1/2) d~). Brushes: against the reference below. "
               "`knob err`: against the tight-knob run at the same resolution (solver-knob error "
               "alone). Force-controlled cases (F~_P given) report the error of d~_max instead of "
               "F~_P.")
    out.append("")
    for case, ref in refs.items():
        if ref is None:
            continue
        rr = ref["row"]
        near = ", ".join(f"{e:.1f}" for e in ref["near"]) or "none"
        knobs = ("tight knobs (cg_tol {:g}, relax_tol = cg_tol, no unloading event merging)"
                 .format(TIGHT["cg_tol"]) if rr["knob"] == "tight" else "default knobs")
        out.append(f"* `{case}` reference: its finest run, {rr['epd']:.2f} elements per "
                   f"diameter, {knobs}: "
                   f"F~_A = {rr['F_A']:.5f}, F~_P = {rr['F_P']:.5f}, d~_max = {rr['d_max']:.5f}; "
                   f"uncertainty (largest deviation of the "
                   f"runs at {near} elements per diameter): F~_A {_unc(ref['unc']['F_A'])}, "
                   f"F~_P {_unc(ref['unc']['F_P'])}, d~_max {_unc(ref['unc']['d_max'])}.")
    out.append("")
    out.extend(preset_summary(rows))
    out.append("")
    out.append("All runs:")
    out.append("")
    out.append("| case | kind | knob | value | elements/diam. | F~_A | err F~_A | knob err F~_A | "
               "err F~_P (d~_max) | wall s | CPU s | CG it. | events |")
    out.append("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    order = {"resolution": 0, "knob": 1, "preset": 2, "tight": 3, "reference": 4}
    for r in sorted(rows, key=lambda r: (r["case"], order.get(r["kind"], 9), r["knob"], r["epd"])):
        if r["status"] != "ok":
            out.append(f"| {r['case']} | {r['kind']} | {r['knob']} | {r['value']} | "
                       f"{r['epd']:.2f} | failed | | | | {r['wall_s']:.2f} | | | |")
            continue
        out.append(f"| {r['case']} | {r['kind']} | {r['knob']} | {r['value']} | {r['epd']:.2f} | "
                   f"{r['F_A']:.5f} | {_pct(r['err_F_A'])} | {_pct(r['kerr_F_A'])} | "
                   f"{_pct(_preload_err(r))} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | "
                   f"{int(r['cg_iterations'])} | {int(r['events'])} |")
    out.append("")
    return "\n".join(out)


def preset_summary(rows: list[dict]) -> list[str]:
    """Markdown lines: each preset's measured error and time per case."""
    from .presets import PRESETS

    cases = sorted({r["case"] for r in rows})
    out = ["Presets (error of F~_A, of F~_P or d~_max, CPU seconds per scene):", "",
           "| preset | elements/diam. | " + " | ".join(cases) + " |",
           "| --- | --- | " + " | ".join("---" for _ in cases) + " |"]
    for name, p in PRESETS.items():
        cells = []
        for c in cases:
            r = next((r for r in rows if r["case"] == c and r["kind"] == "preset"
                      and r["value"] == name and r["status"] == "ok"), None)
            cells.append("not measured" if r is None else
                         f"{_pct(r['err_F_A'])}, {_pct(_preload_err(r))}, {r['cpu_s']:.3g} s")
        out.append(f"| {name} | {p['elements_per_diameter']} | " + " | ".join(cells) + " |")
    return out


def pareto(points: list[tuple]) -> list[tuple]:
    """Points (time, error, ...) not dominated by a faster-and-more-accurate one, by time."""
    front, best = [], math.inf
    for p in sorted(points, key=lambda p: (p[0], p[1], id(p))):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def plot(rows: list[dict], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = sorted({r["case"] for r in rows})
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.4), squeeze=False,
                             constrained_layout=True)
    marks = {"resolution": "o", "knob": "s", "preset": "*", "tight": "^", "reference": "^"}
    for ax, case in zip(axes[0], cases):
        pts = []
        for r in rows:
            if r["case"] != case or r["status"] != "ok" or not math.isfinite(r["err_F_A"]):
                continue
            err = max(abs(r["err_F_A"]), 1e-6)
            pts.append((r["cpu_s"], err, r))
            ax.loglog(r["cpu_s"], err, marks.get(r["kind"], "x"),
                      ms=13 if r["kind"] == "preset" else 6,
                      color={"resolution": "C0", "knob": "C1", "preset": "C3"}.get(r["kind"], "C2"),
                      alpha=0.8)
            if r["kind"] in ("preset", "resolution"):
                ax.annotate(r["value"] if r["kind"] == "preset" else f"{r['epd']:.1f}",
                            (r["cpu_s"], err), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
        front = pareto(pts)
        if front:
            ax.loglog([p[0] for p in front], [p[1] for p in front], "k-", lw=0.8,
                      label="Pareto front")
        ax.set_title(case)
        ax.set_xlabel("CPU time per scene [s] (1 thread)")
        ax.set_ylabel("|relative error of F~_A|")
        ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], ls="", marker=m, color=c, label=l) for l, m, c in
               (("elements per diameter", "o", "C0"), ("one knob changed", "s", "C1"),
                ("preset", "*", "C3"), ("tight knobs", "^", "C2"))]
    handles.append(plt.Line2D([], [], color="k", lw=0.8, label="Pareto front"))
    axes[0][-1].legend(handles=handles, fontsize=7, loc="best")
    tmp = path + ".part.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv=None) -> int:
    p = _Parser(prog="fibril-accuracy", description=__doc__.splitlines()[0])
    p.add_argument("--out", default="accuracy-study", metavar="DIR",
                   help="output folder (accuracy.csv, accuracy.md, pareto.png)")
    p.add_argument("--quick", action="store_true", help="machinery check on tiny grids (CI)")
    p.add_argument("--cases", default=None,
                   help="comma-separated subset of " + ", ".join(CASES) +
                        " (default: pillar,brush6 in quick mode, all otherwise)")
    p.add_argument("--resume", action="store_true",
                   help="reuse the rows already in DIR/accuracy.csv (run cases one at a time)")
    p.add_argument("--report-only", action="store_true",
                   help="rewrite the table and plot from DIR/accuracy.csv without running")
    args = p.parse_args(argv)
    try:
        cases = (args.cases.split(",") if args.cases else
                 (["pillar", "brush6"] if args.quick else list(CASES)))
        for c in cases:
            if c not in CASES:
                raise ConfigError("--cases", c, "a comma-separated subset of " + ", ".join(CASES))
            if args.quick and CASES[c]["quick"] is None:
                raise ConfigError("--cases", c, "in --quick mode: pillar, brush6")
        parent = os.path.dirname(os.path.abspath(args.out))
        if not os.path.isdir(parent) or (os.path.exists(args.out) and not os.path.isdir(args.out)):
            raise ConfigError("--out", args.out, "a folder (created if its parent exists)")
        csv_path = os.path.join(args.out, "accuracy.csv")
        if args.report_only and not os.path.exists(csv_path):
            raise ConfigError("--report-only", csv_path, "an existing accuracy.csv in --out")
    except ConfigError as exc:
        print(f"fibril-accuracy: error: {exc}", file=sys.stderr)
        return 2
    from .results import software_versions

    os.makedirs(args.out, exist_ok=True)
    rows = read_rows(csv_path) if (args.resume or args.report_only) else []
    if not args.report_only:
        CODE[0] = code_version()
        _run(dict(n_side=2, k_tilde=0.01, sigma_tilde=0.5, d_tilde=1.0), 4, {})   # warm-up:
        # numba's cached kernels and FFTW load here, not inside the first timed run
        for c in cases:
            run_case(c, args.quick, rows, csv_path)
    refs = add_errors(rows)
    with open(os.path.join(args.out, "accuracy.md"), "w", encoding="utf-8") as fh:
        fh.write(markdown(rows, refs, args.quick, software_versions()))
    plot(rows, os.path.join(args.out, "pareto.png"))
    print(f"fibril-accuracy: {len(rows)} runs; wrote {args.out}/accuracy.csv, accuracy.md, "
          "pareto.png")
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
