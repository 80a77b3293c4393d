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
    """``pareto.png``: |error of F~_A| against CPU time per case, with the Pareto front."""
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
    try:
        save_figure(fig, path, "writing the accuracy plot")   # atomic; a full disk is one line
    finally:
        plt.close(fig)
