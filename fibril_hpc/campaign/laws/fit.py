"""The "linear, then plateau" laws, fitted per (k~, sigma~) in log F~_A.

Pure functions on plain numbers (no I/O, no plotting). ``F_P: auto`` places its preloads around
the kink of :data:`DEFAULT_LAW` (:mod:`.auto`); the report reads the plateau and the
coefficients without a law (:mod:`.laws.reading`) and shows these laws only beside that reading,
with their residuals (the law comparison).

Every law has two parameters, the plateau P and the kink x_k = P / c (c the initial slope,
F~_A = c F~_P at small preload), and is written log F~_A = log P + g(log F~_P - log x_k):

* ``"tanh"`` (the default): F~_A = P tanh(F~_P / x_k);
* ``"min"`` (a hard kink): F~_A = min(c F~_P, P);
* ``"exp"``: F~_A = P (1 - exp(-F~_P / x_k));
* ``"langmuir"``: F~_A = P F~_P / (x_k + F~_P).

The fit is least squares in log F~_A (relative residuals: F~_A spans decades). For a fixed kink
the law is linear in log P, so log P is profiled out and the residual minimised over log x_k
(a grid, then ``scipy.optimize.minimize_scalar`` on the bracketing cells): deterministic, no
starting guess.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LAWS = ("tanh", "min", "exp", "langmuir")
DEFAULT_LAW = "tanh"


def _g(law: str, t):
    """log of the law's shape at t = log(F~_P / x_k) (0 on the plateau)."""
    t = np.asarray(t, dtype=float)
    e = np.exp(np.minimum(t, 50.0))
    if law == "min":
        return np.minimum(t, 0.0)
    if law == "tanh":                          # log tanh(e^t), stable for both tails
        return np.where(t < -20.0, t, np.log(np.tanh(e)))
    if law == "exp":                           # log(1 - exp(-e^t))
        return np.where(t < -20.0, t, np.log(-np.expm1(-e)))
    return t - np.logaddexp(0.0, t)            # langmuir: log(e^t / (1 + e^t))


def model(law: str, F_P, c: float, plateau: float):
    """F~_A of ``law`` at ``F_P`` (arrays welcome)."""
    x = np.asarray(F_P, dtype=float)
    xk = plateau / c
    with np.errstate(over="ignore", invalid="ignore"):
        return plateau * np.exp(_g(law, np.log(np.maximum(x, 1e-300) / xk)))


@dataclass
class LawFit:
    """A law fitted to points: c, plateau, kink (plateau / c) and the rms residual of log F~_A."""

    law: str
    c: float
    plateau: float
    kink: float
    rms_log: float                  # rms residual of log F~_A
    n_points: int


def fit_law(F_P, F_A, law: str = DEFAULT_LAW) -> LawFit:
    """Least-squares fit of ``law`` in log F~_A to points with F~_P > 0 and F~_A > 0."""
    from scipy import optimize

    if law not in LAWS:
        raise ValueError(f"law: {law!r} is not one of {LAWS}")
    x = np.asarray(F_P, dtype=float)
    y = np.asarray(F_A, dtype=float)
    ok = (x > 0) & (y > 0) & np.isfinite(x) & np.isfinite(y)
    u, v = np.log(x[ok]), np.log(y[ok])
    if u.size < 2:
        return LawFit(law, math.nan, math.nan, math.nan, math.nan, int(u.size))

    def sse(tk):
        tk = np.atleast_1d(np.asarray(tk, dtype=float))
        gg = _g(law, u[None, :] - tk[:, None])
        lp = np.mean(v[None, :] - gg, axis=1)
        r = v[None, :] - lp[:, None] - gg
        return np.sum(r * r, axis=1), lp

    grid = np.linspace(u.min() - 3.0, u.max() + 3.0, 241)
    s, _ = sse(grid)
    i = int(np.argmin(s))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = optimize.minimize_scalar(lambda t: float(sse(t)[0][0]), bounds=(a, b),
                                   method="bounded", options={"xatol": 1e-10})
    tk = float(res.x) if res.success and res.fun <= s[i] else float(grid[i])
    s_opt, lp = sse(tk)
    P, xk = math.exp(lp[0]), math.exp(tk)
    return LawFit(law, P / xk, P, xk, math.sqrt(s_opt[0] / u.size), int(u.size))
