"""``F_P: auto``: the campaign places the preloads of every (k~, sigma~, seed) itself.

F~_A(F~_P) rises linearly (F~_A = c F~_P) and then saturates; where it bends depends on k~ and
sigma~ by orders of magnitude, so a fixed preload list either wastes unloadings on the plateau or
misses the linear stage. With ``F_P: auto`` a loading path is run in *rounds*. Round 0 runs the
``start`` preloads (one loading path, one unloading each). After every round the path's points
are fitted with the report's law (:data:`fibril_hpc.campaign.laws.fit.DEFAULT_LAW`,
:func:`fibril_hpc.campaign.laws.fit.fit_law`; the kink is
plateau / c) and the next round's preloads are chosen:

* fewer than ``below`` preloads below the kink: bisect (in log F~_P) the gap between the largest
  preload below the kink and the smallest above it, and extend the list downwards (the smallest
  tried / 4, / 16, ...; not below ``min``), unless the two smallest preloads give the same
  F~_A within 5 % (a *floor*: below the first contacts F~_A is the pull-off of the few pillars
  that touch and stops falling, so going lower adds nothing);
* fewer than ``above`` preloads above the kink: extend upwards (the largest x 4, ...; not above
  ``max``);
* both met but the kink's bracket (smallest above / largest below) wider than ``bracket``: bisect
  it in log F~_P.

When nothing is left to add (or after ``rounds`` rounds) it checks the plateau: F~_A at the
largest preload must be within 3 % (:data:`.laws.reading.PATH_RTOL`) of F~_A at the preload
below it, or above it (the report's plateau is the preload-insensitive F~_A). If not, *plateau
rounds* follow, one preload each: the largest x 4, capped at ``max``, until F~_A stops rising or
``max`` is reached. Only the path's own records decide, so a resume replays them too, and a file
finished before plateau rounds existed resumes by adding them (its records and job keys stay as
they are; the settings and the campaign hash do not change). New preloads are rounded to three
significant digits. Every chosen preload is an ordinary job with the ordinary key (the hash of its
single-preload scene), so merge, status and export see normal records. The choice of round r is a
function of the records of rounds 0 .. r-1 only, so a resumed campaign (after SIGKILL too)
replays the same rounds from its records and runs exactly the preloads an uninterrupted run would.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass

from ...errors import ConfigError, unknown_key
from ..laws.fit import DEFAULT_LAW, fit_law
from ..laws.reading import path_plateau_reached

AUTO_WORD = "auto"
#: the smallest preload's F~_A at least this fraction of the next one's: a floor, not linear
FLOOR_RATIO = 0.95


@dataclass(frozen=True)
class AutoPreloads:
    """Settings of ``F_P: auto`` (YAML ``F_P: auto`` or ``F_P: {auto: {start: [...], ...}}``)."""

    start: tuple = (0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0)
    min: float = 1e-5
    max: float = 20.0
    below: int = 3
    above: int = 2
    bracket: float = 2.0
    rounds: int = 6

    def to_dict(self) -> dict:
        """The settings as a plain mapping (as written in the resolved grid)."""
        d = asdict(self)
        d["start"] = list(self.start)
        return d


FIELDS = tuple(AutoPreloads.__dataclass_fields__)


def parse(value) -> AutoPreloads:
    """``auto`` or ``{auto: {...}}`` -> :class:`AutoPreloads`; one-line ConfigError otherwise."""
    if value == AUTO_WORD:
        return AutoPreloads()
    if not (isinstance(value, dict) and list(value) == [AUTO_WORD]):
        raise ConfigError("F_P", value, "numbers in (0, 1e6), 'auto' or {auto: {settings}}")
    cfg = value[AUTO_WORD] or {}
    if not isinstance(cfg, dict):
        raise ConfigError("F_P.auto", cfg, "a mapping of " + ", ".join(FIELDS))
    unknown = sorted(set(map(str, cfg)) - set(FIELDS))
    if unknown:
        raise unknown_key(f"F_P.auto.{unknown[0]}", cfg[unknown[0]], FIELDS, "a setting")
    d = AutoPreloads().to_dict()
    d.update(cfg)

    def num(name, lo, hi, integer=False):
        v = d[name]
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and lo <= v <= hi
        if not ok or (integer and int(v) != v):
            kind = "an integer" if integer else "a number"
            raise ConfigError(f"F_P.auto.{name}", v, f"{kind} in [{lo:g}, {hi:g}]")
        return int(v) if integer else float(v)

    mn, mx = num("min", 1e-9, 1e6), num("max", 1e-9, 1e6)
    if mn >= mx:
        raise ConfigError("F_P.auto.min", mn, f"a number below max ({mx:g})")
    start = d["start"]
    if not isinstance(start, list) or len(start) < 2 or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and mn <= x <= mx
            for x in start) or len(set(start)) != len(start):
        raise ConfigError("F_P.auto.start", start,
                          f"a list of at least 2 distinct numbers in [min, max] = [{mn:g}, {mx:g}]")
    return AutoPreloads(start=tuple(sorted(float(x) for x in start)), min=mn, max=mx,
                        below=num("below", 2, 100, True), above=num("above", 1, 100, True),
                        bracket=num("bracket", 1.05, 1e3), rounds=num("rounds", 1, 100, True))


def settings_hash(a: AutoPreloads) -> str:
    """Short SHA-256 of the settings (part of an auto grid's campaign hash)."""
    return hashlib.sha256(json.dumps(a.to_dict(), sort_keys=True).encode()).hexdigest()[:16]


def _round3(x: float) -> float:
    return float(f"{x:.3g}")


def next_preloads(a: AutoPreloads, tried, results) -> list:
    """The preloads of the next round of one path.

    ``tried``: every preload of the rounds so far; ``results``: {preload: (F_P, F_A)} of its done
    jobs (failed ones absent). Returns the new preloads, ascending (empty: the path is finished).
    """
    pts = sorted((p, fp, fa) for p, (fp, fa) in results.items()
                 if p in tried and fp > 0 and fa > 0 and math.isfinite(fa))
    if len(pts) < 2:
        return []
    f = fit_law([fp for _, fp, _ in pts], [fa for _, _, fa in pts], DEFAULT_LAW)
    if not math.isfinite(f.kink):
        return []
    below = [p for p, fp, _ in pts if fp < f.kink]
    above = [p for p, fp, _ in pts if fp >= f.kink]
    new = []
    if below and above and above[0] / below[-1] > a.bracket:
        new.append(math.sqrt(above[0] * below[-1]))
    # below the first contacts F~_A stops falling (the pull-off of the few pillars that touch):
    # going lower would only add points on that floor
    floor = len(pts) >= 2 and pts[0][2] >= FLOOR_RATIO * pts[1][2]
    if len(below) < a.below and not floor:
        lo = min(tried)
        new += [lo / 4.0**i for i in range(1, a.below - len(below) + 1)]
    if len(above) < a.above:
        hi = max(tried)
        new += [hi * 4.0**i for i in range(1, a.above - len(above) + 1)]
    tried_r = {_round3(p) for p in tried}
    out = sorted({_round3(p) for p in new if a.min <= p <= a.max} - tried_r)
    return out


def plateau_preloads(a: AutoPreloads, tried, results) -> list:
    """The next plateau round of one path: ``[min(largest tried x 4, max)]`` while F~_A still
    rises at the largest preload (:func:`.laws.reading.path_plateau_reached`), else ``[]`` (also
    with fewer than two done preloads: nothing to judge)."""
    pts = [(fp, fa) for p, (fp, fa) in results.items() if p in tried and math.isfinite(fa)]
    if len(pts) < 2 or path_plateau_reached([fp for fp, _ in pts], [fa for _, fa in pts]):
        return []
    hi = max(tried)
    nxt = _round3(min(hi * 4.0, a.max))
    return [nxt] if nxt > hi and nxt not in {_round3(p) for p in tried} else []


@dataclass
class Replay:
    """One path replayed from its records (:func:`replay`)."""

    todo: list                      # preloads to run now (empty: the path is finished)
    rounds: int                     # index of the last kink round run (``rounds`` if limited)
    kink_tried: list                # preloads of the kink rounds (start included)
    plateau_tried: list             # preloads of the plateau rounds


def replay(a: AutoPreloads, results, retry_failed=False, failed=()) -> Replay:
    """Replay the rounds of one path from its records: the kink rounds (at most ``rounds``,
    :func:`next_preloads`), then the plateau rounds (:func:`plateau_preloads`).

    ``results``: {preload: (F_P, F_A)} of the done jobs of the path; ``failed``: preloads recorded
    as failed (rerun only with ``retry_failed``)."""
    kink: list = []
    plateau: list = []
    cur = list(a.start)
    r = 0                           # kink rounds completed
    in_kink, limit_hit = True, False
    while True:
        (kink if in_kink else plateau).extend(cur)
        missing = [p for p in cur if p not in results and (retry_failed or p not in failed)]
        if missing:
            return Replay(missing, r if in_kink else max(r - 1, 0), kink, plateau)
        tried = kink + plateau
        if in_kink:
            r += 1
            cur = next_preloads(a, tried, results)
            if cur and r >= a.rounds:   # the round limit: the kink rounds stop here
                cur, limit_hit = [], True
            if not cur:
                in_kink = False
        else:
            cur = []
        if not in_kink:
            cur = plateau_preloads(a, tried, results)
            if not cur:
                return Replay([], a.rounds if limit_hit else r - 1, kink, plateau)


def path_todo(a: AutoPreloads, results, retry_failed=False, failed=()) -> tuple[list, int]:
    """(preloads to run now, round number) of one path, replayed from its records
    (:func:`replay`). An empty list: the path is finished; its round number is then its last
    kink round's index, or ``rounds`` when the kink rounds hit their limit."""
    rp = replay(a, results, retry_failed, failed)
    return rp.todo, rp.rounds


def _path_of(r) -> tuple:
    return float(r["k_tilde"]), float(r["sigma_tilde"]), int(r["seed"])


def results_by_path(records, paths, path_of=None) -> tuple[dict, dict]:
    """({path: {preload: (F_P, F_A)}} of done records, {path: set of failed preloads});
    ``path_of(record)``: its path (default (k~, sigma~, seed); a grid sweeping ``n_side`` passes
    :meth:`.spec.CampaignSpec.record_path`)."""
    want = set(paths)
    path_of = path_of or _path_of
    done: dict = {p: {} for p in want}
    failed: dict = {p: set() for p in want}
    for r in records:
        if r.get("preload_kind") != "F_P":
            continue
        path = path_of(r)
        if path not in want:
            continue
        if r.get("status") == "done":
            done[path][float(r["preload"])] = (float(r["F_P"]), float(r["F_A"]))
        else:
            failed[path].add(float(r["preload"]))
    return done, failed
