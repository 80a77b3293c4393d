"""The report: on a campaign written through the real store it reads the known plateau, c
and alpha/beta; on a real (engine) campaign it writes every figure, table and both pages."""

import csv
import math

import numpy as np
import pytest
from campaign_helpers import TINY, write_grid

from fibril_hpc import load_campaign
from fibril_hpc.campaign.analysis.report import write_report
from fibril_hpc.campaign.plan.spec import spec_from_dict
from fibril_hpc.campaign.storage import store
from fibril_hpc.cli.campaign import main

PRELOADS = [0.001 * 2**i for i in range(15)]    # x 2 apart, as F_P: auto brackets the kink
ALPHA, BETA = 0.5, 0.25                         # sigma~_c = 2
PLATEAU = {0.1: 1.8, 0.2: 1.2, 0.4: 0.7, 3.0: 0.01}
FIGURES = ("FA_vs_FP.png", "c_vs_sigma.png", "c0_vs_sigma.png", "plateau.png",
           "alpha_sigma_c.png", "sigma_c_loss.png", "curves.png")
TABLES = ("alpha_beta.csv", "plateau.csv", "coefficients.csv", "law_comparison.csv")


def _fa(sigma, p):
    """F~_A of the synthetic campaign: a tanh rise whose secant through the origin to half the
    plateau (the report's c) is alpha/sigma~ - beta, flat (the last pillar's pull-off, c = 0)
    beyond sigma~_c."""
    P = PLATEAU[sigma]
    c = ALPHA / sigma - BETA
    if c <= 0:
        return P
    return P * math.tanh(p * c * 2 * math.atanh(0.5) / P)


def _synthetic(tmp_path, seeds, noise=0.02, rng_seed=1, k_tilde=(1,)):
    """A campaign file of known plateau and c per sigma~, written by the store."""
    grid = {"output": "syn.h5", "scene": {"n_side": 18, "preset": "fast"},
            "k_tilde": list(k_tilde), "sigma_tilde": sorted(PLATEAU), "F_P": PRELOADS,
            "seeds": seeds}
    spec = spec_from_dict(grid, base_dir=str(tmp_path))
    rng = np.random.default_rng(rng_seed)
    eff = {(j.k_tilde, j.sigma_tilde, j.seed): rng.normal(0, noise) for j in spec.jobs}
    recs = []
    for j in spec.jobs:
        fa = _fa(j.sigma_tilde, j.preload) * (1 + eff[(j.k_tilde, j.sigma_tilde, j.seed)])
        recs.append({**j.inputs(), "status": "done", "message": "", "F_P": j.preload,
                     "F_A": fa, "record_id": f"{j.index:032x}", "finished": store.now(),
                     "group_size": len(PRELOADS), "wall_s": 0.0})
    store.write_merged(spec.output, store.root_attrs_for(spec), recs)
    return spec.output


def _rows(path):
    return list(csv.DictReader(path.read_text().splitlines()))


def test_report_reads_the_known_plateau_c_and_alpha_beta(tmp_path):
    path = _synthetic(tmp_path, seeds=3)
    out = tmp_path / "rep"
    assert main(["report", path, "--out", str(out), "--n-boot", "100"]) == 0
    for f in FIGURES + TABLES + ("README.md", "report.html"):
        assert (out / f).stat().st_size > 0, f
    plat = {float(r["sigma_tilde"]): r for r in _rows(out / "plateau.csv")}
    for s, P in PLATEAU.items():
        r = plat[s]
        assert float(r["plateau_lo"]) <= float(r["plateau"]) <= float(r["plateau_hi"])
        assert float(r["plateau"]) == pytest.approx(P, rel=0.05)
        assert r["state"] == ("no rise" if s == 3.0 else "reached")
        assert r["group_state"] == ("adhesion lost" if s == 3.0 else "rise resolved")
        assert r["bias_rel"] == "-0.036" and r["dominant"] in ("seeds", "discretisation")
    coef = {float(r["sigma_tilde"]): r for r in _rows(out / "coefficients.csv")}
    # the lost group: c = 0, left out of the alpha/beta line (issue 34), and said so
    assert float(coef[3.0]["c"]) == 0.0 and coef[3.0]["in_alpha_beta_fit"] == "false"
    assert "left out of the alpha/beta line" in coef[3.0]["why_out"]
    assert coef[3.0]["c_minus_law"] == ""
    for s in (0.1, 0.2, 0.4):
        # the secant through the origin to half the plateau, from preloads a factor 2 apart
        assert float(coef[s]["c"]) == pytest.approx(ALPHA / s - BETA, rel=0.05)
    (ab,) = _rows(out / "alpha_beta.csv")
    assert ab["n_c_zero"] == "1" and ab["bracket_c_zero_from"] == "3.0"
    assert float(ab["sigma_tilde_c_lo"]) <= float(ab["sigma_tilde_c"]) <= 3.0
    # the measured loss: the plateau (0.7 at 0.4, 0.01 at 3) crosses 3 pillars' pull-off at
    # 0.4 x 7.5^(ln(0.7/0.0248)/ln 70) = 1.95 (log-log); alpha/beta = 2 lies in the bracket
    assert ab["loss_kind"] == "bracket"
    assert (ab["loss_bracket_lo"], ab["loss_bracket_hi"]) == ("0.4", "3.0")
    assert float(ab["sigma_tilde_c_measured"]) == pytest.approx(1.95, rel=0.05)
    assert 0.4 <= float(ab["sigma_tilde_c_measured_lo"]) <= float(ab["sigma_tilde_c_measured"]) \
        <= float(ab["sigma_tilde_c_measured_hi"]) <= 3.0
    assert ab["loss_vs_law"] == "within" and ab["sigma_tilde_c_status"] == "extrapolated"
    page = (out / "README.md").read_text()
    assert page.splitlines()[2].startswith("**Where this brush loses adhesion, σ̃_c per k̃")
    # one number and one interval: the measured sigma~_c and the sigma~ run around it
    assert page.splitlines()[4] == (f"k̃ = 1: {float(ab['sigma_tilde_c_measured']):.3g}, lost "
                                    "in (0.4, 3].")
    for f in FIGURES:
        assert f"]({f})" in page
    html = (out / "report.html").read_text()
    assert html.count("src='data:image/png;base64,") == len(FIGURES) and "<table>" in html
    assert main(["report", path, "--out", str(out), "--n-boot", "3"]) == 2


def test_report_on_a_real_campaign_writes_every_figure_and_table(tmp_path):
    grid = write_grid(tmp_path, dict(TINY, k_tilde=[1.0], F_P=[0.02, 0.1, 0.5, 2.0]))
    assert main([grid, "--no-progress"]) == 0
    out = tmp_path / "rep"
    files = write_report(str(tmp_path / "tiny.h5"), str(out), n_boot=50)
    assert {p.rsplit("/", 1)[1] for p in files} >= set(FIGURES + TABLES)
    rows = _rows(out / "coefficients.csv")
    assert {(float(r["k_tilde"]), float(r["sigma_tilde"])) for r in rows} == {(1.0, 0.3),
                                                                                 (1.0, 1.0)}
    for r in rows:
        assert r["in_alpha_beta_fit"] in ("true", "false")
        assert r["in_alpha_beta_fit"] == "true" or r["why_out"]
    for r in _rows(out / "alpha_beta.csv"):
        for col in ("alpha", "beta", "sigma_tilde_c"):
            assert r[col] == "" or math.isfinite(float(r[col]))
        assert r["sigma_tilde_c"] != "" or r["note"]


def test_frame_and_export_csv_parquet(tmp_path):
    pd = pytest.importorskip("pandas")
    pytest.importorskip("pyarrow")
    path = _synthetic(tmp_path, seeds=2)
    c = load_campaign(path, curves=False)
    df = c.to_dataframe()
    assert len(df) == len(c.jobs) == 1 * len(PLATEAU) * 2 * len(PRELOADS)
    assert df["F_A"].dtype == float and df["seed"].dtype == "int64"
    assert list(df["key"]) == [j["key"] for j in c.jobs]
    assert np.array_equal(df["F_A"].to_numpy(), c.column("F_A"))
    pq, cs = tmp_path / "o.parquet", tmp_path / "o.csv"
    assert main(["export", path, "--csv", str(cs), "--parquet", str(pq)]) == 0
    back = pd.read_parquet(pq)
    assert list(back.columns) == list(df.columns)
    assert np.array_equal(back["F_A"].to_numpy(), df["F_A"].to_numpy())
    rows = list(csv.DictReader(cs.read_text().splitlines()))
    assert [float(r["F_A"]) for r in rows] == list(df["F_A"])
    assert main(["export", path]) == 2
