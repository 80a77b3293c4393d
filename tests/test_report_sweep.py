"""The report of a grid sweeping lab fields (tip_radius, tip, heights, ...): one combination of
the swept values is read (the first listed, or ``--where NAME=VALUE``), never a mixture of
variants, and the page says which; two points of one (preload, seed) with different numbers
are refused, never one silently replacing the other."""

import csv
import math
import os

import numpy as np
import pytest

from fibril_hpc import load_campaign
from fibril_hpc.campaign import spec_from_dict
from fibril_hpc.campaign.analysis.report import write_report
from fibril_hpc.campaign.analysis.report_data import points_by_group
from fibril_hpc.campaign.analysis.variants import job_variant, swept_lab_fields
from fibril_hpc.errors import ConfigError
from fibril_hpc.campaign.laws.reading import levels, read_group
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage import store
from fibril_hpc.cli.campaign import main
from fibril_hpc.inputs.config import scene_to_yaml

RADII = [0.5, 4]
GRID = {"output": "s.h5", "scene": {"preset": "fast", "n_side": 4, "tip": "sphere",
                                    "tip_radius": 2},
        "k_tilde": [1.0, 0.01], "sigma_tilde": [0.1, 0.5],
        "F_P": [0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0], "seeds": 3,
        "sweep": {"tip_radius": RADII}}


def _plateau(extra) -> float:
    """A law of the swept values the report must read back: a blunter tip holds less."""
    d = dict(extra)
    return 1.0 / (1.0 + d.get("tip_radius", 2) / 4) * (0.8 if d.get("lattice") == "hexagonal" else 1.0) \
        * (1.0 - 1.0 / d.get("n_side", 1e9))


def _synthetic(folder, grid, name=None, keep=lambda extra: True, keep_job=lambda job: True,
               law=None):
    """A campaign written through the real store, every record with its stored scene, whose
    F~_A rises to a plateau set by the swept values (each seed a fixed 1 % off the next); only
    the jobs whose swept values pass ``keep`` are written (the others still to run)."""
    grid = dict(grid, output=name or grid["output"])
    spec = spec_from_dict(grid, base_dir=str(folder))
    recs = []
    for i, j in enumerate(spec.jobs):
        if not (keep(dict(j.extra)) and keep_job(j)):
            continue
        fa = law(j) if law else \
            _plateau(j.extra) * math.tanh(j.preload / 0.1) * (1 + 0.01 * (j.seed - 1))
        recs.append({**j.inputs(), "status": "done", "message": "", "F_P": j.preload, "F_A": fa,
                     "record_id": f"{i:032x}", "finished": store.now(), "group_size": 1,
                     "wall_s": 0.0, "scene_yaml": scene_to_yaml(spec.job_scene(j))})
    store.write_merged(spec.output, store.root_attrs_for(spec), recs)
    return spec.output


def _csv(path) -> list:
    with open(path) as fh:
        return list(csv.DictReader(fh))


def _alone(folder, grid, **values):
    """The report of a grid holding one variant alone: the reference every reading must equal."""
    one = dict(grid, sweep={**grid["sweep"], **{n: [v] for n, v in values.items()}})
    tag = "-".join(f"{n}{v}" for n, v in values.items())
    path = _synthetic(folder, one, name=f"alone-{tag}.h5")
    write_report(path, str(folder / f"alone-{tag}"), n_boot=40)
    return folder / f"alone-{tag}"


TABLES = ("plateau.csv", "coefficients.csv", "alpha_beta.csv")


@pytest.mark.slow
def test_the_report_reads_the_first_variant_alone_and_says_so(tmp_path):
    path = _synthetic(tmp_path, GRID)
    write_report(path, str(tmp_path / "rep"), n_boot=40)
    ref = _alone(tmp_path, GRID, tip_radius=0.5)
    for name in TABLES:                 # every number of the variant alone, none of the other
        assert _csv(tmp_path / "rep" / name) == _csv(ref / name), name
    plat = _csv(tmp_path / "rep" / "plateau.csv")
    assert len(plat) == 4
    assert all(float(r["plateau"]) == pytest.approx(_plateau({"tip_radius": 0.5}), rel=0.02)
               for r in plat)
    page = (tmp_path / "rep" / "README.md").read_text()
    assert "The grid sweeps tip_radius (0.5, 4)" in page
    assert "reads **tip_radius = 0.5** only (the first listed combination with done jobs" in page
    assert "Not read: tip_radius = 4 (84 done jobs)" in page
    figs = page.split("## Figures")[1].split("## Tables")[0]        # the figures come first
    captions = [line for line in figs.splitlines() if line.startswith("### ")]
    assert captions and all(c.endswith("(tip_radius = 0.5)") for c in captions)
    html = (tmp_path / "rep" / "report.html").read_text()
    assert "tip_radius = 0.5" in html and "Not read: tip_radius = 4" in html


@pytest.mark.slow
def test_while_the_first_variant_has_no_done_job_the_first_that_has_is_read(tmp_path):
    path = _synthetic(tmp_path, GRID, keep=lambda e: e["tip_radius"] == 4)
    write_report(path, str(tmp_path / "rep"), n_boot=40)
    assert _csv(tmp_path / "rep" / "plateau.csv") == _csv(_alone(tmp_path, GRID, tip_radius=4) /
                                                          "plateau.csv")
    page = (tmp_path / "rep" / "README.md").read_text()
    assert "reads **tip_radius = 4** only (the first listed combination with done jobs" in page
    assert "No other variant has done jobs in the file." in page


@pytest.mark.slow
def test_where_reads_another_variant(tmp_path, capsys):
    path = _synthetic(tmp_path, GRID)
    out = tmp_path / "rep4"
    assert main(["report", path, "--out", str(out), "--n-boot", "40",
                 "--where", "tip_radius=4"]) == 0
    ref = _alone(tmp_path, GRID, tip_radius=4)
    for name in TABLES:
        assert _csv(out / name) == _csv(ref / name), name
    assert all(float(r["plateau"]) == pytest.approx(_plateau({"tip_radius": 4}), rel=0.02)
               for r in _csv(out / "plateau.csv"))
    page = (out / "README.md").read_text()
    assert "reads **tip_radius = 4** only (chosen with `--where`" in page
    assert "Not read: tip_radius = 0.5 (84 done jobs)" in page
    # the Python API takes the same choice as a mapping
    write_report(path, str(tmp_path / "api"), n_boot=40, where={"tip_radius": 4.0})
    assert _csv(tmp_path / "api" / "plateau.csv") == _csv(out / "plateau.csv")


@pytest.mark.slow
def test_two_swept_fields_read_one_combination(tmp_path):
    grid = dict(GRID, k_tilde=[1.0], sweep={"lattice": ["square", "hexagonal"],
                                            "tip_radius": RADII})
    path = _synthetic(tmp_path, grid)
    write_report(path, str(tmp_path / "rep"), n_boot=40, where=["lattice=hexagonal"])
    plat = _csv(tmp_path / "rep" / "plateau.csv")
    want = _plateau({"lattice": "hexagonal", "tip_radius": 0.5})
    assert all(float(r["plateau"]) == pytest.approx(want, rel=0.02) for r in plat)
    page = (tmp_path / "rep" / "README.md").read_text()
    assert "reads **lattice = hexagonal, tip_radius = 0.5** only" in page
    assert ("Not read: lattice = square, tip_radius = 0.5 (42 done jobs); lattice = square, "
            "tip_radius = 4 (42 done jobs); lattice = hexagonal, tip_radius = 4 (42 done jobs)"
            ) in page


@pytest.mark.slow
def test_a_variant_is_read_from_the_stored_scene_without_the_grid(tmp_path):
    grid = dict(GRID, sweep={"lattice": ["square", "hexagonal"], "tip_radius": RADII})
    path = _synthetic(tmp_path, grid)
    c = load_campaign(path)
    values = swept_lab_fields(c.meta)
    spec = spec_from_dict(dict(grid, output="x.h5"), base_dir=str(tmp_path))
    want = {j.key: tuple(values[n].index(dict(j.extra)[n]) for n in values) for j in spec.jobs}
    by_key = {j.key: dict(j.extra) for j in spec.jobs}
    for j in c.jobs:                    # by key through the grid, and from the scene alone
        assert job_variant(j, values, by_key) == want[j["key"]]
        assert job_variant(j, values, None) == want[j["key"]]


@pytest.mark.slow
def test_a_size_sweep_with_a_lab_sweep_reads_the_variant_at_every_size(tmp_path):
    grid = dict(GRID, k_tilde=[1.0], seeds=2, sweep={"n_side": [4, 8], "tip_radius": RADII})
    grid["scene"] = {k: v for k, v in GRID["scene"].items() if k != "n_side"}
    path = _synthetic(tmp_path, grid)
    write_report(path, str(tmp_path / "rep"), n_boot=40, where=["tip_radius=4"])
    rows = _csv(tmp_path / "rep" / "finite_size.csv")
    assert {r["n_side"] for r in rows} == {"4", "8"}
    for r in rows:
        want = _plateau({"tip_radius": 4, "n_side": int(r["n_side"])})
        assert float(r["plateau"]) == pytest.approx(want, rel=0.02)
    page = (tmp_path / "rep" / "README.md").read_text()
    assert "### Finite size: the plateau against the brush size n_side, and its change against " \
           "the largest (tip_radius = 4)" in page
    assert "(tip_radius = 4, n_side = 8)" in page


@pytest.mark.parametrize("where, text", [
    (["tip=flat"], "allowed: NAME=VALUE, one of tip_radius=0.5, tip_radius=4"),
    (["tip_radius=3"], "allowed: one of tip_radius=0.5, tip_radius=4"),
    (["tip_radius"], "allowed: NAME=VALUE, one of tip_radius=0.5, tip_radius=4"),
    (["tip_radius=4", "tip_radius=0.5"], "each NAME once"),
    (["n_side=4"], "its own reading"),
])
def test_a_bad_where_is_one_line_exit_2_nothing_written(tmp_path, capsys, where, text):
    path = _synthetic(tmp_path, GRID)
    out = tmp_path / "rep"
    argv = ["report", path, "--out", str(out)]
    for w in where:
        argv += ["--where", w]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--where" in err[0] and text in err[0], err
    assert not out.exists()


@pytest.mark.slow
def test_where_on_a_grid_without_a_lab_sweep_is_refused(tmp_path, capsys):
    grid = {k: v for k, v in GRID.items() if k != "sweep"}
    path = _synthetic(tmp_path, grid)
    assert main(["report", path, "--out", str(tmp_path / "rep"), "--where", "tip=flat"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--where" in err[0] and "sweeps no lab field" in err[0]
    assert not (tmp_path / "rep").exists()
    write_report(path, str(tmp_path / "ok"), n_boot=20)        # and without: as it always was
    assert "sweeps" not in (tmp_path / "ok" / "README.md").read_text()


# ------------------------------------------------------------------------------ a real campaign
REAL = {"output": "real.h5", "scene": {"n_side": 3, "preset": "fast", "tip": "sphere",
                                       "tip_radius": 2, "solver": {"fft_threads": 1}},
        "k_tilde": [1], "sigma_tilde": [0.5], "F_P": [0.1, 1, 4], "seeds": 2,
        "sweep": {"tip_radius": RADII}}


def _run(folder, grid):
    spec = spec_from_dict(grid, base_dir=str(folder))
    assert run_serial(spec, progress=False) == 0
    return spec.output


@pytest.mark.slow
def test_a_real_swept_campaign_reads_each_variant_as_its_own_grid(tmp_path):
    path = _run(tmp_path, REAL)
    for r in RADII:
        one = _run(tmp_path, dict(REAL, output=f"one-{r}.h5", sweep={"tip_radius": [r]}))
        write_report(one, str(tmp_path / f"one-{r}"), n_boot=20)
        write_report(path, str(tmp_path / f"all-{r}"), n_boot=20, where=[f"tip_radius={r}"])
        assert _csv(tmp_path / f"all-{r}" / "plateau.csv") == \
            _csv(tmp_path / f"one-{r}" / "plateau.csv")
    write_report(path, str(tmp_path / "default"), n_boot=20)
    assert _csv(tmp_path / "default" / "plateau.csv") == _csv(tmp_path / "one-0.5" /
                                                              "plateau.csv")
    a, b = (float(_csv(tmp_path / f"one-{r}" / "plateau.csv")[0]["plateau"]) for r in RADII)
    assert abs(a / b - 1) > 0.01        # the variants differ: a mixture would be neither


def test_every_table_keeps_the_variants_apart(tmp_path):
    """DataFrame, CSV, Parquet and netCDF carry each swept lab field: the rows of two variants
    at one (k~, sigma~, preload, seed) are told apart, each by its own value."""
    xr = pytest.importorskip("xarray")
    from fibril_hpc.campaign.analysis.export import export_csv, export_netcdf
    from fibril_hpc.campaign.analysis.dataset import netcdf_available

    grid = dict(GRID, k_tilde=[1.0], seeds=2, sweep={"lattice": ["square", "hexagonal"],
                                                     "tip_radius": RADII})
    path = _synthetic(tmp_path, grid)
    spec = spec_from_dict(dict(grid, output="x.h5"), base_dir=str(tmp_path))
    want = {j.key: dict(j.extra) for j in spec.jobs}
    c = load_campaign(path)
    assert c.lab_sweeps == {"lattice": ["square", "hexagonal"], "tip_radius": RADII}
    df = c.to_dataframe()
    assert list(df.columns[-2:]) == ["lattice", "tip_radius"]
    pd = pytest.importorskip("pandas")
    assert df["tip_radius"].dtype == float and pd.api.types.is_string_dtype(df["lattice"])
    for _, row in df.iterrows():
        assert (row["lattice"], row["tip_radius"]) == (want[row["key"]]["lattice"],
                                                       want[row["key"]]["tip_radius"])
    assert not df.duplicated(["lattice", "tip_radius", "k_tilde", "sigma_tilde", "preload",
                              "seed"]).any()
    # one cell's variants in the grid's order
    cell = df[(df.sigma_tilde == 0.1) & (df.preload == 0.01) & (df.seed == 0)]
    assert list(zip(cell.lattice, cell.tip_radius)) == [
        ("square", 0.5), ("square", 4.0), ("hexagonal", 0.5), ("hexagonal", 4.0)]
    export_csv(path, str(tmp_path / "e.csv"))
    rows = _csv(tmp_path / "e.csv")
    assert [(r["key"], r["lattice"], float(r["tip_radius"])) for r in rows] == \
        list(zip(df.key, df.lattice, df.tip_radius))
    ds = c.to_xarray(curves=False)
    assert ds["F_A"].dims == ("lattice", "tip_radius", "k_tilde", "sigma_tilde", "preload",
                              "seed")
    assert list(ds["lattice"].values) == ["hexagonal", "square"]
    for _, row in df.iterrows():
        got = ds["F_A"].sel(lattice=row["lattice"], tip_radius=row["tip_radius"],
                            k_tilde=row["k_tilde"], sigma_tilde=row["sigma_tilde"],
                            preload=row["preload"], seed=row["seed"])
        assert float(got) == row["F_A"]
    if netcdf_available():
        export_netcdf(path, str(tmp_path / "e.nc"), curves=False)
        with xr.open_dataset(tmp_path / "e.nc") as back:
            assert back["F_A"].dims == ds["F_A"].dims
            np.testing.assert_array_equal(back["F_A"].values, ds["F_A"].values)


def test_a_file_without_a_lab_sweep_keeps_its_columns(tmp_path):
    grid = {k: v for k, v in GRID.items() if k != "sweep"}
    c = load_campaign(_synthetic(tmp_path, dict(grid, k_tilde=[1.0], seeds=1)))
    assert c.lab_sweeps == {}
    assert "tip_radius" not in c.to_dataframe().columns
    assert c.to_xarray(curves=False)["F_A"].dims == ("k_tilde", "sigma_tilde", "preload",
                                                      "seed")


# ------------------------------------------------------------------------------ the safety net
def test_levels_refuse_two_different_points_of_one_preload_and_seed():
    seed, pre = [0, 0, 1, 1, 0], [1.0, 2.0, 1.0, 2.0, 1.0]
    F_P, F_A = [1.0, 2.0, 1.0, 2.0, 1.0], [0.5, 0.8, 0.52, 0.81, 0.7]
    with pytest.raises(ValueError, match=r"preload 1, seed 0 .*\(1, 0\.5\) and \(1, 0\.7\)"):
        levels(seed, pre, F_P, F_A)
    with pytest.raises(ValueError, match="preload 1, seed 0"):
        read_group(seed, pre, F_P, F_A)
    # the same point twice counts once, exactly as before
    lv = levels(seed, pre, F_P, [0.5, 0.8, 0.52, 0.81, 0.5])
    ref = levels(seed[:4], pre[:4], F_P[:4], [0.5, 0.8, 0.52, 0.81])
    assert np.array_equal(lv.F_A, ref.F_A) and np.array_equal(lv.n, ref.n)


def test_points_of_two_scenes_in_one_group_name_both_jobs():
    base = {"status": "done", "k_tilde": 1.0, "sigma_tilde": 0.5, "preload": 1.0, "seed": 0,
            "F_P": 1.0}
    jobs = [dict(base, key="a" * 8, F_A=0.5), dict(base, key="b" * 8, F_A=0.6)]
    with pytest.raises(ConfigError, match="aaaaaaaa and bbbbbbbb") as err:
        points_by_group(jobs)           # a user's file: one line and exit 2 on the command line
    assert "\n" not in str(err.value)
    same = points_by_group([jobs[0], dict(jobs[0], key="c" * 8)])      # same numbers: fine
    assert len(same[(1.0, 0.5)][0]) == 2 and len(levels(*same[(1.0, 0.5)])) == 1


def test_the_shipped_machine_and_size_sweeps_have_no_variants():
    """k_machine and n_side keep their own readings: no variant, no --where for them."""
    here = os.path.join(os.path.dirname(__file__), "..", "campaigns")
    for name in ("machine.yaml", "finite_size.yaml"):
        with open(os.path.join(here, name)) as fh:
            assert swept_lab_fields({"campaign_yaml": fh.read()}) == {}, name


@pytest.mark.slow
def test_a_k_without_the_largest_size_is_named_not_dropped_in_silence(tmp_path):
    """A merged file whose k~ = 1 ran 4 x 4 only and k~ = 0.01 also 8 x 8: the per-(k~, sigma~)
    tables read n_side = 8 (k~ = 0.01 alone) and the page says so, naming k~ = 1's size."""
    grid = dict(GRID, sweep={"n_side": [4, 8]})
    grid["scene"] = {k: v for k, v in GRID["scene"].items() if k != "n_side"}
    path = _synthetic(tmp_path, grid, keep_job=lambda j: not (j.k_tilde == 1.0
                                                               and dict(j.extra)["n_side"] == 8))
    write_report(path, str(tmp_path / "rep"), n_boot=20)
    assert {r["k_tilde"] for r in _csv(tmp_path / "rep" / "plateau.csv")} == {"0.01"}
    page = " ".join((tmp_path / "rep" / "README.md").read_text().split())
    assert ("k̃ = 1 ran no job at n_side = 8 (largest: 4): the σ̃_c line, the per-(k̃, σ̃) "
            "tables and the figures leave them out") in page


@pytest.mark.slow
def test_the_size_loss_table_gives_the_measured_sigma_c_at_the_size_read(tmp_path):
    """One number, one interval per page: the k~ = 0.01 64 x 64 page gave sigma~_c 1.28 [0.458,
    1.83] in the alpha/beta table and [0.684, inf] in the size-loss table (two readings)."""
    from fibril_hpc.campaign.laws.reading import pillar_floor

    def law(j):                  # the plateau falls through 3 pillars between sigma~ 0.4 and 0.8
        n = dict(j.extra)["n_side"]
        top = 0.5 * math.exp(-4.0 * j.sigma_tilde) * (1 + 0.05 * (j.seed - 1))
        return (top + pillar_floor(n, 0.16)) * math.tanh(j.preload / 0.05)

    grid = dict(GRID, k_tilde=[1.0], sigma_tilde=[0.2, 0.4, 0.8, 1.6], seeds=4,
                sweep={"n_side": [4, 8]}, scene={"preset": "fast", "tip": "flat"})
    write_report(_synthetic(tmp_path, grid, law=law), str(tmp_path / "rep"), n_boot=40)
    ab = _csv(tmp_path / "rep" / "alpha_beta.csv")[0]
    rows = {r["n_side"]: r for r in _csv(tmp_path / "rep" / "size_loss.csv")}
    few = rows["8"]
    assert 0.4 < float(ab["sigma_tilde_c_measured"]) < 0.8
    assert [few[c] for c in ("sigma_few", "sigma_few_lo", "sigma_few_hi")] == \
        [ab[c] for c in ("sigma_tilde_c_measured", "sigma_tilde_c_measured_lo",
                         "sigma_tilde_c_measured_hi")]


@pytest.mark.slow
def test_a_size_sweep_of_tips_that_are_not_flat_reads_no_loss_across_sizes(tmp_path):
    """Its thresholds are flat pillars' pull-off: with sphere tips the per-(k~, sigma~) reading
    has no floor, and the size-loss section read one anyway (8: 0.446 beside "no loss")."""
    grid = dict(GRID, k_tilde=[1.0], sweep={"n_side": [4, 8]})
    grid["scene"] = {k: v for k, v in GRID["scene"].items() if k != "n_side"}
    write_report(_synthetic(tmp_path, grid), str(tmp_path / "rep"), n_boot=20)
    assert not (tmp_path / "rep" / "size_loss.csv").exists()
    page = " ".join((tmp_path / "rep" / "README.md").read_text().split())
    assert ("Where adhesion is lost across sizes is not read (no pillar floor: the tips are not "
            "flat punches: its thresholds are flat pillars' pull-off).") in page
