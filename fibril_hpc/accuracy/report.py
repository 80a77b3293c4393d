"""Tables and the plot of the accuracy study (``accuracy.md``, ``pareto.png``)."""

from __future__ import annotations

import math

from ..inputs.presets import PRESETS
from ..io.files import save_figure
from .study import CASES, TIGHT


def _preload_err(r) -> float:
    """The preload-side error: F~_P for displacement preloads, d~_max for force preloads."""
    displacement = "d_tilde" in CASES.get(r["case"], {}).get("scene", {})
    return r["err_F_P"] if displacement else r["err_d_max"]


def _pct(x) -> str:
    return "" if not math.isfinite(x) else f"{100 * x:+.2f} %"


def _num(x, fmt: str = "{:d}") -> str:
    """A count or number, blank where the row has none (rows of an older ``accuracy.csv``)."""
    return "" if not math.isfinite(x) else fmt.format(int(x) if fmt == "{:d}" else x)


def _ratio(a, b) -> str:
    """a / b to two decimals, blank without a positive b (a run with no FFT pair)."""
    return f"{a / b:.2f}" if math.isfinite(a) and math.isfinite(b) and b > 0 else ""


#: what a preset row of each kind adds to the preset's name (``default + confirm: local``)
SUFFIX = {"local": " + confirm: local", "multipole": " + far_field: multipole"}


def label(r) -> str:
    """How a row is named in the tables and the plot: a preset, or a preset with local
    confirmation or the far field by moments (``default + confirm: local``)."""
    return str(r["value"]) + SUFFIX.get(r["kind"], "")


def _unc(x) -> str:
    return "unknown" if not math.isfinite(x) else f"±{100 * x:.2f} %"


def markdown(rows: list[dict], refs: dict, quick: bool, versions: dict) -> str:
    """The ``accuracy.md`` text: references, preset summary, every run."""
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
    out.extend(local_summary(rows))
    out.append("")
    out.append("All runs:")
    out.append("")
    out.append("| case | kind | knob | value | elements/diam. | F~_A | err F~_A | knob err F~_A | "
               "err F~_P (d~_max) | wall s | CPU s | CG it. | FFT pairs | events | "
               "kept locally |")
    out.append("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | "
               "--- | --- |")
    order = {"resolution": 0, "knob": 1, "preset": 2, "local": 3, "multipole": 4, "tight": 5,
             "reference": 6}
    for r in sorted(rows, key=lambda r: (r["case"], order.get(r["kind"], 9), r["knob"], r["epd"])):
        if r["status"] != "ok":
            out.append(f"| {r['case']} | {r['kind']} | {r['knob']} | {r['value']} | "
                       f"{r['epd']:.2f} | failed | | | | {r['wall_s']:.2f} | | | | | |")
            continue
        out.append(f"| {r['case']} | {r['kind']} | {r['knob']} | {r['value']} | {r['epd']:.2f} | "
                   f"{r['F_A']:.5f} | {_pct(r['err_F_A'])} | {_pct(r['kerr_F_A'])} | "
                   f"{_pct(_preload_err(r))} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | "
                   f"{int(r['cg_iterations'])} | {_num(r['fft_pairs'])} | {int(r['events'])} | "
                   f"{_num(r['confirmed_local'])} |")
    out.append("")
    return "\n".join(out)


def _row(rows, case, kind, name):
    return next((r for r in rows if r["case"] == case and r["kind"] == kind
                 and r["value"] == name and r["status"] == "ok"), None)


def preset_summary(rows: list[dict]) -> list[str]:
    """Markdown lines: each preset's measured error and time per case, and each preset with
    ``confirm: local`` and with ``far_field: multipole`` (its own points, below the preset)."""
    cases = sorted({r["case"] for r in rows})
    out = ["Presets, and presets with `solver.confirm: local` or `solver.far_field: multipole` "
           "(error of F~_A, of F~_P or d~_max, CPU seconds per scene, FFT pairs):", "",
           "| preset | elements/diam. | " + " | ".join(cases) + " |",
           "| --- | --- | " + " | ".join("---" for _ in cases) + " |"]
    for name, p in PRESETS.items():
        for kind in ("preset", "local", "multipole"):
            cells = []
            for c in cases:
                r = _row(rows, c, kind, name)
                cells.append("not measured" if r is None else
                             f"{_pct(r['err_F_A'])}, {_pct(_preload_err(r))}, "
                             f"{r['cpu_s']:.3g} s" + (f", {_num(r['fft_pairs'])}" if
                                                     math.isfinite(r["fft_pairs"]) else ""))
            if kind != "preset" and all(x == "not measured" for x in cells):
                continue                    # an older study, run before these points
            out.append(f"| {label({'kind': kind, 'value': name})} | "
                       f"{p['elements_per_diameter']} | " + " | ".join(cells) + " |")
    return out


def local_summary(rows: list[dict]) -> list[str]:
    """Markdown lines: each preset with ``confirm: local`` and with ``far_field: multipole``
    against the same preset's run (the reference path): the change of F~_A and of the preload
    side, and the ratios of CPU time and FFT pairs. Empty when no such pair of runs is in
    ``rows``."""
    out = []
    for case in sorted({r["case"] for r in rows}):
        for name in PRESETS:
            for kind in ("local", "multipole"):
                g, new = _row(rows, case, "preset", name), _row(rows, case, kind, name)
                if g is None or new is None:
                    continue
                pre = "F_P" if "d_tilde" in CASES.get(case, {}).get("scene", {}) else "d_max"
                d = [new[q] / g[q] - 1 if g[q] else math.nan for q in ("F_A", pre)]
                out.append(f"| {case} | {label({'kind': kind, 'value': name})} | {d[0]:+.1e} | "
                           f"{d[1]:+.1e} | {_ratio(new['cpu_s'], g['cpu_s'])} | "
                           f"{_ratio(new['fft_pairs'], g['fft_pairs'])} | "
                           f"{_num(new['confirmed_local']) if kind == 'local' else ''} |")
    if not out:
        return []
    return ["`confirm: local` and `far_field: multipole` against the same preset's run (the "
            "reference path): relative change of F~_A and of F~_P (d~_max), ratios of CPU time "
            "and FFT pairs (< 1: a saving), and the relaxations kept without a global solve:", "",
            "| case | preset | change of F~_A | change of F~_P (d~_max) | CPU ratio | "
            "FFT-pair ratio | relaxations kept locally |",
            "| --- | --- | --- | --- | --- | --- | --- |", *out]


def pareto(points: list[tuple]) -> list[tuple]:
    """Points (time, error, ...) not dominated by a faster-and-more-accurate one, by time."""
    front, best = [], math.inf
    for p in sorted(points, key=lambda p: (p[0], p[1], id(p))):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def plot(rows: list[dict], path: str) -> None:
    """``pareto.png``: |error of F~_A| against CPU time per case, with the Pareto front."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import ticker

    cases = sorted({r["case"] for r in rows})
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.4), squeeze=False,
                             constrained_layout=True)
    marks = {"resolution": "o", "knob": "s", "preset": "*", "local": "P", "multipole": "X",
             "tight": "^", "reference": "^"}
    colours = {"resolution": "C0", "knob": "C1", "preset": "C3", "local": "C4",
               "multipole": "C5"}
    tags = {"local": "+local", "multipole": "+multipole"}
    for ax, case in zip(axes[0], cases):
        pts = []
        for r in rows:
            if r["case"] != case or r["status"] != "ok" or not math.isfinite(r["err_F_A"]):
                continue
            err = max(abs(r["err_F_A"]), 1e-6)
            pts.append((r["cpu_s"], err, r))
            ax.loglog(r["cpu_s"], err, marks.get(r["kind"], "x"),
                      ms={"preset": 13, "local": 10, "multipole": 10}.get(r["kind"], 6),
                      color=colours.get(r["kind"], "C2"), alpha=0.8)
            if r["kind"] in ("preset", "local", "multipole", "resolution"):
                # a local or multipole point sits near its preset's error: its label goes
                # below or above; a resolution's to the left (the preset takes the right)
                ax.annotate(f"{r['value']}{tags[r['kind']]}" if r["kind"] in tags else
                            r["value"] if r["kind"] == "preset" else f"{r['epd']:.1f}",
                            (r["cpu_s"], err), fontsize=7,
                            xytext={"local": (3, -10), "multipole": (3, 10),
                                    "preset": (3, 3)}.get(r["kind"], (-3, 3)),
                            ha="right" if r["kind"] == "resolution" else "left",
                            textcoords="offset points", color=colours.get(r["kind"], "k")
                            if r["kind"] in tags else "k")
        front = pareto(pts)
        if front:
            ax.loglog([p[0] for p in front], [p[1] for p in front], "k-", lw=0.8,
                      label="Pareto front")
        ax.set_title(case)
        ax.set_xlabel("CPU time per scene [s] (1 thread)")
        ax.set_ylabel("|relative error of F~_A|")
        ax.grid(True, which="both", alpha=0.3)
        for axis in (ax.xaxis, ax.yaxis):
            # plain labels at 1, 2 and 5 of each decade; the minor ticks unlabelled (on axes
            # spanning about a decade matplotlib labels every minor tick, one over the next)
            axis.set_major_locator(ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(ticker.NullFormatter())
    handles = [plt.Line2D([], [], ls="", marker=m, color=c, label=l) for l, m, c in
               (("elements per diameter", "o", "C0"), ("one knob changed", "s", "C1"),
                ("preset", "*", "C3"), ("preset + confirm: local", "P", "C4"),
                ("preset + far_field: multipole", "X", "C5"),
                ("tight knobs", "^", "C2"))]
    handles.append(plt.Line2D([], [], color="k", lw=0.8, label="Pareto front"))
    axes[0][-1].legend(handles=handles, fontsize=7, loc="best")
    try:
        save_figure(fig, path, "writing the accuracy plot")   # atomic; a full disk is one line
    finally:
        plt.close(fig)
