"""campaign.plan.search, pinned so that its one-line mutations fail (issue 34;
benchmarks/mutation.py): the settings and their one-line errors, the loss bracket, the next
round's sigma~ at the edges of every rule, the round limit to the exact round, the replay of a
group (its seeds, its floor, its records) and a whole search on synthetic brushes whose loss is a
*fade* (the plateau falls smoothly to the last pillars, seeds paired across sigma~) with
borderline rises that ``seeds: auto`` must settle, not a clean step."""

import hashlib
import json
import math
from functools import partial
from types import SimpleNamespace

import numpy as np
import pytest

from fibril_hpc.campaign.laws.precision import group_precision
from fibril_hpc.campaign.laws.reading import (
    FEW_PILLARS,
    LOST,
    RESOLVED,
    UNDETERMINED,
    UNRESOLVED,
    pillar_floor,
)
from fibril_hpc.campaign.plan import search
from fibril_hpc.campaign.plan.search import AutoSeeds, AutoSigma
from fibril_hpc.campaign.plan.spec import spec_from_dict
from fibril_hpc.errors import ConfigError

PRELOADS = [0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0]
FLOOR = pillar_floor(18, 0.16)


def _spec(sigma=None, seeds=3, F_P=None, **kw):
    data = {"output": "s.h5", "scene": kw.pop("scene", {"n_side": 18, "phi": 0.16}),
            "k_tilde": kw.pop("k", [1.0]),
            "sigma_tilde": sigma or {"auto": {"start": [0.2, 0.8, 3.2]}},
            "F_P": F_P or PRELOADS, "seeds": seeds, **kw}
    return spec_from_dict(data)


def _err(fn, *args, **kw) -> str:
    with pytest.raises(ConfigError) as e:
        fn(*args, **kw)
    return str(e.value)


# ------------------------------------------------------------------------------ the settings
def test_defaults_and_to_dict():
    assert search.parse_sigma("auto") == AutoSigma()
    assert search.parse_sigma({"auto": None}) == AutoSigma()
    assert search.parse_sigma({"auto": {}}) == AutoSigma()
    assert AutoSigma().to_dict() == {"start": [0.05, 0.2, 0.8, 3.2], "min": 0.01, "max": 20.0,
                                     "bracket": 1.1, "spacing": 2.0, "rounds": 12}
    assert isinstance(AutoSigma().to_dict()["start"], list)
    assert search.parse_seeds("auto") == AutoSeeds()
    assert AutoSeeds().to_dict() == {"start": 3, "max": 10, "width": 0.2}
    assert search.parse_seeds({"auto": {"max": 4}}) == AutoSeeds(3, 4, 0.2)


def test_settings_are_read_with_their_types():
    a = search.parse_sigma({"auto": {"start": [3.2, 0.05], "min": 0.02, "max": 10, "bracket": 1.2,
                                     "spacing": 3, "rounds": 5}})
    assert a == AutoSigma(start=(0.05, 3.2), min=0.02, max=10.0, bracket=1.2, spacing=3.0,
                          rounds=5)
    assert type(a.max) is float and type(a.spacing) is float and type(a.rounds) is int
    assert all(type(x) is float for x in a.start)
    s = search.parse_seeds({"auto": {"start": 2.0, "max": 6, "width": 1}})
    assert s == AutoSeeds(2, 6, 1.0) and type(s.start) is int and type(s.width) is float
    # the ends of every range are allowed
    edge = search.parse_sigma({"auto": {"start": [1e-9, 1e6], "min": 1e-9, "max": 1e6,
                                        "bracket": 1.01, "spacing": 1.05, "rounds": 1}})
    assert (edge.min, edge.max, edge.bracket, edge.spacing, edge.rounds) == (1e-9, 1e6, 1.01, 1.05, 1)
    edge = search.parse_sigma({"auto": {"bracket": 100, "spacing": 1000, "rounds": 100}})
    assert (edge.bracket, edge.spacing, edge.rounds) == (100.0, 1000.0, 100)
    assert search.parse_seeds({"auto": {"start": 2, "max": 2, "width": 0.001}}) == AutoSeeds(2, 2, 0.001)
    assert search.parse_seeds({"auto": {"start": 1000, "max": 1000, "width": 10}}) == \
        AutoSeeds(1000, 1000, 10.0)
    # the scene's range bounds min and max
    assert search.parse_sigma({"auto": {"min": 0.5, "start": [1]}}, sigma_range=(0.5, 30)).min == 0.5


NUM = "a number in [{}]"
INT = "an integer in [{}]"


@pytest.mark.parametrize(("cfg", "field", "value", "allowed"), [
    ({"min": 0}, "sigma_tilde.auto.min", "0", NUM.format("1e-09, 1e+06")),
    ({"max": 2e6}, "sigma_tilde.auto.max", "2000000.0", NUM.format("1e-09, 1e+06")),
    ({"min": True}, "sigma_tilde.auto.min", "True", NUM.format("1e-09, 1e+06")),
    ({"max": "5"}, "sigma_tilde.auto.max", "'5'", NUM.format("1e-09, 1e+06")),
    ({"min": 5, "max": 5, "start": [5]}, "sigma_tilde.auto.min", "5.0", "a number below max (5)"),
    ({"bracket": 1.0099}, "sigma_tilde.auto.bracket", "1.0099", NUM.format("1.01, 100")),
    ({"bracket": 100.5}, "sigma_tilde.auto.bracket", "100.5", NUM.format("1.01, 100")),
    ({"spacing": 1.04}, "sigma_tilde.auto.spacing", "1.04", NUM.format("1.05, 1000")),
    ({"spacing": 1001}, "sigma_tilde.auto.spacing", "1001", NUM.format("1.05, 1000")),
    ({"rounds": 0}, "sigma_tilde.auto.rounds", "0", INT.format("1, 100")),
    ({"rounds": 101}, "sigma_tilde.auto.rounds", "101", INT.format("1, 100")),
    ({"rounds": 2.5}, "sigma_tilde.auto.rounds", "2.5", INT.format("1, 100")),
    ({"rounds": True}, "sigma_tilde.auto.rounds", "True", INT.format("1, 100")),
    ({"start": []}, "sigma_tilde.auto.start", "[]",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
    ({"start": (0.1, 0.2)}, "sigma_tilde.auto.start", "(0.1, 0.2)",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
    ({"start": [0.1, 0.1]}, "sigma_tilde.auto.start", "[0.1, 0.1]",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
    ({"start": [0.1, True]}, "sigma_tilde.auto.start", "[0.1, True]",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
    ({"start": [0.1, "x"]}, "sigma_tilde.auto.start", "[0.1, 'x']",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
    ({"start": [0.009]}, "sigma_tilde.auto.start", "[0.009]",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
    ({"start": [21]}, "sigma_tilde.auto.start", "[21]",
     "a list of distinct numbers in [min, max] = [0.01, 20]"),
])
def test_a_bad_sigma_setting_is_one_line_naming_it(cfg, field, value, allowed):
    assert _err(search.parse_sigma, {"auto": cfg}) == f"{field}: got {value}; allowed: {allowed}"


def test_bad_sigma_settings_that_are_not_settings():
    assert _err(search.parse_sigma, "automatic") == ("sigma_tilde: got 'automatic'; allowed: "
                                                     "numbers, 'auto' or {auto: {settings}}")
    assert _err(search.parse_sigma, {"auto": {}, "x": 1}).startswith("sigma_tilde: got ")
    assert _err(search.parse_sigma, {"auto": 5}) == (
        "sigma_tilde.auto: got 5; allowed: a mapping of start, min, max, bracket, spacing, rounds")
    assert _err(search.parse_sigma, {"auto": {"spaceing": 2, "zzz": 1}}) == (
        "sigma_tilde.auto.spaceing: got 2; allowed: a setting (did you mean 'spacing'?): start, "
        "min, max, bracket, spacing, rounds")
    # YAML keys of any type: named as written, first by their text, never a traceback
    assert _err(search.parse_sigma, {"auto": {1: 2}}).startswith("sigma_tilde.auto.1: got 2;")
    assert _err(search.parse_sigma, {"auto": {"zz": 1, 3: 2}}).startswith("sigma_tilde.auto.3: got 2;")
    assert _err(search.parse_sigma, {"auto": {1: 2, "1": 3}}).startswith("sigma_tilde.auto.1: got 2;")
    assert _err(search.parse_seeds, {"auto": {None: 4}}).startswith("seeds.auto.None: got 4;")
    assert _err(search.parse_sigma, {"auto": {"min": 0.5}}, sigma_range=(1, 30)) == (
        "sigma_tilde.auto.min: got 0.5; allowed: a number in [1, 30]")
    assert _err(search.parse_sigma, {"auto": {"max": 31}}, sigma_range=(0.001, 30)) == (
        "sigma_tilde.auto.max: got 31; allowed: a number in [0.001, 30]")


@pytest.mark.parametrize(("cfg", "msg"), [
    ({"max": 1}, "seeds.auto.max: got 1; allowed: an integer in [2, 1000]"),
    ({"max": 1001}, "seeds.auto.max: got 1001; allowed: an integer in [2, 1000]"),
    ({"max": 4.5}, "seeds.auto.max: got 4.5; allowed: an integer in [2, 1000]"),
    ({"start": 1}, "seeds.auto.start: got 1; allowed: an integer in [2, 10]"),
    ({"start": 11}, "seeds.auto.start: got 11; allowed: an integer in [2, 10]"),
    ({"start": 20, "max": 12}, "seeds.auto.start: got 20; allowed: an integer in [2, 12]"),
    ({"width": 0.0009}, "seeds.auto.width: got 0.0009; allowed: a number in [0.001, 10]"),
    ({"width": 10.5}, "seeds.auto.width: got 10.5; allowed: a number in [0.001, 10]"),
    ({"widht": 1}, "seeds.auto.widht: got 1; allowed: a setting (did you mean 'width'?): start, "
     "max, width, first"),
    ({"first": -1}, "seeds.auto.first: got -1; allowed: an integer in [0, 1e+09]"),
    ({"first": 2.5}, "seeds.auto.first: got 2.5; allowed: an integer in [0, 1e+09]"),
])
def test_a_bad_seeds_setting_is_one_line_naming_it(cfg, msg):
    assert _err(search.parse_seeds, {"auto": cfg}) == msg


def test_a_first_seed_sets_the_labels_of_every_group():
    """seeds.auto.first: a group's seeds are first, first + 1, ... (disjoint seed sets)."""
    auto = search.parse_seeds({"auto": {"start": 3, "first": 10}})
    assert auto.first == 10 and auto.seeds(3) == [10, 11, 12] and auto.seeds(0) == []
    plain = search.parse_seeds({"auto": {"start": 3}})
    assert plain.first == 0 and plain.seeds(2) == [0, 1]


def test_seeds_that_are_not_auto_are_none_and_auto_words():
    for v in (3, [0, 1, 2], "many", {"auto": {}, "x": 1}, {}):
        assert search.parse_seeds(v) is None
    assert _err(search.parse_seeds, {"auto": [1]}) == ("seeds.auto: got [1]; allowed: a mapping "
                                                       "of start, max, width, first")
    assert search.is_auto("auto") and search.is_auto({"auto": None}) and search.is_auto({"auto": 3})
    for v in ("Auto", "automatic", {"auto": 1, "x": 2}, {}, ["auto"], 3, None):
        assert not search.is_auto(v), v


def test_settings_hash_and_round3():
    parts = ({"b": 1, "a": [1, 2]}, 3, "x")
    want = hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:16]
    assert search.settings_hash(*parts) == want and len(want) == 16
    assert search.settings_hash({"a": [1, 2], "b": 1}, 3, "x") == want       # key order
    assert search.settings_hash(4) != search.settings_hash(5)
    assert search.round3(0.123456) == 0.123 and search.round3(1234.5) == 1230.0
    assert search.round3(0.0009996) == 0.001


# ------------------------------------------------------------------------------ the grid check
def test_a_search_grid_refuses_what_it_cannot_run():
    e = _err(_spec, group_preloads=False)
    assert e == ("group_preloads: got False; allowed: true with sigma_tilde: auto (a group's seeds "
                 "are loading paths)")
    e = _err(_spec, sigma=[0.1, 0.2], seeds="auto", group_preloads=False)
    assert e.startswith("group_preloads: got False; allowed: true with seeds: auto (")
    e = _err(_spec, sweep={"k_spread": [0.1, 0.2]})
    assert e == ("sweep.k_spread: got [0.1, 0.2]; allowed: no lab-field sweep with sigma_tilde: "
                 "auto (n_side is the one field it sweeps): run one grid per value")
    e = _err(_spec, sigma=[0.1], seeds="auto", sweep={"k_spread": [0.1, 0.2]})
    assert e.startswith("sweep.k_spread: got [0.1, 0.2]; allowed: no lab-field sweep with seeds: "
                        "auto")
    # every end of the sigma~ range is a scene the grid can build (the scene allows <= 1000)
    for cfg, bad in (({"max": 2000}, "2000.0"), ({"max": 3000, "start": [1500]}, "3000.0")):
        e = _err(_spec, sigma={"auto": cfg})
        assert e == f"sigma_tilde.auto: got {bad}; allowed: a number in [0, 1000]"
    # a search grid may sweep n_side (the one field it sweeps)
    sized = _spec(scene={"phi": 0.16}, sweep={"n_side": [8, 12]})
    assert sized.lines() == [(1.0, 8), (1.0, 12)]
    assert _err(_spec, sigma={"auto": {"min": 0.1, "max": 900, "start": [1200]}}).startswith(
        "sigma_tilde.auto.start:")
    # a fixed sigma~ list with seeds: auto keeps the scene's own error
    with pytest.raises(ConfigError) as e:
        spec_from_dict({"output": "s.h5", "scene": {"n_side": 18}, "k_tilde": [1.0],
                        "sigma_tilde": [0.1], "F_P": PRELOADS, "seeds": "auto",
                        "solver": {"tol": -1}})
    assert e.value.field != "sigma_tilde.auto"


def test_check_grid_tries_the_first_preload_of_each_line_and_end(monkeypatch):
    spec = _spec(sigma={"auto": {"min": 0.05, "max": 10, "start": [0.3, 2]}}, k=[1.0, 0.1])
    calls = []
    monkeypatch.setattr(type(spec), "auto_task",
                        lambda self, path, pre: calls.append((path, tuple(pre))))
    assert search.check_grid(spec, {}, True) is spec
    assert calls == [((k, s, 0), (0.001,)) for k in (1.0, 0.1) for s in (0.05, 10.0, 0.3, 2.0)]
    fixed = _spec(sigma=[0.4, 0.9], seeds="auto", F_P="auto")
    calls.clear()
    monkeypatch.setattr(type(fixed), "auto_task",
                        lambda self, path, pre: calls.append((path, tuple(pre))))
    search.check_grid(fixed, {}, True)
    assert calls == [((1.0, s, 0), (fixed.auto.start[0],)) for s in (0.4, 0.9)]
    sized = _spec(sigma={"auto": {"min": 0.05, "max": 10, "start": [0.3]}}, scene={"phi": 0.16},
                  sweep={"n_side": [8, 12]})
    calls.clear()
    search.check_grid(sized, {"n_side": [8, 12]}, True)
    assert calls == [((1.0, s, 0, n), (0.001,)) for n in (8, 12) for s in (0.05, 10.0, 0.3)]


def test_check_grid_renames_only_a_search_grids_sigma_errors(monkeypatch):
    def raising(field):
        def task(self, path, pre):
            raise ConfigError(field, path[1], "a number in [0, 1]")
        return task

    spec = _spec(sigma={"auto": {"min": 0.05, "max": 10, "start": [0.3]}})
    monkeypatch.setattr(type(spec), "auto_task", raising("sigma_tilde"))
    assert _err(search.check_grid, spec, {}, True) == ("sigma_tilde.auto: got 0.05; allowed: a "
                                                       "number in [0, 1]")
    monkeypatch.setattr(type(spec), "auto_task", raising("F_P"))
    assert _err(search.check_grid, spec, {}, True) == "F_P: got 0.05; allowed: a number in [0, 1]"
    monkeypatch.undo()
    fixed = _spec(sigma=[0.4, 0.9], seeds="auto")
    monkeypatch.setattr(type(fixed), "auto_task", raising("sigma_tilde"))
    assert _err(search.check_grid, fixed, {}, True) == ("sigma_tilde: got 0.4; allowed: a number "
                                                        "in [0, 1]")


# ------------------------------------------------------------------------------ the choices
def test_loss_bracket():
    assert search.loss_bracket({0.1: RESOLVED, 0.2: UNRESOLVED, 0.4: LOST, 0.8: LOST}) == (0.2, 0.4)
    # a rise above the smallest lost sigma~ does not narrow it; undetermined is not alive
    assert search.loss_bracket({0.1: RESOLVED, 0.3: UNDETERMINED, 0.4: LOST, 0.6: RESOLVED}) == \
        (0.1, 0.4)
    lo, hi = search.loss_bracket({0.1: RESOLVED, 0.2: RESOLVED})
    assert lo == 0.2 and math.isnan(hi)
    lo, hi = search.loss_bracket({0.1: LOST, 0.2: RESOLVED})
    assert math.isnan(lo) and hi == 0.1
    lo, hi = search.loss_bracket({0.1: UNDETERMINED})
    assert math.isnan(lo) and math.isnan(hi)
    assert search.loss_bracket({0.5: UNRESOLVED, 0.7: LOST}) == (0.5, 0.7)


def test_next_sigmas_at_the_edge_of_every_rule():
    a = AutoSigma(start=(0.1, 1.0), min=0.01, max=20.0, bracket=1.1, spacing=2.0)
    # upwards x 4, capped at max; downwards / 4, floored at min
    assert search.next_sigmas(a, {1.0: RESOLVED, 2.0: UNRESOLVED}) == [8.0]
    assert search.next_sigmas(a, {0.5: UNRESOLVED, 1.0: UNRESOLVED, 2.0: UNRESOLVED}) == [8.0]
    assert search.next_sigmas(a, {3.0: UNRESOLVED, 6.0: UNRESOLVED}) == [20.0]
    assert search.next_sigmas(a, {0.2: LOST, 0.4: LOST}) == [0.05]
    assert search.next_sigmas(a, {0.03: LOST, 1.0: LOST}) == [0.01]
    assert search.next_sigmas(a, {0.01: LOST}) == []                      # at min: finished
    # the bracket: split while wider than 10 %, not at exactly 10 %
    assert search.next_sigmas(a, {1.0: UNRESOLVED, 1.1: LOST}) == []
    assert search.next_sigmas(a, {1.0: UNRESOLVED, 1.12: LOST}) == [1.06]
    assert search.next_sigmas(a, {0.5: UNRESOLVED, 2.0: LOST, 3.0: LOST}) == [1.0]
    # leverage: resolved neighbours below the loss more than `spacing` apart, not exactly 2
    assert search.next_sigmas(a, {0.1: RESOLVED, 0.2: RESOLVED, 0.21: LOST}) == []
    assert search.next_sigmas(a, {0.1: RESOLVED, 0.201: RESOLVED, 0.21: LOST}) == [0.142]
    # only resolved rises give leverage, and only below the loss
    assert search.next_sigmas(a, {0.1: UNRESOLVED, 0.3: UNRESOLVED, 0.31: LOST}) == []
    assert search.next_sigmas(a, {0.1: RESOLVED, 0.3: UNRESOLVED, 0.31: LOST, 0.5: RESOLVED,
                                  2.0: RESOLVED}) == []
    # without a loss every resolved pair counts
    assert search.next_sigmas(a, {0.1: RESOLVED, 1.0: RESOLVED}) == [0.316, 4.0]
    # a new sigma~ that rounds onto one tried is not new; outside [min, max] not run
    fine = AutoSigma(start=(1.0,), bracket=1.01)
    assert search.next_sigmas(fine, {1.0: RESOLVED, 1.0201: LOST}) == [1.01]
    assert search.next_sigmas(fine, {1.0: RESOLVED, 1.0104: UNDETERMINED, 1.0201: LOST}) == []
    b = AutoSigma(start=(0.1,), min=0.05, max=0.3, bracket=1.1, spacing=1.5)
    assert search.next_sigmas(b, {0.05: RESOLVED, 0.3: RESOLVED}) == [0.122]
    # sorted, three digits
    assert search.next_sigmas(a, {0.01: RESOLVED, 0.1: RESOLVED, 1.0: RESOLVED, 1.5: LOST}) == \
        [0.0316, 0.316, 1.22]


def _halvings(ratio, target):
    k = 0
    while ratio > target:
        ratio, k = math.sqrt(ratio), k + 1
    return k


@pytest.mark.parametrize(("start", "bracket", "spacing"), [
    ((0.05, 0.2, 0.8, 3.2), 1.1, 2.0), ((0.1, 1.0), 1.1, 2.0), ((1.0,), 1.1, 2.0),
    ((0.1, 0.2, 1.0), 1.1, 2.0), ((0.1, 0.2, 1.0), 1.1, 1.5), ((0.1, 0.5, 0.6), 1.5, 1.3),
    ((0.1, 0.15), 1.5, 2.0), ((0.2, 0.1, 0.8), 1.2, 3.0),
])
def test_expected_sigmas_counts_bisections(start, bracket, spacing):
    s = sorted(start)
    gaps = [y / x for x, y in zip(s, s[1:])] or [4.0]
    want = len(s) + _halvings(max(gaps), bracket) + sum(2 ** _halvings(g, spacing) - 1
                                                       for g in gaps[:-1])
    assert search.expected_sigmas(AutoSigma(start=start, bracket=bracket, spacing=spacing)) == want


def test_expected_sigmas_hand_counts():
    assert search.expected_sigmas(AutoSigma(start=(1.0,), bracket=1.1)) == 1 + 4
    assert search.expected_sigmas(AutoSigma(start=(0.1, 0.2, 1.0), bracket=1.1, spacing=1.5)) == 3 + 5 + 1
    assert search.expected_sigmas(AutoSigma(start=(0.1, 0.15), bracket=1.5)) == 2
    assert search.expected_sigmas(AutoSigma(start=(0.1, 0.4, 0.5), bracket=1.1, spacing=2.0)) == 3 + 4 + 1


# ------------------------------------------------------------------------------ the round limit
def _fake_line(monkeypatch, loss, start=(0.2, 0.8, 3.2), rounds=12, todo_at=None):
    """replay_line on a fake line whose groups are finished (lost from ``loss`` on) without
    records; ``todo_at``: a sigma~ whose group still runs."""
    calls = []

    def fake(spec, line, s, done, failed, retry_failed=False, cache=None):
        calls.append(s)
        todo = [("path", [1.0])] if s == todo_at else []
        return search.Group(s, [0], todo, "" if todo else (LOST if s >= loss else RESOLVED))

    monkeypatch.setattr(search, "replay_group", fake)
    spec = SimpleNamespace(sigma_auto=AutoSigma(start=start, rounds=rounds))
    return search.replay_line(spec, (1.0,), {}, {}), calls


ROUNDS = [[0.2, 0.8, 3.2], [0.4, 1.6], [1.13], [0.951], [1.04]]     # a loss at sigma~ = 1


@pytest.mark.parametrize("rounds", [1, 2, 3, 4, 5, 6, 12])
def test_the_round_limit_is_exact(monkeypatch, rounds):
    ln, calls = _fake_line(monkeypatch, 1.0, rounds=rounds)
    assert ln.line == (1.0,)
    ran = min(rounds, len(ROUNDS))
    assert ln.sigmas == [s for r in ROUNDS[:ran] for s in r]
    assert ln.rounds == ran - 1
    assert ln.limit_hit == (rounds < len(ROUNDS))
    assert sorted(calls) == sorted(ln.sigmas) and len(calls) == len(set(calls))   # each once
    assert ln.finished and ln.todo == []


def test_a_round_waits_for_every_group_and_a_fixed_grid_has_one(monkeypatch):
    ln, calls = _fake_line(monkeypatch, 1.0, todo_at=0.8)
    assert ln.sigmas == [0.2, 0.8, 3.2] and ln.rounds == 0 and not ln.limit_hit
    assert ln.todo == [("path", [1.0])] and not ln.finished
    assert ln.groups[0.8].todo and not ln.groups[0.8].finished and ln.groups[0.2].finished

    def fake(spec, line, s, done, failed, retry_failed=False, cache=None):
        return search.Group(s, [0], [], RESOLVED)

    monkeypatch.setattr(search, "replay_group", fake)
    spec = SimpleNamespace(sigma_auto=None, sigma_tilde=(0.3, 0.6))
    ln = search.replay_line(spec, (1.0,), {}, {})
    assert ln.sigmas == [0.3, 0.6] and ln.rounds == 0 and set(ln.groups) == {0.3, 0.6}


def test_the_start_is_rounded_to_three_digits(monkeypatch):
    ln, _ = _fake_line(monkeypatch, 100.0, start=(0.12345, 0.5), rounds=1)
    assert ln.sigmas == [0.123, 0.5] and ln.limit_hit


# ------------------------------------------------------------------------------ records
def test_results_keep_the_grids_done_and_failed_records():
    spec = _spec(sigma=[0.2], seeds=2)
    rec = {"preload_kind": "F_P", "k_tilde": 1.0, "sigma_tilde": 0.2, "seed": 1, "status": "done",
           "preload": 0.25, "F_P": 0.3, "F_A": 0.1}
    recs = [rec, dict(rec, preload=1.0, status="failed"), dict(rec, preload_kind="d_tilde"),
            dict(rec, seed=7), {"preload_kind": "F_P", "status": "done"},
            dict(rec, sigma_tilde="x"), dict(rec, seed=0, preload=4, F_P=4.1, F_A=0.2)]
    path = spec.record_path(rec)
    done, failed = search.results(spec, recs)
    assert done == {path: {0.25: (0.3, 0.1)},
                    spec.record_path(dict(rec, seed=0)): {4.0: (4.1, 0.2)}}
    assert failed == {path: {1.0}}
    assert all(type(v) is float for d in done.values() for k, xy in d.items() for v in (k, *xy))


def test_path_preloads_and_the_first_frontier():
    spec = _spec(sigma=[0.2, 0.4], seeds=2)
    assert search.path_preloads(spec, {}, ()) == PRELOADS
    assert search.path_preloads(spec, {0.001: (0, 0)}, {0.004}) == PRELOADS[2:]
    assert search.path_preloads(spec, {0.001: (0, 0)}, {0.004}, retry_failed=True) == PRELOADS[1:]
    front = search.frontier(spec, [])
    assert front == [((1.0, s, d), PRELOADS) for s in (0.2, 0.4) for d in (0, 1)]
    auto = _spec(sigma={"auto": {"start": [0.3, 3.0]}}, seeds={"auto": {"start": 2, "max": 4}},
                 F_P="auto")
    front = search.frontier(auto, [])
    assert front == [((1.0, s, d), list(auto.auto.start)) for s in (0.3, 3.0) for d in (0, 1)]
    got = search.path_preloads(auto, {}, (), False)
    assert got == list(auto.auto.start)


class Fade:
    """A synthetic brush whose adhesion fades: the plateau falls smoothly, P(sigma~) =
    min(top, LOSS (sigma_c/sigma~)^fade) pillars' pull-off, through the loss threshold at
    ``sigma_c`` down to the last pillar (a floor below which F~_A never goes); c follows
    alpha/sigma~ - beta where it is positive. A seed is one height pattern at every sigma~: its
    deviates (plateau, c) are the same at every sigma~ (paired seeds), and F~_A creeps at the
    few-pillar end like real data, never a clean step."""

    def __init__(self, sigma_c, fade=2.0, top=1.0, alpha=0.5, beta=0.05, P_sd=0.03,
                 pillar_sd=0.5, c_sd=0.1):
        self.sigma_c, self.fade, self.top = sigma_c, fade, top
        self.alpha, self.beta, self.P_sd, self.c_sd = alpha, beta, P_sd, c_sd
        self.pillar_sd = pillar_sd

    def plateau(self, s):
        return max(FLOOR, min(self.top, FEW_PILLARS * FLOOR * (self.sigma_c / s) ** self.fade))

    def rel_sd(self, s):
        """A plateau of few pillars scatters most: P_sd + pillar_sd / sqrt(pillars) (0.32 at
        3 pillars with the defaults; real 18 x 18 groups there: 2.4-5.5 pillars over 10 seeds)."""
        return self.P_sd + self.pillar_sd / math.sqrt(self.plateau(s) / FLOOR)

    def __call__(self, path, p):
        s, seed = path[1], path[2]
        zp, zc = np.random.default_rng([seed, 1]).standard_normal(2)
        P = self.plateau(s) * max(0.2, 1 + self.rel_sd(s) * zp)
        c = max(self.alpha / s - self.beta, 10 * P) * math.exp(self.c_sd * zc)
        return p, max(FLOOR * (1 + 0.02 * zp), min(c * p, P))


@pytest.fixture
def quick_bootstrap(monkeypatch):
    """The planner's reading with 50 bootstrap resamples instead of 200: these tests are of the
    search's choices, not of the bootstrap's resolution (tests/test_mutants_precision.py), and
    mutation testing runs them once per mutant."""
    monkeypatch.setattr(search, "group_precision", partial(group_precision, n_boot=50))


def drive(spec, truth, cache=True):
    done: dict = {}
    c: dict | None = {} if cache else None
    for _ in range(1000):
        todo = search.frontier_of(spec, done, {}, cache=c)
        if not todo:
            return done
        for path, pre in todo:
            for p in pre:
                done.setdefault(path, {})[p] = truth(path, p)
    raise AssertionError("the search never finished")


def test_a_search_over_a_fade_brackets_where_the_mean_plateau_crosses_three_pillars(
        quick_bootstrap):
    """The plateau fades through 3 pillars at sigma_c = 0.9 and scatters most there: the
    group just past the threshold is uncertain at 3 seeds and grows to the maximum, the lost
    ones far from it stay at 3; the bracket is where these seeds'
    mean crosses, here holding the truth's crossing."""
    truth = Fade(0.9)
    auto = {"auto": {"start": 3, "max": 8, "width": 0.5}}
    spec = _spec(sigma={"auto": {"start": [0.2, 0.8, 3.2], "rounds": 8}}, seeds=auto)
    done = drive(spec, truth)
    ln = search.replay_line(spec, (1.0,), done, {})
    states = {s: g.state for s, g in ln.groups.items()}
    lo, hi = search.loss_bracket(states)
    assert ln.finished and not ln.limit_hit and hi / lo <= 1.1 * (1 + 2e-3)
    assert lo < truth.sigma_c <= hi, (lo, hi)
    assert ln.sigmas == [0.2, 0.8, 3.2, 0.4, 1.6, 1.13, 0.951, 0.872]
    seeds = {s: len(g.seeds) for s, g in ln.groups.items()}
    assert seeds[hi] == 8 and ln.groups[hi].precision.short in ((), ("state",))  # borderline
    assert seeds[1.6] == seeds[3.2] == seeds[1.13] == 3           # certainly lost
    assert all(g.sigma == s for s, g in ln.groups.items())
    for g in ln.groups.values():
        # every group stopped because it was certain and precise, or at the maximum
        assert g.precision.met or len(g.seeds) == 8
        assert g.seeds == list(range(len(g.seeds)))
        if g.state == LOST:
            assert "plateau" not in g.precision.short and "c" not in g.precision.short


def test_a_borderline_rise_grows_seeds_until_its_state_is_certain(quick_bootstrap):
    """Groups whose true plateau is 2.8 and 3.0 pillars (32 % seed scatter there): read as
    rising at 3 seeds, but their intervals straddle the threshold, so ``seeds: auto`` adds seeds
    (doubling: the state has no width to scale) whatever the plateau's and c's widths say; at 12
    the 2.8-pillar one reads lost, and neither is certain: both stop at the maximum."""
    truth = Fade(1.0, c_sd=0.02)
    for pillars, final in ((2.8, LOST), (3.0, RESOLVED)):
        s = search.round3(truth.sigma_c / (pillars / 3) ** (1 / truth.fade))
        spec = _spec(sigma=[s], seeds={"auto": {"start": 3, "max": 12, "width": 10.0}})
        done = drive(spec, truth)
        g = search.replay_line(spec, (1.0,), done, {}).groups[s]
        for n in (3, 6):
            first = search.group_precision(*search._points(done, [(1.0, s, d) for d in range(n)]),
                                           floor=FLOOR, width=10.0)
            assert first.short == ("state",), (pillars, n)
            assert n == 6 or first.state == RESOLVED
        assert g.seeds == list(range(12)) and sorted({p[2] for p in done}) == list(range(12))
        assert g.state == final and g.precision.short == ("state",)


def test_replay_group_reads_with_the_lines_floor_and_the_grids_width():
    truth = Fade(0.5)
    spec = _spec(sigma=[0.3], seeds=3, scene={"phi": 0.2}, sweep={"n_side": [8, 12]})
    line = (1.0, 8)                      # the smaller brush: not the base scene's 12
    done = {}
    for d in range(3):
        path = (1.0, 0.3, d, 8)
        done[path] = {p: truth(path, p) for p in PRELOADS}
    g = search.replay_group(spec, line, 0.3, done, {})
    assert g.finished and g.seeds == [0, 1, 2] and g.todo == []
    pts = search._points(done, [(1.0, 0.3, d, 8) for d in range(3)])
    want = group_precision(*pts, floor=pillar_floor(8, 0.2), width=0.2)
    assert g.precision == want and g.state == want.state
    assert g.precision.threshold == FEW_PILLARS * pillar_floor(8, 0.2)
    # a missing level is run first; a failed one is not rerun unless asked
    part = {p: dict(v) for p, v in done.items()}
    del part[(1.0, 0.3, 1, 8)][1.0]
    g = search.replay_group(spec, line, 0.3, part, {})
    assert g.todo == [((1.0, 0.3, 1, 8), [1.0])] and g.state == ""
    assert g.sigma == 0.3 and g.seeds == [0, 1, 2] and not g.finished
    g = search.replay_group(spec, line, 0.3, part, {(1.0, 0.3, 1, 8): {1.0}})
    assert g.finished
    g = search.replay_group(spec, line, 0.3, part, {(1.0, 0.3, 1, 8): {1.0}}, retry_failed=True)
    assert g.todo == [((1.0, 0.3, 1, 8), [1.0])]
    # a fixed seed count is judged against a width of 0.2: c's 0.79 is short
    rise = {(1.0, 0.2, d, 8): {p: truth((1.0, 0.2, d, 8), p) for p in PRELOADS} for d in range(3)}
    g = search.replay_group(spec, line, 0.2, rise, {})
    assert g.sigma == 0.2 and g.state == RESOLVED and g.precision.short == ("c",)
    assert 0.2 < g.precision.widths[0] < 1.0
    ln = search.replay_line(spec, line, part, {(1.0, 0.3, 1, 8): {1.0}})
    assert ln.finished
    ln = search.replay_line(spec, line, part, {(1.0, 0.3, 1, 8): {1.0}}, True)
    assert ln.todo == [((1.0, 0.3, 1, 8), [1.0])]


def test_points_are_floats_whatever_the_records_hold():
    seed, pre, x, y = search._points({(1.0, 0.2, 0): {1: (2, 3)}}, [(1.0, 0.2, 0)])
    assert seed.tolist() == [0] and pre.dtype == x.dtype == y.dtype == np.float64


def test_points_are_every_done_job_of_the_paths_in_order():
    done = {(1.0, 0.2, 0): {0.5: (0.6, 0.1), 0.1: (0.2, 0.05)}, (1.0, 0.2, 1): {0.1: (0.3, 0.07)},
            (1.0, 0.4, 0): {0.1: (9.0, 9.0)}}
    seed, pre, x, y = search._points(done, [(1.0, 0.2, 0), (1.0, 0.2, 1), (1.0, 0.2, 2)])
    assert seed.tolist() == [0, 0, 1] and pre.tolist() == [0.1, 0.5, 0.1]
    assert x.tolist() == [0.2, 0.6, 0.3] and y.tolist() == [0.05, 0.1, 0.07]
    assert pre.dtype == float and x.dtype == float and y.dtype == float


def test_thin_levels_give_every_seed_the_levels_any_seed_reached():
    spec = _spec(sigma=[0.2], seeds=3, F_P="auto")
    a, b, c = [(1.0, 0.2, d) for d in range(3)]
    done = {a: {0.1: (0.1, 0.1), 1.0: (1, 1)}, b: {0.1: (0.1, 0.1), 4.0: (4, 1)}, c: {0.1: (0.1, 0.1)}}
    got = search._thin_levels(spec, [a, b, c], done, {})
    assert got == [(a, [4.0]), (b, [1.0]), (c, [1.0, 4.0])]
    got = search._thin_levels(spec, [a, b, c], done, {c: {4.0}})
    assert got == [(a, [4.0]), (b, [1.0]), (c, [1.0])]
    got = search._thin_levels(spec, [a, b, c], done, {c: {4.0}}, retry_failed=True)
    assert got[-1] == (c, [1.0, 4.0])
    assert search._thin_levels(spec, [a, b], {a: {0.1: (0, 0)}, b: {0.1: (0, 0)}}, {}) == []
    assert search._thin_levels(spec, [a, c], {a: {0.1: (0, 0)}}, {}) == [(c, [0.1])]   # none yet
    assert search._thin_levels(_spec(sigma=[0.2]), [a, b, c], done, {}) == []


def test_seeds_stop_at_the_max_and_a_fixed_count_never_grows(quick_bootstrap):
    truth = Fade(0.2, P_sd=0.5, c_sd=0.5)
    spec = _spec(sigma=[0.1], seeds={"auto": {"start": 2, "max": 3, "width": 0.01}})
    done = drive(spec, truth)
    g = search.replay_line(spec, (1.0,), done, {}).groups[0.1]
    assert g.seeds == [0, 1, 2] and not g.precision.met
    # the cache is a cache: the same records and choices without it
    assert drive(spec, truth, cache=False) == done
    fixed = _spec(sigma=[0.1], seeds=2)
    done = drive(fixed, truth)
    g = search.replay_line(fixed, (1.0,), done, {}).groups[0.1]
    assert g.seeds == [0, 1] and not g.precision.met and sorted(done) == [(1.0, 0.1, 0), (1.0, 0.1, 1)]


def test_the_frontier_of_a_file_with_failed_jobs_reruns_them_only_when_asked():
    spec = _spec(sigma=[0.2], seeds=2)
    rec = {"preload_kind": "F_P", "k_tilde": 1.0, "sigma_tilde": 0.2, "seed": 0, "status": "done",
           "F_P": 0.0, "F_A": 0.0}
    recs = [dict(rec, seed=d, preload=p, F_P=p, F_A=min(p, 1.0)) for d in (0, 1) for p in PRELOADS]
    recs[-1] = dict(recs[-1], status="failed")
    path = (1.0, 0.2, 1)
    assert search.frontier(spec, recs) == []
    assert search.frontier(spec, recs, True) == [(path, [PRELOADS[-1]])]
    assert search.frontier(spec, recs, retry_failed=True) == [(path, [PRELOADS[-1]])]
    done, failed = search.results(spec, recs)
    assert search.frontier_of(spec, done, failed) == []
    assert search.frontier_of(spec, done, failed, True) == [(path, [PRELOADS[-1]])]


def test_path_preloads_of_f_p_auto_pass_the_failed_preloads_on():
    auto = _spec(sigma=[0.3], seeds=2, F_P="auto")
    start = list(auto.auto.start)
    res = {p: (p, min(p, 1.0)) for p in start[1:]}
    nxt = search.path_preloads(auto, res, {start[0]})
    assert nxt and start[0] not in nxt                                   # on to the next round
    assert search.path_preloads(auto, res, {start[0]}, True) == [start[0]]
    assert search.path_preloads(auto, res, set()) == [start[0]]


def test_a_cache_passed_is_filled_and_read(quick_bootstrap, monkeypatch):
    spec = _spec(sigma=[0.2, 0.4], seeds=2)
    done = drive(spec, Fade(0.5))
    cache: dict = {}
    a = search.frontier_of(spec, done, {}, cache=cache)
    assert a == [] and len(cache) == 2
    monkeypatch.setattr(search, "group_precision", None)     # read from the cache only
    assert search.frontier_of(spec, done, {}, cache=cache) == []
    ln = search.replay_line(spec, (1.0,), done, {}, cache=cache)
    assert sorted(map(id, (g.precision for g in ln.groups.values()))) == sorted(map(id, cache.values()))
    monkeypatch.undo()
    # other records of the same size are read anew, not taken from the cache
    other = {p: {q: (fp, 0.9 * fa) for q, (fp, fa) in v.items()} for p, v in done.items()}
    partial_nb = partial(group_precision, n_boot=50)
    monkeypatch.setattr(search, "group_precision", partial_nb)
    got = search.replay_line(spec, (1.0,), other, {}, cache=cache)
    ref = search.replay_line(spec, (1.0,), other, {})
    assert [g.precision for g in got.groups.values()] == [g.precision for g in ref.groups.values()]
    assert len(cache) == 4


def test_with_f_p_auto_every_seed_of_a_group_runs_every_level(quick_bootstrap):
    """F_P: auto places each path's preloads on its own; before a group is read its seeds are
    given the levels the others reached, so no level is thin (as tests/test_campaign_search.py,
    on a fade's group)."""
    from fibril_hpc.campaign.plan import auto

    spec = _spec(sigma=[0.3], seeds=3, F_P="auto")

    def truth(path, p):                    # each seed its own kink: different preload rounds
        c = 2.0 * math.exp(np.random.default_rng([path[2], 3]).standard_normal())
        return p, min(c * p, 1.0)

    done = drive(spec, truth)
    assert len({frozenset(v) for v in done.values()}) == 1
    own = {p: frozenset(rp.kink_tried + rp.plateau_tried)
           for p in done for rp in [auto.replay(spec.auto, done[p])]}
    assert len(set(own.values())) > 1 and any(own[p] != frozenset(v) for p, v in done.items())
    # a filled-in level that failed is not run again unless asked
    p0 = next(p for p in sorted(done) if own[p] != frozenset(done[p]))
    extra = sorted(frozenset(done[p0]) - own[p0])[0]
    part = {p: dict(v) for p, v in done.items()}
    del part[p0][extra]
    g = search.replay_group(spec, (1.0,), 0.3, part, {})
    assert g.todo == [(p0, [extra])] and g.sigma == 0.3 and g.seeds == [0, 1, 2] and g.state == ""
    assert search.replay_group(spec, (1.0,), 0.3, part, {p0: {extra}}).finished
    g = search.replay_group(spec, (1.0,), 0.3, part, {p0: {extra}}, retry_failed=True)
    assert g.todo == [(p0, [extra])]
