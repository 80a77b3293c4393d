"""The developer benchmark (python -m benchmarks.fibril_bench): the quick mode produces the table
and the JSON (no timing assertions).

The peer comparison checks *answers* (same total force and contact set as fibril on the peers'
own problem) when ContactMechanics / tamaas are installed, and says "skipped" when they are not.
"""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from benchmarks.fibril_bench import cli, memory, table, timing
from fibril_hpc.geometry.grid import pitch_elements

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    env = dict(os.environ)
    env.setdefault("NUMBA_CACHE_DIR",
                   os.path.join(os.path.dirname(__file__), "..", ".numba_cache"))
    proc = subprocess.run([sys.executable, "-m", "benchmarks.fibril_bench", "--quick", "--out",
                           str(out)], capture_output=True, text=True, env=env, timeout=900,
                          cwd=ROOT)
    assert proc.returncode == 0, proc.stderr[-3000:]
    files = sorted(out.glob("bench-*-quick.json"))
    assert len(files) == 1, list(out.iterdir())
    with open(files[0]) as fh:
        return proc.stdout, json.load(fh)


@pytest.mark.slow
def test_table_has_every_section(quick):
    stdout, res = quick
    lines = stdout.splitlines()
    head = [i for i, line in enumerate(lines) if line.startswith("section")]
    assert len(head) == 1, "exactly one table"
    sections = {line.split("|")[0].strip() for line in lines[head[0] + 2:] if "|" in line}
    assert {"fft", "cg", "scaling", "curve", "memory", "campaign", "peers"} <= sections
    assert "JSON:" in lines[-1]


def test_json_contents(quick):
    _, res = quick
    meta = res["meta"]
    assert meta["mode"] == "quick" and meta["threads"]["OPENBLAS_NUM_THREADS"] == "1"
    assert len(meta["loadavg_start"]) == 3
    for r in res["fft"]:
        assert r["m"] >= 2 * r["N"] - 1
        assert r["floor_ms"] > 0 and r["pruned_pair_ms"] > 0 and 0 < r["R"] <= r["N"]
    for r in res["cg"]:
        assert r["cg_iteration_ms"] > 0 and r["solve_at_cg_iterations"] > 0
        # every CG iteration is one operator product, plus at most one per solve (the start
        # residual, unless u = K x is kept valid without an FFT)
        its, solves = r["solve_at_cg_iterations"], r["solve_at_cg_solves"]
        assert its <= r["solve_at_fft_pairs"] <= its + solves
        assert math.isfinite(r["law_m2logm_ratio"])
    assert [c["preset"] for c in res["curves"]] == ["fast", "default"]
    for c in res["curves"]:
        assert c["status"] == "ok" and c["F_A"] > 0 and c["fft_pairs"] >= c["cg_iterations"]
    mem = res["memory"][0]
    assert "error" not in mem, mem
    assert mem["peak_growth_MB"] > 0 and mem["arrays"]["fft_buffers"]["count"] == 6
    assert mem["arrays"]["kernel_transform"]["count"] == 1      # held once, by the pair
    vec = mem["arrays"]["active_length_float_vectors"]
    # 17 since the load path keeps p0 and w (far_field: multipole's held states)
    assert 13 <= vec["count"] <= 18 and vec["bytes"] == 8 * mem["n_active"] * vec["count"]
    camp = res["campaign"]["modes"]
    assert camp[0]["mode"] == "serial" and camp[0]["jobs"] > 0
    assert camp[0]["jobs_per_hour_median"] > 0


def test_peers_same_answer_or_skipped(quick):
    stdout, res = quick
    peers = res["peers"]
    for name in ("contactmechanics", "tamaas"):
        if not peers["available"].get(name):
            assert f"{name}" in stdout and "skipped" in stdout
            continue
        for size in peers["sizes"]:
            c = size["codes"][name]
            # the same discretised problem: same force (CM: displacement control; tamaas is run
            # at fibril's force) and the same contact set, pressures equal to the tolerance
            assert abs(c["force_rel_diff"]) < 1e-6, c
            assert c["contact_set_mismatch"] == 0, c
            assert c["pressure_rel_l2_diff"] < 1e-4, c
            assert c["iterations"] and c["iterations"] > 0


def test_epd_for_pitch_hits_the_pitch():
    for pitch in (7, 9, 15, 17, 29, 35):
        assert pitch_elements(timing.PHI, timing.epd_for_pitch(pitch)) == pitch


def test_floor_pair_is_a_real_fft_pair():
    f = timing.floor_pair(12, "estimate", runs=1)
    assert f["m"] == 12 and f["median_s"] > 0 and f["planner"] == "FFTW_ESTIMATE"


def test_memory_arrays_counts_what_the_solve_holds():
    from fibril_hpc.model import build_scene_model
    from fibril_hpc.path.loading import PathDriver

    model = build_scene_model(timing.bench_scene(2, 7))
    drv = PathDriver(model)
    drv.solve_at(1.0 * model.scaling.d_c)
    a = memory.memory_arrays(model, drv)
    from fibril_hpc.elastic.fft import COLUMN_BLOCK as B

    pair = model.operator.pair
    m, r = model.operator.m, len(pair.rows)
    w = m // 2 + 1
    wp = -(-w // B) * B             # the row spectra padded to whole column blocks
    # real rows in and out, one complex row-spectrum buffer (the column stage works in place in
    # it), three m x B column blocks; the real kernel, held once: cut into column blocks (not
    # duplicated per re, im; the operator keeps no copy of its own)
    assert a["fft_buffers"]["bytes"] == 2 * 8 * r * m + 16 * r * wp + 3 * 16 * m * B
    assert a["kernel_transform"]["bytes"] == 8 * m * wp
    assert a["kernel_transform"]["count"] == 1 and wp >= w
    vec = a["active_length_float_vectors"]
    assert vec["bytes"] == vec["count"] * 8 * model.geometry.n_active and vec["count"] >= 13
    assert a["total_bytes"] == sum(v["bytes"] for k, v in a.items() if k != "total_bytes")


def test_table_formatting_of_a_failed_memory_row():
    res = {"meta": {"fftw_planner": "FFTW_ESTIMATE"}, "memory": [{"pitch": 9, "error": ["boom"]}]}
    rows = table.table_rows(res)
    assert rows == [("memory", "pitch 9", "failed", "['boom']")]
    assert table.format_table(rows).splitlines()[0].startswith("section")


def test_unknown_section_is_a_usage_error(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "benchmarks.fibril_bench", "--quick", "--only",
                           "nope", "--out", str(tmp_path), "--no-pin"],
                          capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert proc.returncode != 0 and "unknown section 'nope'" in proc.stderr
    assert not list(tmp_path.iterdir())


def test_time_call_reports_a_median():
    t = timing.time_call(lambda: np.sum(np.ones(10)), runs=3, min_s=1e-4)
    assert t["wall_min_s"] <= t["wall_median_s"] and len(t["wall_samples_s"]) == 3
    assert t["median_s"] == t["cpu_median_s"] and len(t["cpu_samples_s"]) == 3
    w = timing.time_call(lambda: None, runs=2, min_s=1e-4, clock="wall")
    assert w["median_s"] == w["wall_median_s"]


def test_every_section_is_in_the_dispatch_table():
    assert set(cli.DEFAULT_SECTIONS) < set(cli.SECTIONS) and "opts" in cli.SECTIONS
    assert all(callable(f) for f in cli.SECTIONS.values())


def test_growth_rows_of_a_capped_and_a_whole_curve(tmp_path):
    """benchmarks/growth.py --max-wall-s: a curve stopped by the cap is a row with its status
    and F~_A nan (the pairs and events up to the cap), a whole one is ``ok`` with its F~_A."""
    from benchmarks import growth

    rows = []
    for name, extra in (("whole", []), ("capped", ["--max-wall-s", "1e-3"])):
        out = tmp_path / name
        assert growth.main(["--sides", "5", "--preset", "fast", "--out", str(out)] + extra) == 0
        (f,) = [p for p in os.listdir(out) if p.endswith(".json")]
        with open(out / f) as fh:
            rows.append(json.load(fh)["rows"][0])
    whole, capped = rows
    assert whole["status"] == "ok" and whole["F_A"] > 0 and whole["fft_pairs"] > 0
    assert capped["status"] == "failed" and math.isnan(capped["F_A"])
    assert capped["events"] < whole["events"]
