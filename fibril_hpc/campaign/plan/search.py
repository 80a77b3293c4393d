"""``sigma_tilde: auto`` and ``seeds: auto``: the campaign places roughnesses and seeds itself.

The critical roughness sigma~_c of a stiffness is where adhesion is lost; a fixed sigma~ list
brackets it only as finely as the list is dense, and a fixed seed count is too many for some
groups and too few for others. A *search grid* lets the campaign decide, from its own records,
read exactly as the report reads them (:func:`.laws.reading.read_group`,
:func:`.laws.precision.group_precision`):

**A line** is one k~ (and one brush size where the grid sweeps ``n_side``); its sigma~ are run in
*rounds*. Round 0 runs ``start``. When every group of a round is finished (every seed's loading
path, with its own ``F_P: auto`` rounds, and the seeds ``seeds: auto`` adds), the line's states
decide the next round (:func:`next_sigmas`):

* no sigma~ lost adhesion: the largest x 4 (not above ``max``): search upwards;
* the smallest sigma~ already lost: the smallest / 4 (not below ``min``);
* else the *loss bracket* (the largest sigma~ still holding adhesion below the smallest lost
  one, that lost one) wider than ``bracket`` (hi/lo; 1.1 is 10 %): its middle in log sigma~;
* and *leverage*: c = alpha/sigma~ - beta is fitted to the groups whose rise is resolved; where
  two neighbouring ones lie more than ``spacing`` apart (a factor in sigma~) below the loss, the
  fit has no point to hold it there: their middle in log sigma~ is added too.

The line is finished when a round adds nothing, or after ``rounds`` rounds. New sigma~ are
rounded to three significant digits (a bracket narrower than that cannot be split).

**A group** (k~, sigma~) runs seeds ``first`` .. ``first`` + ``start`` - 1 (``first`` 0 unless
given); with ``seeds: auto``, when they are finished, :func:`.laws.precision.seeds_needed` says
whether its plateau and c are known within ``width`` (and a lost group's state with certainty)
or how many seeds would do; the group grows to that count (seeds ``first`` .. ``first`` + n - 1,
at most ``max`` of them) and is read again. Two runs of one grid with ``first`` 0 and ``first``
>= the first run's ``max`` use disjoint seeds (independent brushes). With ``F_P: auto`` every path
places its own preloads; before a group is read, each seed also runs the preloads any other seed
of the group reached, so that every level holds every seed (a level some seeds lack is *thin*:
the report shows it but does not read it, and a plateau round run by a few seeds would leave the
plateau unread).

Every choice is a function of the line's records only, and every job is an ordinary job with the
ordinary key (its single-preload scene's hash), so a resumed campaign (after SIGKILL too) replays
the same rounds from its records and runs exactly what an uninterrupted run would; a campaign
run with fixed lists resumes under a search grid whose ``start`` holds its sigma~ and seed count
by adding rounds (``--extend``).
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ...errors import ConfigError, unknown_key
from ..laws.precision import group_precision, seeds_needed
from ..laws.reading import LOST, RESOLVED, UNRESOLVED, pillar_floor
from .auto import path_todo

AUTO_WORD = "auto"
#: the largest first seed of ``seeds: auto`` (its seeds run to first + max - 1)
FIRST_MAX = 10**9


@dataclass(frozen=True)
class AutoSigma:
    """Settings of ``sigma_tilde: auto`` (module text)."""

    start: tuple = (0.05, 0.2, 0.8, 3.2)
    min: float = 0.01
    max: float = 20.0
    bracket: float = 1.1
    spacing: float = 2.0
    rounds: int = 12

    def to_dict(self) -> dict:
        """The settings as a plain mapping (as written in the resolved grid)."""
        d = asdict(self)
        d["start"] = list(self.start)
        return d


@dataclass(frozen=True)
class AutoSeeds:
    """Settings of ``seeds: auto``: ``start`` seeds per group, more (at most ``max``) until the
    seed intervals of plateau and c are within ``width`` of their value (full width); the
    seeds are ``first``, ``first`` + 1, ... (``first`` 0 by default: a disjoint seed set of the
    same grid starts at ``first`` = the other set's ``max``)."""

    start: int = 3
    max: int = 10
    width: float = 0.2
    first: int = 0

    def to_dict(self) -> dict:
        """The settings as a plain mapping (as written in the resolved grid); ``first`` only
        when it is not 0, so that a grid written before it had ``first`` keeps its hash."""
        d = asdict(self)
        if not self.first:
            d.pop("first")
        return d

    def seeds(self, n: int) -> list:
        """The first ``n`` seeds of a group."""
        return list(range(self.first, self.first + n))


def _settings(field_name: str, value, cls):
    """``auto`` or ``{auto: {...}}`` -> (a copy of the defaults updated, the defaults)."""
    if value == AUTO_WORD:
        return cls().to_dict()
    if not (isinstance(value, dict) and list(value) == [AUTO_WORD]):
        return None
    cfg = value[AUTO_WORD] or {}
    names = tuple(cls.__dataclass_fields__)
    if not isinstance(cfg, dict):
        raise ConfigError(f"{field_name}.auto", cfg, "a mapping of " + ", ".join(names))
    unknown = sorted((k for k in cfg if str(k) not in names), key=str)   # YAML keys: any type
    if unknown:
        raise unknown_key(f"{field_name}.auto.{unknown[0]}", cfg[unknown[0]], names, "a setting")
    d = cls().to_dict()
    d.update(cfg)
    return d


def _num(where: str, v, lo, hi, integer=False):
    ok = isinstance(v, (int, float)) and not isinstance(v, bool) and lo <= v <= hi
    if not ok or (integer and int(v) != v):
        kind = "an integer" if integer else "a number"
        raise ConfigError(where, v, f"{kind} in [{lo:g}, {hi:g}]")
    return int(v) if integer else float(v)


def is_auto(value) -> bool:
    """Whether a grid value asks for the search (``auto`` or ``{auto: ...}``)."""
    return value == AUTO_WORD or (isinstance(value, dict) and list(value) == [AUTO_WORD])


def parse_sigma(value, sigma_range=(1e-9, 1e6)) -> AutoSigma:
    """``sigma_tilde: auto`` or ``{auto: {...}}`` -> :class:`AutoSigma`; one-line ConfigError
    naming the setting otherwise. ``sigma_range``: the scene's allowed sigma~."""
    d = _settings("sigma_tilde", value, AutoSigma)
    if d is None:
        raise ConfigError("sigma_tilde", value, "numbers, 'auto' or {auto: {settings}}")
    lo, hi = sigma_range
    mn = _num("sigma_tilde.auto.min", d["min"], lo, hi)
    mx = _num("sigma_tilde.auto.max", d["max"], lo, hi)
    if mn >= mx:
        raise ConfigError("sigma_tilde.auto.min", mn, f"a number below max ({mx:g})")
    start = d["start"]
    if not isinstance(start, list) or not start or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and mn <= x <= mx
            for x in start) or len(set(start)) != len(start):
        raise ConfigError("sigma_tilde.auto.start", start,
                          f"a list of distinct numbers in [min, max] = [{mn:g}, {mx:g}]")
    return AutoSigma(start=tuple(sorted(float(x) for x in start)), min=mn, max=mx,
                     bracket=_num("sigma_tilde.auto.bracket", d["bracket"], 1.01, 100.0),
                     spacing=_num("sigma_tilde.auto.spacing", d["spacing"], 1.05, 1e3),
                     rounds=_num("sigma_tilde.auto.rounds", d["rounds"], 1, 100, True))


def parse_seeds(value) -> AutoSeeds | None:
    """``seeds: auto`` or ``{auto: {...}}`` -> :class:`AutoSeeds`; None for a count or list."""
    d = _settings("seeds", value, AutoSeeds)
    if d is None:
        return None
    mx = _num("seeds.auto.max", d["max"], 2, 1000, True)
    start = _num("seeds.auto.start", d["start"], 2, mx, True)
    return AutoSeeds(start=start, max=mx,
                     width=_num("seeds.auto.width", d["width"], 0.001, 10.0),
                     first=_num("seeds.auto.first", d.get("first", 0), 0, FIRST_MAX, True))


def settings_hash(*parts) -> str:
    """Short SHA-256 of a search grid's settings (part of its campaign hash)."""
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:16]


def round3(x: float) -> float:
    """``x`` to three significant digits (the sigma~ a round adds)."""
    return float(f"{x:.3g}")


def check_grid(spec, sweep: dict, group: bool):
    """A search grid: refuse what it cannot run, in one line naming the field,
    and validate every line's scene at the ends of its sigma~ range and its preloads."""
    where = "sigma_tilde" if spec.sigma_auto is not None else "seeds"
    if not group:
        raise ConfigError("group_preloads", group, f"true with {where}: auto (a group's seeds "
                          "are loading paths)")
    lab = [name for name in sweep if name != "n_side"]
    if lab:
        raise ConfigError(f"sweep.{lab[0]}", list(sweep[lab[0]]), f"no lab-field sweep with "
                          f"{where}: auto (n_side is the one field it sweeps): run one grid per "
                          "value")
    a = spec.sigma_auto
    ends = (a.min, a.max) + tuple(a.start) if a is not None else spec.sigma_tilde
    pre = spec.auto.start if spec.auto is not None else spec.preloads
    for line in spec.lines():
        for s in ends:
            try:
                spec.auto_task((line[0], s, 0) + tuple(line[1:]), pre[:1])
            except ConfigError as exc:
                if exc.field != "sigma_tilde" or a is None:
                    raise
                raise ConfigError("sigma_tilde.auto", s, exc.allowed) from None
    return spec


# ------------------------------------------------------------------------------ the choices
def loss_bracket(states: dict) -> tuple:
    """(lo, hi) of a line's states {sigma~: state}: hi the smallest lost sigma~, lo the largest
    sigma~ below it still holding adhesion (rise resolved or not resolved); NaN where absent."""
    lost = [s for s, st in states.items() if st == LOST]
    hi = min(lost) if lost else math.nan
    alive = [s for s, st in states.items() if st in (RESOLVED, UNRESOLVED)
             and not (s >= hi)]
    return (max(alive) if alive else math.nan), hi


def next_sigmas(a: AutoSigma, states: dict) -> list:
    """The sigma~ of a line's next round from its finished groups' states {sigma~: state}
    (module text); empty: the line is finished."""
    tried = sorted(states)
    lo, hi = loss_bracket(states)
    new = []
    if not math.isfinite(hi):
        new.append(min(tried[-1] * 4.0, a.max))
    elif not math.isfinite(lo):
        new.append(max(tried[0] / 4.0, a.min))
    elif hi / lo > a.bracket:
        new.append(math.sqrt(lo * hi))
    top = hi if math.isfinite(hi) else math.inf
    rising = sorted(s for s, st in states.items() if st == RESOLVED and s < top)
    new += [math.sqrt(x * y) for x, y in zip(rising, rising[1:]) if y / x > a.spacing]
    have = {round3(s) for s in tried}
    return sorted({round3(s) for s in new if a.min <= s <= a.max} - have)


def expected_sigmas(a: AutoSigma) -> int:
    """How many sigma~ a line of ``sigma_tilde: auto`` typically runs when the loss lies inside
    the start range: the start, the bisections of one start gap down to ``bracket``, and the
    bisections of the start gaps below it down to ``spacing`` (what ``--dry-run`` prices)."""
    s = sorted(a.start)
    gaps = [y / x for x, y in zip(s, s[1:])] or [4.0]

    def halvings(ratio, target):
        return max(0, math.ceil(math.log2(math.log(ratio) / math.log(target)))) if ratio > target else 0

    fills = sum(2 ** halvings(g, a.spacing) - 1 for g in gaps[:-1])
    return len(s) + halvings(max(gaps), a.bracket) + fills


# ------------------------------------------------------------------------------ the replay
@dataclass
class Group:
    """One (k~, sigma~) of a line, replayed: its seeds, what its paths still run, its state."""

    sigma: float
    seeds: list
    todo: list                       # [(path, preloads)] to run now
    state: str = ""                  # the reading's state once finished
    precision: object = None         # :class:`.laws.precision.Precision` (seeds: auto)

    @property
    def finished(self) -> bool:
        """Every path of the group has run (its state is read)."""
        return not self.todo


@dataclass
class Line:
    """One line (k~[, n_side]) replayed from its records (:func:`replay_line`)."""

    line: tuple
    sigmas: list                     # every sigma~ of the rounds so far, in round order
    rounds: int                      # rounds whose choice was made
    groups: dict = field(default_factory=dict)       # sigma~ -> Group
    limit_hit: bool = False

    @property
    def todo(self) -> list:
        """[(path, preloads)] to run now, over the line's groups."""
        return [t for g in self.groups.values() for t in g.todo]

    @property
    def finished(self) -> bool:
        """Nothing left to run and no round left to choose."""
        return not self.todo


def path_preloads(spec, results: dict, failed, retry_failed=False) -> list:
    """The preloads of one path to run now: the current ``F_P: auto`` round, or the grid's
    preloads without a record (failed ones only with ``retry_failed``)."""
    if spec.auto is not None:
        return path_todo(spec.auto, results, retry_failed, failed)[0]
    return [p for p in spec.preloads if p not in results and (retry_failed or p not in failed)]


def _points(done: dict, paths) -> tuple:
    seed, pre, x, y = [], [], [], []
    for path in paths:
        for p, (fp, fa) in sorted(done.get(path, {}).items()):
            seed.append(path[2])
            pre.append(p)
            x.append(fp)
            y.append(fa)
    return np.asarray(seed), np.asarray(pre, float), np.asarray(x, float), np.asarray(y, float)


def _thin_levels(spec, paths, done, failed, retry_failed=False) -> list:
    """[(path, preloads)] that give every seed of a group the preloads any of its seeds reached
    (``F_P: auto`` places each path's preloads, plateau rounds included, on its own: a level
    that some seeds lack is *thin*, and the report shows it but cannot read it)."""
    if spec.auto is None:
        return []
    levels = set().union(*(set(done.get(p, {})) for p in paths))
    out = []
    for p in paths:
        have = set(done.get(p, {})) | (set() if retry_failed else set(failed.get(p, ())))
        if levels - have:
            out.append((p, sorted(levels - have)))
    return out


def replay_group(spec, line, sigma, done, failed, retry_failed=False, cache=None) -> Group:
    """One group of ``line`` replayed from the records ``done`` {path: {preload: (F_P, F_A)}}
    and ``failed`` {path: set of preloads}; ``cache``: a dict kept between calls (a finished
    group's reading depends only on its records)."""
    k, extra = line[0], tuple(line[1:])
    sa = spec.seeds_auto
    seeds = sa.seeds(sa.start) if sa is not None else list(spec.seeds)
    n_side = extra[0] if extra else spec.base.n_side
    floor = pillar_floor(n_side, spec.base.phi)
    width = sa.width if sa is not None else 0.2
    while True:
        paths = [(k, sigma, s) + extra for s in seeds]
        todo = [(p, pre) for p in paths
                if (pre := path_preloads(spec, done.get(p, {}), failed.get(p, ()),
                                         retry_failed))]
        if todo:
            return Group(sigma, seeds, todo)
        fill = _thin_levels(spec, paths, done, failed, retry_failed)
        if fill:
            return Group(sigma, seeds, fill)
        pts = _points(done, paths)
        ck = (line, sigma, len(seeds), pts[0].size, float(np.sum(pts[3])) if pts[3].size else 0.0)
        prec = None if cache is None else cache.get(ck)
        if prec is None:
            prec = group_precision(*pts, floor=floor, width=width)
            if cache is not None:
                cache[ck] = prec
        if sa is None:
            return Group(sigma, seeds, [], prec.state, prec)
        want = seeds_needed(prec, sa.width, sa.max)
        if want <= len(seeds):
            return Group(sigma, seeds, [], prec.state, prec)
        seeds = sa.seeds(want)


def replay_line(spec, line, done, failed, retry_failed=False, cache=None) -> Line:
    """One line replayed round by round from its records (module text)."""
    a = spec.sigma_auto
    sigmas = [round3(s) for s in a.start] if a is not None else list(spec.sigma_tilde)
    out = Line(tuple(line), list(sigmas), 0)
    while True:
        for s in out.sigmas:
            if s not in out.groups or not out.groups[s].finished:
                out.groups[s] = replay_group(spec, line, s, done, failed, retry_failed, cache)
        if out.todo or a is None:
            return out
        new = next_sigmas(a, {s: g.state for s, g in out.groups.items()})
        if not new:
            return out
        if out.rounds + 1 >= a.rounds:
            out.limit_hit = True
            return out
        out.rounds += 1
        out.sigmas += new


def results(spec, records) -> tuple[dict, dict]:
    """({path: {preload: (F_P, F_A)}} of the done records of the grid's paths, {path: set of
    failed preloads}); records of other grids or preload kinds are left out."""
    done: dict = {}
    failed: dict = {}
    for r in records:
        if r.get("preload_kind") != spec.preload_kind:
            continue
        try:
            path = spec.record_path(r)
        except (KeyError, TypeError, ValueError):
            continue
        if not spec.holds_path(path):
            continue
        p = float(r["preload"])
        if r.get("status") == "done":
            done.setdefault(path, {})[p] = (float(r["F_P"]), float(r["F_A"]))
        else:
            failed.setdefault(path, set()).add(p)
    return done, failed


def frontier(spec, records, retry_failed=False) -> list:
    """[(path, preloads)] a run of the search grid ``spec`` would start with now, from the
    file's ``records`` (a fresh file: round 0 of every line)."""
    return frontier_of(spec, *results(spec, records), retry_failed)


def frontier_of(spec, done: dict, failed: dict, retry_failed=False, cache=None) -> list:
    """:func:`frontier` from the records by path (:func:`results`); ``cache``: as in
    :func:`replay_group`."""
    return [t for line in spec.lines() for t in
            replay_line(spec, line, done, failed, retry_failed, cache).todo]


__all__ = ["AutoSigma", "AutoSeeds", "parse_sigma", "parse_seeds", "is_auto", "next_sigmas",
           "loss_bracket", "replay_line", "replay_group", "results", "frontier", "frontier_of",
           "round3",
           "Line", "Group", "path_preloads", "check_grid",
           "expected_sigmas"]
