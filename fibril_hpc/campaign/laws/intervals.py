"""The whole error of a number: its seed interval and the preset's discretisation bias.

**Seed interval.** Seeds are the independent realisations of a (k~, sigma~), so the interval
comes from resampling seeds with replacement (``scipy.stats.bootstrap``, one resample = one
multiset of seed labels, the whole reading redone on it) and taking the 2.5 and 97.5 %
percentiles of the replicates. A seed is the same brush at every sigma~ (and every group it is
in), so a resample picks a label in every group that holds it: paired across groups, also where
groups hold different seed sets (:func:`paired_replicates`). With n seeds there are only C(2n-1,
n) distinct resamples (10 for three seeds), and the percentile interval of a seed mean is a
normal interval on the plug-in sd: over synthetic groups of known truth it held the true c in
67-81 % of draws at 3 seeds, 81-85 % at 5 and 87-92 % at 10 (benchmarks/NOTES.md, "Seed
intervals against known truth"). The study therefore widens it about its value by
:func:`small_sample_factor` (Student t over the normal, unbiased over plug-in sd), which brings
the coverage to the level claimed. A replicate that cannot be formed (a sigma~_c whose beta <=
0) counts as +inf: the upper end of the interval is then unbounded.

**Discretisation bias.** The converged-reference study (``benchmarks/accuracy/``,
``benchmarks/NOTES.md`` §27b) measured F~_A of the default scene (18 x 18 pillars, F~_P = 4)
against its converged value 0.9759 +- 0.16 %: ``fast`` -3.6 %, ``default`` +0.9 %,
``accurate`` +1.3 %. A preset's bias is taken as a relative error of every force-like number of
the campaign (F~_A, the plateau, c, c0, alpha, beta); a ratio such as sigma~_c = alpha/beta
does not change when every c is off by the same factor, so its bias is 0 to first order. The
study measured one scene: carrying the figure to other (k~, sigma~) is an assumption, stated in
the report. A scene whose resolution is not its preset's has no measured bias.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

#: relative error of F~_A per preset against the converged reference (benchmarks/NOTES.md §27b)
PRESET_BIAS = {"fast": -0.036, "default": 0.009, "accurate": 0.013}
#: elements per diameter of each preset (fibril_hpc/presets.py), to tell a preset from an override
PRESET_EPD = {"fast": 6.0, "default": 8.0, "accurate": 16.0}
LEVEL = 0.95
_BIG = 1e300


def preset_bias(preset, elements_per_diameter) -> tuple[float, str]:
    """(relative bias of F~_A, why) for a campaign's preset and resolution; NaN if unmeasured."""
    if preset not in PRESET_BIAS:
        return math.nan, f"preset {preset!r}: no measured discretisation bias"
    epd = PRESET_EPD[preset]
    if elements_per_diameter is not None and not math.isclose(float(elements_per_diameter), epd):
        return math.nan, (f"elements_per_diameter {float(elements_per_diameter):g} is not the "
                          f"{preset} preset's {epd:g}: no measured discretisation bias")
    return PRESET_BIAS[preset], (f"preset {preset}: F~_A {100 * PRESET_BIAS[preset]:+.1f} % "
                                 "against the converged reference of the default scene")


def seed_replicates(labels, statistic, n_boot: int, rng_seed: int = 0):
    """Bootstrap replicates of ``statistic(labels_resampled) -> 1-d array`` over seed labels.

    Returns an array (n_values, n_boot), or None with fewer than two seeds or ``n_boot < 1``.
    Non-finite replicate values are kept (NaN: not formed; inf: unbounded).
    """
    from scipy import stats

    labels = np.asarray(sorted(set(labels)))
    if labels.size < 2 or n_boot < 1:
        return None

    def stat(i):
        return np.atleast_1d(np.asarray(statistic(labels[np.asarray(i, dtype=int)]), dtype=float))

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        # the interval is taken below from the replicates; scipy's own warns on NaN/inf ones
        warnings.simplefilter("ignore")
        res = stats.bootstrap((np.arange(labels.size),), stat, vectorized=False,
                              n_resamples=int(n_boot), method="percentile",
                              rng=np.random.default_rng(rng_seed))
    d = np.asarray(res.bootstrap_distribution, dtype=float)
    return d.reshape(-1, d.shape[-1])


def paired_replicates(label_sets, statistic, n_boot: int, rng_seed: int = 0):
    """Bootstrap replicates over seed *labels*, paired across groups: ``statistic(picks) ->
    1-d array``, ``picks`` one array of resampled labels per set (``label_sets``: the seeds of
    each group; ``seeds: auto`` gives a group only the seeds it needs).

    A seed is the same height pattern in every group it is in, so one replicate is one multiset
    of labels drawn with replacement from the *union* of the sets (as many draws as the union
    has labels), and each group takes, with their multiplicity, the drawn labels that it holds:
    a seed drawn twice counts twice in every group that has it, and numbers read across groups
    keep their correlation through the seeds. Groups that hold the same seeds get the same
    multiset (the ordinary paired bootstrap); a group with n of the union's N seeds gets a
    binomial(N, n/N) number of them, whose mean 1/size is close to 1/n (0.333 for 3 of 10,
    against 1/3), so its interval has its own seeds' width on average.

    A group left with fewer than two drawn labels (it cannot show a spread) draws its own
    ordinary resample of its n seeds instead, for that replicate alone (unpaired there); a
    group of one seed always takes it. Returns an array (n_values, n_boot), or None when no set
    holds two seeds or ``n_boot < 1``.
    """
    sets = [np.asarray(sorted(set(s))) for s in label_sets]
    if max((len(s) for s in sets), default=0) < 2 or n_boot < 1:
        return None
    union = np.asarray(sorted(set().union(*(s.tolist() for s in sets))))
    member = [np.isin(union, s) for s in sets]
    rng = np.random.default_rng(rng_seed)
    out = []
    with np.errstate(all="ignore"):
        for _ in range(int(n_boot)):
            drawn = rng.integers(0, union.size, union.size)
            picks = []
            for g, s in enumerate(sets):
                mine = union[drawn[member[g][drawn]]]
                if mine.size < min(2, s.size):          # redrawn within the group
                    mine = s[rng.integers(0, s.size, s.size)]
                picks.append(mine)
            out.append(np.atleast_1d(np.asarray(statistic(picks), dtype=float)))
    return np.array(out).T


def percentile_interval(replicates, level: float = LEVEL) -> tuple[float, float]:
    """(lo, hi) percentiles of the replicates; +inf ones make hi unbounded (inf); NaN ones are
    left out; fewer than two usable replicates: (NaN, NaN)."""
    r = np.asarray(replicates, dtype=float)
    r = r[~np.isnan(r)]
    if r.size < 2:
        return math.nan, math.nan
    r = np.clip(r, -_BIG, _BIG)
    q = (1 - level) / 2
    lo, hi = np.percentile(r, [100 * q, 100 * (1 - q)])
    # an end interpolated towards an unbounded replicate is unbounded (not a huge number),
    # also where both its neighbours are (most replicates at +inf: the lower end too)
    lo_n = np.percentile(r, 100 * q, method="lower")
    hi_n = np.percentile(r, 100 * (1 - q), method="higher")
    return _end(lo, lo_n, np.percentile(r, 100 * q, method="higher")), \
        _end(hi, np.percentile(r, 100 * (1 - q), method="lower"), hi_n)


def _end(v: float, below: float, above: float) -> float:
    """A percentile ``v`` interpolated between the replicates ``below`` and ``above`` (clipped
    to +-_BIG): -inf where ``below`` is unbounded, +inf where ``above`` is, else ``v``."""
    if below <= -_BIG:
        return -math.inf
    return math.inf if above >= _BIG else float(v)


def small_sample_factor(n_seeds: int, level: float = LEVEL) -> float:
    """How much a percentile interval over ``n_seeds`` seeds is widened about its value:
    t_(n-1) / z x sqrt(n / (n - 1)) (2.69 for 3 seeds, 1.58 for 5, 1.22 for 10, -> 1): the
    bootstrap's spread of a seed mean is the plug-in sd / sqrt(n), and its quantiles are the
    normal's; a Student t interval needs the unbiased sd and t's quantiles. 1 below 2 seeds."""
    from scipy import stats

    if n_seeds < 2:
        return 1.0
    q = 0.5 + level / 2
    return float(stats.t.ppf(q, n_seeds - 1) / stats.norm.ppf(q) * math.sqrt(n_seeds / (n_seeds - 1)))


def expanded(value, ci, n_seeds: int, level: float = LEVEL) -> tuple[float, float]:
    """The interval ``ci`` widened about ``value`` by :func:`small_sample_factor` (infinite or
    undefined ends stay as they are; an undefined value leaves the interval alone)."""
    lo, hi = ci
    if not math.isfinite(value):
        return lo, hi
    f = small_sample_factor(n_seeds, level)
    return (value - f * (value - lo) if math.isfinite(lo) else lo,
            value + f * (hi - value) if math.isfinite(hi) else hi)


def replicate_sd(replicates) -> float:
    """Standard deviation of the finite replicates (NaN with fewer than two)."""
    r = np.asarray(replicates, dtype=float)
    r = r[np.isfinite(r)]
    return float(np.std(r, ddof=1)) if r.size > 1 else math.nan


def dominant(value, ci, bias_rel) -> str:
    """Which error is larger, the seed interval's half-width or the bias: ``"seeds"``,
    ``"discretisation"``, or ``"unknown"`` when either is not known."""
    if not (math.isfinite(value) and math.isfinite(bias_rel)
            and all(math.isfinite(v) for v in ci)):
        return "unknown"
    half = max(value - ci[0], ci[1] - value)
    return "seeds" if half >= abs(bias_rel * value) else "discretisation"
