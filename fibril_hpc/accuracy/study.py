"""Cases, runs, references and errors of the accuracy study (see :mod:`fibril_hpc.accuracy`)."""

from __future__ import annotations

import csv
import io
import math
import os
import time

from ..api import simulate
from ..elastic.analytic import single_pillar_F_A
from ..inputs.presets import PRESETS, preset_values
from ..inputs.scene import Scene
from ..io.files import write_text_atomically

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

#: The opt-in local confirmation (``solver.confirm: local``, docs/model.md §6): each preset is
#: also run with it (kind ``local``, value the preset's name), a point of its own beside the
#: preset's. It keeps a state without its global solve where a certified bound puts its force
#: within ``confirm_tol`` of the exact one, so it moves time, not (to that bound) the error.
LOCAL = {"confirm": "local"}
#: The opt-in far field by pillar moments (``solver.far_field: multipole``, docs/model.md §6):
#: each preset is also run with it (kind ``multipole``). Not certified: its error is what the
#: study measures, beside its time.
MULTIPOLE = {"far_field": "multipole"}
#: the solver options each kind of preset row adds to its preset's
PRESET_KINDS = {"preset": {}, "local": LOCAL, "multipole": MULTIPOLE}

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
          "d_max", "F_A_exact", "F_P_exact", "wall_s", "cpu_s", "cg_iterations", "fft_pairs",
          "events", "confirmed_local", "status", "code", "when"]
#: what a run measures (a row that repeats an earlier run's knobs copies these)
MEASURED = ("epd_target", "epd", "phi_discrete", "F_A", "F_P", "d_max", "wall_s", "cpu_s",
            "cg_iterations", "fft_pairs", "events", "confirmed_local", "status")


def run_one(scene_kw: dict, epd: float, knobs: dict) -> dict:
    """One timed ``simulate`` of the case scene at ``epd`` with ``knobs`` over the defaults."""
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
            "fft_pairs": r.stats["fft_pairs"], "events": r.stats["events"],
            # relaxations kept without a global solve (confirm: local only)
            "confirmed_local": r.stats.get("confirmed_local", 0), "status": r.status}


def plan(case: str, quick: bool) -> list[tuple]:
    """(kind, knob, value, epd, knobs) of every run of a case, cheapest first."""
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
        runs.append(("local", "confirm: local", name, e, {**p["solver"], **LOCAL}))
        runs.append(("multipole", "far_field: multipole", name, e,
                     {**p["solver"], **MULTIPOLE}))
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
    """The rows of an ``accuracy.csv`` (numbers as floats; [] when there is none)."""
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
    """Write the rows to ``path`` atomically (a full disk is one line: DiskFull)."""
    buf = io.StringIO(newline="")
    w = csv.DictWriter(buf, fieldnames=FIELDS, extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: (f"{r[k]:.10g}" if isinstance(r[k], float) else r.get(k, ""))
                    for k in FIELDS})
    write_text_atomically(path, buf.getvalue(), "writing the accuracy table")


def _effective(epd, knobs) -> tuple:
    """Identity of a run: resolution and every accuracy knob it resolves to."""
    eff = {**preset_values("default")["solver"], **knobs}
    return (float(epd),) + tuple(sorted((k, str(v)) for k, v in eff.items()))


def _knobs_of(row) -> dict:
    if row["kind"] in PRESET_KINDS:
        return {**PRESETS[row["value"]]["solver"], **PRESET_KINDS[row["kind"]]}
    if row["knob"] == "tight":
        return dict(TIGHT)
    if row["kind"] == "knob":
        v = row["value"]
        return {row["knob"]: v if row["knob"] == "detach_policy" else float(v)}
    return {}


def run_case(case: str, quick: bool, rows: list[dict], csv_path: str, code: str = "",
             log=print) -> None:
    """Run every planned run of ``case`` not yet in ``rows``; a run whose resolution and knobs
    equal an earlier one's (e.g. the ``default`` preset and the default-knob resolution row) is
    not repeated: its row reuses that run's numbers and times. ``code`` labels the code that
    ran (recorded per row: timings depend on it)."""
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
        res = ({k: same[k] for k in MEASURED} if same is not None
               else run_one(scene_kw, epd, knobs))
        row = {"case": case, "kind": kind, "knob": knob, "value": str(value), **res,
               "F_A_exact": math.nan, "F_P_exact": math.nan,
               "code": same.get("code", "") if same is not None else code,
               "when": (same.get("when", "") if same is not None
                        else time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime()))}
        if CASES[case]["exact"]:
            row["F_A_exact"] = single_pillar_F_A(res["phi_discrete"])
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
