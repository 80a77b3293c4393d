"""The benchmark's one table: rows from the JSON result, and their text layout."""

from __future__ import annotations


def _fmt(x, spec=".3g"):
    if x is None:
        return "-"
    if isinstance(x, float):
        return format(x, spec)
    return str(x)


def table_rows(res: dict) -> list:
    """(section, case, quantity, value) rows of a benchmark result."""
    rows = []
    add = lambda *a: rows.append(tuple(str(x) for x in a))  # noqa: E731
    pl = res["meta"]["fftw_planner"]
    for r in res.get("fft", []):
        add("fft", f"N={r['N']} m={r['m']} R={r['R']}", f"floor pair ({pl}, 1 thread)",
            f"{r['floor_ms']:.2f} ms")
        add("fft", f"N={r['N']} m={r['m']}", "row-pruned pair / floor",
            f"{r['pruned_pair_ms']:.2f} ms = {r['pruned_over_floor']:.2f}x")
    for r in res.get("cg", []):
        add("cg", f"N={r['N']} m={r['m']}", "CG iteration / floor pair",
            f"{r['cg_iteration_ms']:.2f} ms = {r['cg_iteration_over_floor']:.2f}x")
        add("cg", f"N={r['N']} m={r['m']}", "solve_at: time, CG its, FFT pairs, all-in per it",
            f"{r['solve_at_s_median_warm']:.3f} s, {r['solve_at_cg_iterations']}, "
            f"{r['solve_at_fft_pairs']}, {r['solve_at_per_iteration_over_floor']:.2f}x floor")
        add("scaling", f"N={r['N']} m={r['m']}", "t_it / t_it(smallest) vs m^2 log m law",
            f"{r['measured_iteration_ratio']:.2f} vs {r['law_m2logm_ratio']:.2f} "
            f"(floor {r['measured_floor_ratio']:.2f})")
    cg = res.get("cg", [])
    if len(cg) >= 2 and "fitted_exponent_cg_iteration_ms" in cg[0]:
        add("scaling", f"m={cg[0]['m']}..{cg[-1]['m']}", "fitted exponent of m: CG it, floor, law",
            f"{cg[0]['fitted_exponent_cg_iteration_ms']:.2f}, "
            f"{cg[0]['fitted_exponent_floor_ms']:.2f}, {cg[0]['fitted_exponent_m2logm']:.2f}")
    for r in res.get("curves", []):
        add("curve", f"{r['preset']} {r['n_side']}x{r['n_side']} N={r['N']} m={r['m']}",
            "time, CG solves, CG its, FFT pairs, events, F_A",
            f"{r['time_s']:.1f} s{'' if r['status'] == 'ok' else ' (' + r['status'] + ')'}, "
            f"{r['cg_solves']}, {r['cg_iterations']}, {r['fft_pairs']}, {r['events']}, "
            f"{_fmt(r['F_A'], '.4f')}")
        ev = max(1, r["events"])
        add("curve", f"{r['preset']}", "per event: CG solves, CG its, FFT pairs",
            f"{r['cg_solves'] / ev:.1f}, {r['cg_iterations'] / ev:.1f}, {r['fft_pairs'] / ev:.1f}")
        add("curve", f"{r['preset']}", "time per FFT pair / floor",
            f"{r['wall_over_pairs_floor']:.2f}x")
    for r in res.get("memory", []):
        if "error" in r:
            add("memory", f"pitch {r['pitch']}", "failed", r["error"])
            continue
        a = r["arrays"]
        add("memory", f"N={r['N']} m={r['m']}", "peak RSS growth (build+solve) / arrays held",
            f"{r['peak_growth_MB']:.1f} MB / {r['arrays_MB']:.1f} MB = "
            f"{r['growth_over_arrays']:.2f}x")
        add("memory", f"N={r['N']} m={r['m']}", "peak RSS growth of the solve alone / arrays",
            f"{r['solve_peak_growth_MB']:.1f} MB = {r['solve_peak_over_arrays']:.2f}x "
            f"(build peak {r['build_peak_growth_MB']:.1f} MB)")
        add("memory", f"N={r['N']} m={r['m']}", "arrays counted",
            f"{a['fft_buffers']['count']} FFT buffers, 1 kernel transform, "
            f"{a['active_length_float_vectors']['count']} active-length vectors, "
            f"{a['preconditioner_blocks']['count']} block arrays")
    camp = res.get("campaign")
    if camp:
        for r in camp["modes"]:
            extra = f" ({r['speedup_vs_n2']:.2f}x -n 2)" if "speedup_vs_n2" in r else ""
            add("campaign", f"{r['mode']} ({r['workers']} worker{'s' if r['workers'] > 1 else ''})",
                f"jobs/hour ({r['jobs']} jobs); cores used; jobs/CPU-hour",
                f"{r['jobs_per_hour_median']:.0f}{extra}; {r['cores_used_median']:.2f}; "
                f"{r['jobs_per_cpu_hour_median']:.0f}")
    peers = res.get("peers")
    if peers:
        for name in ("contactmechanics", "tamaas"):
            if not peers["available"].get(name):
                add("peers", name, "not installed", "skipped")
        for s in peers["sizes"]:
            for name, c in s["codes"].items():
                ratio = ""
                if "ratio_wall_vs_fibril_median" in c:
                    ratio = f" = {c['ratio_wall_vs_fibril_median']:.1f}x fibril"
                add("peers", f"{name} N={s['N']} m={s['m']}",
                    "solve time, CG its, FFT pairs, per it in floor pairs",
                    f"{c['time_s_median']:.3f} s{ratio}, {c['iterations']}, "
                    f"{c.get('fft_pairs', '-')}, {_fmt(c['per_iteration_floor_pairs'], '.1f')}")
                if name != "fibril":
                    add("peers", f"{name} N={s['N']}", "agreement: force, contact set, p (L2)",
                        f"{c['force_rel_diff']:.1e}, {c['contact_set_mismatch']} elements, "
                        f"{c['pressure_rel_l2_diff']:.1e}")
    o = res.get("opts")
    if o:
        p = o["preconditioner"]
        add("opts", f"preconditioner ({p['scene']})", "diagonal -> block: CG its, pairs, time",
            f"{p['diagonal']['cg_iterations']} -> {p['block']['cg_iterations']}, "
            f"{p['diagonal']['fft_pairs']} -> {p['block']['fft_pairs']}, "
            f"{p['diagonal']['time_s']:.1f} -> {p['block']['time_s']:.1f} s "
            f"(F_A rel diff {p['F_A_rel_diff']:.1e})")
        e = o["event_merge"]
        add("opts", f"event_merge 1e-6 -> 1e-4 ({e['scene']})", "solves, time, F_A rel diff",
            f"{e['1e-06']['cg_solves']} -> {e['0.0001']['cg_solves']}, "
            f"{e['1e-06']['time_s']:.1f} -> {e['0.0001']['time_s']:.1f} s, "
            f"{e['F_A_rel_diff']:.1e}")
        x = o["relax_tol"]
        add("opts", f"relax_tol 1e-8 -> 1e-5 ({x['scene']})", "CG its, time, F_A rel diff",
            f"{x['1e-08']['cg_iterations']} -> {x['1e-05']['cg_iterations']}, "
            f"{x['1e-08']['time_s']:.1f} -> {x['1e-05']['time_s']:.1f} s, {x['F_A_rel_diff']:.1e}")
        for r in o["padded_size"].values():
            add("opts", f"N={r['N']} m={r['m']} ({r['rule']}), FFTW {r['planner']}",
                "CG iteration time (vs 7-smooth, ESTIMATE)",
                f"{r['cg_iteration_ms']:.2f} ms ({r['speedup_vs_default']:.2f}x, "
                f"force rel diff {r['force_rel_diff']:.0e})")
        for m, r in o["planner"].items():
            add("opts", f"FFTW ESTIMATE -> MEASURE m={m}", "pruned pair, planning, break-even",
                f"{r['estimate']['pair_ms']:.2f} -> {r['measure']['pair_ms']:.2f} ms "
                f"({r['pair_speedup']:.2f}x), {r['measure']['plan_s']:.1f} s, "
                f"{_fmt(r['break_even_pairs'], '.0f')} pairs")
    return rows


def format_table(rows) -> str:
    """The rows as one aligned text table."""
    head = ("section", "case", "quantity", "value")
    w = [max(len(r[i]) for r in list(rows) + [head]) for i in range(4)]
    line = lambda r: " | ".join(s.ljust(w[i]) for i, s in enumerate(r)).rstrip()  # noqa: E731
    sep = "-+-".join("-" * x for x in w)
    return "\n".join([line(head), sep] + [line(r) for r in rows])
