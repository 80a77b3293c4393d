"""sigma_tilde: auto and seeds: auto (campaign.plan.search): the search finds a known loss of
adhesion within its stated bracket, adds seeds only where the scatter asks for them, makes the
same choices whatever the order its paths finish in, and runs, resumes and prices like any grid."""

import math
import os
import signal
import time

import numpy as np
import pytest
from campaign_helpers import results_by_key, run, same_numbers, start, write_grid
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fibril_hpc import load_campaign
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, pillar_floor
from fibril_hpc.campaign.plan import search
from fibril_hpc.campaign.plan.spec import spec_from_dict
from fibril_hpc.cli.campaign import main

PRELOADS = [0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0, 16.0]
FLOOR = pillar_floor(18, 0.16)


def _spec(sigma=None, seeds=None, **kw):
    data = {"output": "s.h5", "scene": {"n_side": 18, "phi": 0.16}, "k_tilde": kw.pop("k", [1.0]),
            "sigma_tilde": sigma or {"auto": {"start": [0.05, 0.2, 0.8, 3.2]}},
            "F_P": PRELOADS, "seeds": seeds or 3, **kw}
    return spec_from_dict(data)


class Truth:
    """A synthetic brush: c = alpha/sigma~ - beta and a plateau of 1 below ``loss``, adhesion
    lost (1.5 pillars' pull-off at every preload) from ``loss`` on; every seed scatters F~_A by
    ``noise`` (relative, the same at every preload of a path)."""

    def __init__(self, loss, alpha=0.3, beta=0.05, noise=0.02, c_noise=0.0):
        self.loss, self.alpha, self.beta, self.noise = loss, alpha, beta, noise
        self.c_noise = c_noise          # a seed's own scatter of c (moves its kink)

    def __call__(self, path, p):
        k, s, seed = path[:3]
        z = np.random.default_rng([seed, int(round(s * 1e6))]).standard_normal()
        if s >= self.loss:
            return p, 1.5 * FLOOR * (1 + 0.05 * z)
        c = max(self.alpha / s - self.beta, 1e-3)
        if self.c_noise:
            c *= math.exp(self.c_noise * np.random.default_rng([seed, 7]).standard_normal())
        return p, min(c * p, 1.0) * (1 + self.noise * z)


def drive(spec, truth, rng=None):
    """Run a search grid on synthetic records: every round's paths, or (``rng``) a random part
    of them at a time, as paths finish in any order; returns the records {path: {preload: ...}}."""
    done: dict = {}
    cache: dict = {}
    for _ in range(10000):
        todo = search.frontier_of(spec, done, {}, cache=cache)
        if not todo:
            return done
        if rng is not None:
            todo = [todo[i] for i in sorted(rng.choice(len(todo), size=rng.integers(1, len(todo) + 1),
                                                       replace=False))]
        for path, pre in todo:
            for p in pre:
                done.setdefault(path, {})[p] = truth(path, p)
    raise AssertionError("the search never finished")


def _lines(spec, done):
    return {line: search.replay_line(spec, line, done, {}) for line in spec.lines()}


@pytest.mark.slow
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(loss=st.floats(0.06, 3.0))
def test_the_search_brackets_a_known_loss_within_its_bracket(loss):
    spec = _spec()
    ln = _lines(spec, drive(spec, Truth(loss)))[(1.0,)]
    states = {s: g.state for s, g in ln.groups.items()}
    lo, hi = search.loss_bracket(states)
    assert lo < loss <= hi, (loss, sorted(states.items()))
    # the stated bracket, to the 3 significant digits a new sigma~ is rounded to
    assert hi / lo <= spec.sigma_auto.bracket * (1 + 2e-3), (lo, hi)
    assert all(st_ == LOST for s, st_ in states.items() if s >= loss)
    # leverage: no two neighbouring resolved sigma~ below the loss more than `spacing` apart
    rising = sorted(s for s, st_ in states.items() if st_ == RESOLVED)
    assert all(y / x <= spec.sigma_auto.spacing * (1 + 2e-3) for x, y in zip(rising, rising[1:]))
    assert not ln.limit_hit and ln.finished


@pytest.mark.slow
def test_the_search_extends_past_its_start_range_both_ways():
    spec = _spec()
    hi_line = _lines(spec, drive(spec, Truth(9.0, alpha=3, beta=0)))[(1.0,)]   # beyond 3.2
    lo_, hi_ = search.loss_bracket({s: g.state for s, g in hi_line.groups.items()})
    assert lo_ < 9.0 <= hi_ and max(hi_line.sigmas) > 3.2
    low = _lines(spec, drive(spec, Truth(0.03)))[(1.0,)]             # below 0.05: downwards
    lo_, hi_ = search.loss_bracket({s: g.state for s, g in low.groups.items()})
    assert lo_ < 0.03 <= hi_ and min(low.sigmas) < 0.05
    # no loss up to max: the line stops at max with no loss found
    never = _lines(spec, drive(spec, Truth(1e9, alpha=30, beta=0)))[(1.0,)]
    assert max(never.sigmas) == spec.sigma_auto.max
    assert all(g.state != LOST for g in never.groups.values())


@pytest.mark.slow
@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1))
def test_the_choices_do_not_depend_on_the_order_paths_finish_in(seed):
    spec = _spec(seeds={"auto": {"start": 2, "max": 6, "width": 0.1}}, k=[1.0, 0.01])
    truth = Truth(0.7, noise=0.05)
    ref = drive(spec, truth)
    got = drive(spec, truth, np.random.default_rng(seed))
    assert {p: sorted(v) for p, v in got.items()} == {p: sorted(v) for p, v in ref.items()}


def test_seeds_are_added_where_the_scatter_asks_and_stop_at_the_max():
    auto = {"auto": {"start": 3, "max": 8, "width": 0.2}}
    sigma = [0.1, 0.3]
    quiet = _spec(sigma=sigma, seeds=auto)
    ln = _lines(quiet, drive(quiet, Truth(5.0, noise=0.005)))[(1.0,)]
    assert all(g.seeds == [0, 1, 2] and g.precision.met for g in ln.groups.values())
    loud = _spec(sigma=sigma, seeds=auto)
    ln = _lines(loud, drive(loud, Truth(5.0, noise=0.4)))[(1.0,)]
    for g in ln.groups.values():
        assert g.seeds == list(range(8)) and not g.precision.met    # hit the max, still short
    mid = _spec(sigma=sigma, seeds=auto)
    ln = _lines(mid, drive(mid, Truth(5.0, noise=0.06)))[(1.0,)]
    counts = [len(g.seeds) for g in ln.groups.values()]
    assert all(3 < n < 8 for n in counts) or all(g.precision.met for g in ln.groups.values())
    assert any(n > 3 for n in counts)
    for g in ln.groups.values():       # stopped because the target was met, not at the max
        assert g.precision.met or len(g.seeds) == 8


def test_next_sigmas_rules():
    a = search.AutoSigma(start=(0.1, 1.0), bracket=1.1, spacing=2.0)
    assert search.next_sigmas(a, {0.1: RESOLVED, 1.0: RESOLVED}) == [0.316, 4.0]
    assert search.next_sigmas(a, {0.1: LOST, 1.0: LOST}) == [0.025]
    assert search.next_sigmas(a, {0.1: RESOLVED, 1.0: LOST}) == [0.316]
    assert search.next_sigmas(a, {1.0: RESOLVED, 1.05: LOST}) == []       # within 10 %
    assert search.next_sigmas(a, {20.0: RESOLVED}) == []                  # max reached


@pytest.mark.parametrize(("value", "field"), [
    ({"sigma_tilde": {"auto": {"bracket": 1.0}}}, "sigma_tilde.auto.bracket"),
    ({"sigma_tilde": {"auto": {"start": []}}}, "sigma_tilde.auto.start"),
    ({"sigma_tilde": {"auto": {"min": 2, "max": 1}}}, "sigma_tilde.auto.min"),
    ({"sigma_tilde": {"auto": {"rounds": 0}}}, "sigma_tilde.auto.rounds"),
    ({"sigma_tilde": {"auto": {"spaceing": 2}}}, "sigma_tilde.auto.spaceing"),
    ({"sigma_tilde": "automatic"}, "sigma_tilde"),
    ({"seeds": {"auto": {"max": 1}}}, "seeds.auto.max"),
    ({"seeds": {"auto": {"start": 20, "max": 10}}}, "seeds.auto.start"),
    ({"seeds": {"auto": {"width": -1}}}, "seeds.auto.width"),
    ({"seeds": {"auto": None, "x": 1}}, "seeds"),
    ({"sigma_tilde": "auto", "group_preloads": False}, "group_preloads"),
])
def test_bad_search_settings_are_one_line_and_exit_2(tmp_path, capsys, value, field):
    grid = write_grid(tmp_path, SMALL, **value)
    assert main([grid, "--dry-run"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{field}:" in err[0], err
    assert not os.path.exists(tmp_path / "search.h5")


# ------------------------------------------------------------------------------ real runs
SMALL = {"output": "search.h5",
         "scene": {"n_side": 4, "phi": 0.16, "preset": "fast",
                   "solver": {"fft_threads": 1, "max_wall_s": 120}},
         "k_tilde": [1],
         "sigma_tilde": {"auto": {"start": [0.3, 3.0], "bracket": 1.5, "rounds": 6}},
         "F_P": [0.01, 0.1, 1, 10],
         "seeds": {"auto": {"start": 2, "max": 3, "width": 0.5}}}


@pytest.fixture(scope="module")
def search_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("search")
    grid = write_grid(d, SMALL)
    assert main([grid, "--no-progress", "--serial"]) == 0
    return grid, str(d / "search.h5")


def test_a_real_search_runs_its_rounds_with_ordinary_jobs(search_run, capsys):
    grid, path = search_run
    spec = load_spec(grid)
    jobs = load_campaign(path, curves=False).jobs
    assert jobs and all(j["status"] == "done" for j in jobs)
    sigmas = sorted({j["sigma_tilde"] for j in jobs})
    assert len(sigmas) > 2                                 # it added sigma~ of its own
    for j in jobs:                                         # ordinary keys
        path_ = (j["k_tilde"], j["sigma_tilde"], j["seed"])
        assert spec.auto_task(path_, [j["preload"]]).jobs[0].key == j["key"]
    done, failed = search.results(spec, jobs)
    ln = search.replay_line(spec, (1.0,), done, failed)
    assert ln.finished and sorted(ln.sigmas) == sigmas    # replaying asks for nothing more
    assert main(["status", path]) == 0
    assert main([grid, "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "search grid" in out and f"{len(jobs)} done, 0 failed, 0 to run" in out


@pytest.mark.slow
def test_a_search_resumes_after_sigkill_with_the_same_records(search_run, tmp_path):
    _, ref = search_run
    grid = write_grid(tmp_path, SMALL)
    out = str(tmp_path / "search.h5")
    p = start([grid, "--serial", "--no-progress", "--checkpoint-s", "0"])
    t0 = time.monotonic()
    killed = False
    while time.monotonic() - t0 < 120 and p.poll() is None:
        if os.path.exists(out) and len(results_by_key(out)) >= 12:    # past round 0
            p.send_signal(signal.SIGKILL)
            killed = True
            break
        time.sleep(0.05)
    p.communicate(timeout=120)
    assert killed, "the run finished before it could be killed"
    r = run([grid, "--serial", "--no-progress"], timeout=300)
    assert r.returncode == 0, r.stderr
    a, b = results_by_key(ref), results_by_key(out)
    assert set(a) == set(b)
    assert same_numbers(a, b) == []


@pytest.mark.slow
def test_a_fixed_file_resumes_under_a_search_by_adding_rounds(search_run, tmp_path):
    _, ref = search_run
    fixed = write_grid(tmp_path, SMALL, name="fixed.yaml", sigma_tilde=[0.3, 3.0], seeds=2)
    assert main([fixed, "--no-progress", "--serial"]) == 0
    before = results_by_key(str(tmp_path / "search.h5"))
    grid = write_grid(tmp_path, SMALL)
    assert main([grid, "--no-progress", "--serial"]) == 2          # another grid: refused
    assert main([grid, "--no-progress", "--serial", "--extend"]) == 0
    after = results_by_key(str(tmp_path / "search.h5"))
    assert set(before) < set(after) and same_numbers(before, after) == []
    a = results_by_key(ref)
    assert set(a) == set(after) and same_numbers(a, after) == []


@pytest.mark.slow
def test_search_shards_merge_into_the_same_records(tmp_path):
    two = dict(SMALL, k_tilde=[1, 0.01], seeds=2)
    grid = write_grid(tmp_path, two)
    assert main([grid, "--no-progress", "--serial"]) == 0
    for s in (0, 1):
        assert main([grid, "--no-progress", "--serial", "--shard", f"{s}/2"]) == 0
    out = str(tmp_path / "all.h5")
    assert main(["merge", str(tmp_path / "search.shard-0-of-2.h5"),
                 str(tmp_path / "search.shard-1-of-2.h5"), "-o", out]) == 0
    a, b = results_by_key(str(tmp_path / "search.h5")), results_by_key(out)
    assert set(a) == set(b) and same_numbers(a, b) == []


def test_expected_sigmas_counts_the_start_and_its_bisections():
    a = search.AutoSigma(start=(0.05, 0.2, 0.8, 3.2), bracket=1.1, spacing=2.0)
    # 4 start, bisecting a factor 4 down to 1.1: 4, 2, 1.41, 1.19, 1.09 (4 halvings), and the
    # two start gaps below it halved once each to 2
    assert search.expected_sigmas(a) == 4 + 4 + 2
    b = search.AutoSigma(start=(0.1, 1.0), bracket=1.1, spacing=2.0)   # a factor 10
    assert search.expected_sigmas(b) == 2 + math.ceil(math.log2(math.log(10) / math.log(1.1)))


def test_with_f_p_auto_every_seed_of_a_group_runs_every_level():
    """F_P: auto places each path's preloads on its own (its kink, its plateau rounds): before a
    group is read its seeds are given the levels the others reached, so no level is thin."""
    spec = _spec(sigma=[0.3, 2.0], seeds=4, F_P="auto")
    assert spec.auto is not None
    truth = Truth(5.0, noise=0.05, c_noise=1.0)
    done = drive(spec, truth)
    for s in (0.3, 2.0):
        sets = {frozenset(v) for p, v in done.items() if p[1] == s}
        assert len(sets) == 1, (s, sets)
    # the paths' own rounds chose different preloads (else the test shows nothing): the levels
    # a seed holds beyond its own rounds were filled in
    from fibril_hpc.campaign.plan import auto

    own = {p: frozenset(rp.kink_tried + rp.plateau_tried)
           for p in done for rp in [auto.replay(spec.auto, done[p])]}
    assert any(len({own[p] for p in done if p[1] == s}) > 1 for s in (0.3, 2.0))
    assert any(own[p] != frozenset(v) for p, v in done.items())
