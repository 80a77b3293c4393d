"""The report on real engine output: tests/data/real18_k1.h5, the k~ = 1 block of an 18 x 18,
preset fast, F_P: auto campaign (3 seeds, 5 sigma~; how it was made: real18_k1.yaml beside it).

The plateau lies inside the seed range of F~_A at the largest preload, or the group says
"plateau not reached" and F_P: auto extends that path until F~_A stops rising."""

import os

import pytest

from fibril_hpc import load_campaign
from fibril_hpc.campaign.analysis.report_data import law_rows, points_by_group
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, pillar_floor
from fibril_hpc.campaign.laws.study import study
from fibril_hpc.campaign.plan import auto

FIXTURE = os.path.join(os.path.dirname(__file__), "data", "real18_k1.h5")
SIGMAS = (0.07, 0.164, 0.384, 0.898, 2.1)
FLOOR = pillar_floor(18, 0.16)


@pytest.fixture(scope="module")
def jobs():
    return load_campaign(FIXTURE, curves=False).jobs


def _study(jobs):
    return study(points_by_group(jobs), n_boot=50, floor=FLOOR)[1.0]


def _paths(jobs):
    out: dict = {}
    for j in jobs:
        out.setdefault((j["k_tilde"], j["sigma_tilde"], j["seed"]), {})[j["preload"]] = (
            j["F_P"], j["F_A"])
    return out


def test_the_plateau_is_inside_the_seed_range_at_the_largest_preload(jobs):
    st = _study(jobs)
    assert [g.sigma_tilde for g in st.groups] == list(SIGMAS)
    for g in st.groups:
        r = g.reading
        assert r.plateau_state in ("reached", "no rise"), (g.sigma_tilde, r.notes)
        eps = 1e-12 * abs(r.plateau)
        assert r.top_lo - eps <= r.plateau <= r.top_hi + eps, (g.sigma_tilde, r)
        assert g.plateau_ci[0] - eps <= r.plateau <= g.plateau_ci[1] + eps
    # the rough, stiff brush: the last pillar's pull-off at every preload, equal over seeds:
    # adhesion lost (F~_A = 0.0075 within one pillar's Kendall pull-off, 0.0083); the others rise
    last = st.groups[-1].reading
    assert last.plateau_state == "no rise" and last.state == LOST and last.c == 0.0
    assert last.plateau < pillar_floor(18, 0.16)
    assert [g.reading.state for g in st.groups[:-2]] == [RESOLVED] * 3
    assert last.top_lo == pytest.approx(last.top_hi, rel=1e-12)          # seeds equal to 1e-14


def test_a_plateau_not_reached_is_said_and_auto_extends_the_preloads(jobs):
    # the file before its plateau rounds: F~_A still rises from 0.71 at F~_P = 1 to 0.81 at 4
    before = [j for j in jobs if j["preload"] <= 4.0]
    g = next(g for g in _study(before).groups if g.sigma_tilde == 0.164)
    assert g.reading.plateau_state == "not reached" and not g.in_fit
    assert "plateau not reached" in g.reading.notes[0]
    a = auto.AutoPreloads()            # the grid's settings: the defaults of F_P: auto
    for path, res in _paths(before).items():
        if path[1] == 0.164:
            assert auto.path_todo(a, res)[0] == [16.0], path
    # with the plateau round's records the group is read on its plateau, and nothing is left
    for path, res in _paths(jobs).items():
        assert auto.path_todo(a, res)[0] == [], path
    g = next(g for g in _study(jobs).groups if g.sigma_tilde == 0.164)
    assert g.reading.plateau_state == "reached" and g.reading.plateau_from == pytest.approx(4.0)


def test_alpha_beta_take_the_lost_adhesion_as_c_zero(jobs):
    st = _study(jobs)
    ab = st.ab
    # sigma~ = 0.898 creeps from one pillar's pull-off to two (0.0075 -> 0.021, below 3 pillars'
    # 0.025) and sigma~ = 2.1 stays at one: both lost adhesion, c = 0 in the fit
    assert [g.reading.state for g in st.groups][-2:] == [LOST, LOST]
    assert ab.ok and ab.n_points == 5 and ab.n_zero == 2 and ab.bracket == (0.384, 0.898)
    assert all(g.in_fit for g in st.groups)
    # the two lost groups are given to the fit but left out of it (issue 34: their weight
    # swung from 0.43 (creeping) to 5.3e4 (flat)); three rising points, one dof
    assert ab.n_active == 3 and ab.dof == 1 and ab.lost == "out"
    assert st.status != "fitted" or not ab.poor


def test_the_tanh_law_reads_the_plateau_low_where_the_reading_does_not(jobs):
    points = points_by_group(jobs)
    st = study(points, n_boot=0, floor=FLOOR)
    rows = law_rows(points, st)
    # the bias: fitted in log F~_A to points packed at small preloads, tanh's plateau
    # lies well below F~_A at every large preload (the reading sits inside their seed range)
    assert rows[(1.0, 0.07)]["tanh"].plateau_vs_read < -0.1
