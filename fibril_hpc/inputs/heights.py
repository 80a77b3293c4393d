"""Pillar height and stiffness laws, and measured files of either (docs/model.md §9).

A scene's ``heights`` is a law name or the per-pillar lengths themselves:

* ``gaussian`` (default): xi_n standard normal, exactly the draw of
  :func:`~fibril_hpc.geometry.grid.pillar_heights`;
* ``exponential``: xi_n = e_n - 1 with e_n standard exponential (mean 0, standard deviation 1; a
  tail of long pillars);
* ``uniform``: xi_n uniform on [-sqrt 3, sqrt 3] (mean 0, standard deviation 1).

For every law the length is l_n = l0 + sigma xi_n with sigma = ``sigma_tilde`` d_c (so ``sigma_tilde``
is the standard deviation of the length under every law, and campaign grids sweep it the same way),
drawn by ``numpy.random.Generator(PCG64(seed))`` in row-major pillar order, and the set-back is
zeta_n = sigma (max xi - xi_n).

Measured lengths: a ``.csv`` (numbers separated by commas, blanks or new lines; ``#`` starts a
comment) or ``.npy`` file, or a list, of one length per pillar in row-major pillar order, >= 0 and
finite, in units of d_c, or in any physical unit when ``heights_d_c`` gives d_c in that unit. The
scene then holds the values themselves (so a stored scene reproduces the run without the file) and
``heights_source`` the file's name and SHA-256; zeta_n = max l - l_n and ``sigma_tilde`` is not
used.
"""

from __future__ import annotations

import hashlib
import math
import os

import numpy as np

from ..errors import ConfigError
from ..geometry.grid import pillar_heights
from .ranges import as_float

#: Height laws (``Scene.heights`` may also be a file or a list of lengths).
HEIGHT_LAWS = ("gaussian", "exponential", "uniform")
HEIGHT_FILES = (".csv", ".npy")


#: Per-pillar stiffness laws besides the per-pillar values themselves (``Scene.k_law``).
K_LAWS = ("one", "lognormal")


class LawOrValuesRange:
    """The allowed values of a field that is a law name or per-pillar values (used like the
    ranges of :mod:`fibril_hpc.inputs.ranges`): ``laws``, or a non-empty list of finite numbers, each
    > 0 (``positive``) or >= 0; files are read by :func:`read_file` before the check."""

    def __init__(self, laws: tuple, text: str, positive: bool):
        self.laws, self.text, self.positive = laws, text, positive

    def allowed(self, plural: bool = False) -> str:  # noqa: ARG002
        """The text of the allowed values."""
        return self.text

    def check(self, name: str, v):
        """A law name, or the per-pillar values as a tuple of floats."""
        if isinstance(v, str):
            if v in self.laws:
                return v
            raise ConfigError(name, v, self.text)
        if isinstance(v, np.ndarray):
            v = v.tolist()
        if not isinstance(v, (list, tuple)) or not v:
            raise ConfigError(name, v, self.text)
        out = []
        for x in v:
            x = as_float(name, x, self.text)
            if not math.isfinite(x) or (x <= 0 if self.positive else x < 0):
                raise ConfigError(name, x, self.text)
            out.append(x)
        return tuple(out)


def KLawRange() -> LawOrValuesRange:  # noqa: N802 - reads like the range classes
    """The allowed values of ``k_law``: ``one``, ``lognormal``, a file or a list of k~ > 0."""
    return LawOrValuesRange(K_LAWS, "'one' (every pillar k_tilde), 'lognormal', a .csv or .npy "
                            "file of per-pillar k_tilde, or a list of them (> 0, one per pillar)",
                            positive=True)


def HeightsRange() -> LawOrValuesRange:  # noqa: N802 - reads like the range classes
    """The allowed values of ``heights``: a law, a file or a list of lengths >= 0."""
    return LawOrValuesRange(HEIGHT_LAWS, "'gaussian', 'exponential', 'uniform', a .csv or .npy "
                            "file of per-pillar lengths, or a list of them (finite, >= 0, one "
                            "per pillar)", positive=False)


def pillar_stiffness(k_tilde: float, law, spread: float, n: int, seed: int):
    """k~ of the pillars: the number ``k_tilde`` itself for ``one`` (no per-pillar array), else an
    array: ``lognormal``, k~_n = k_tilde exp(spread z_n) with z_n standard normal from the stream
    ``PCG64(seed).jumped()`` (independent of the height draws; median k_tilde), or the given
    values."""
    if isinstance(law, str):
        if law == "one":
            return k_tilde
        rng = np.random.Generator(np.random.PCG64(seed).jumped())
        return k_tilde * np.exp(spread * rng.standard_normal(n))
    return np.asarray(law, dtype=np.float64)


def is_file(v) -> bool:
    """Whether a ``heights`` value names a file."""
    return isinstance(v, str) and v.lower().endswith(HEIGHT_FILES)


def read_file(path: str, name: str = "heights") -> tuple[tuple, str]:
    """(values, "path sha256:HEX") of a height (or stiffness) file; any problem is a one-line
    ConfigError."""
    allowed = (HeightsRange() if name == "heights" else KLawRange()).allowed()
    full = os.path.expanduser(path)
    if not os.path.isfile(full):
        raise ConfigError(name, path, "an existing file: " + allowed)
    try:
        with open(full, "rb") as fh:
            raw = fh.read()
        if full.lower().endswith(".npy"):
            import io

            values = np.load(io.BytesIO(raw), allow_pickle=False)
        else:
            text = "\n".join(line.split("#", 1)[0] for line in raw.decode("utf-8").splitlines())
            values = np.array([float(t) for t in text.replace(",", " ").split()])
        values = np.asarray(values, dtype=np.float64).ravel()
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise ConfigError(name, path, f"a readable file of numbers ({exc.__class__.__name__}): "
                          + allowed) from None
    bad = ~np.isfinite(values) | ((values < 0) if name == "heights" else (values <= 0))
    if bad.any():
        what = "finite lengths >= 0" if name == "heights" else "finite stiffnesses > 0"
        raise ConfigError(name, path, f"{what} (value {float(values[bad][0])!r} at pillar "
                          f"{int(np.flatnonzero(bad)[0])})")
    if not len(values):
        raise ConfigError(name, path, "one length per pillar (the file is empty)")
    return tuple(values.tolist()), f"{path} sha256:{hashlib.sha256(raw).hexdigest()}"


def draws(law: str, n: int, seed: int) -> np.ndarray:
    """n unit-variance, zero-mean draws of a law, in row-major pillar order."""
    if law == "gaussian":
        return pillar_heights(n, seed)
    rng = np.random.Generator(np.random.PCG64(seed))
    if law == "exponential":
        return rng.standard_exponential(n) - 1.0
    if law == "uniform":
        return rng.uniform(-math.sqrt(3.0), math.sqrt(3.0), n)
    raise ValueError(f"unknown height law {law!r}")


def setbacks(heights, heights_d_c, n: int, sigma: float, seed: int, d_c: float) -> tuple:
    """(xi, zeta) per pillar: the draws (or the lengths over d_c) and the set-backs (internal
    units) of a scene's ``heights`` (``sigma``: the length spread in internal units)."""
    if isinstance(heights, str):
        xi = draws(heights, n, seed)
        return xi, (sigma * (xi.max() - xi) if n else np.zeros(0))
    xi = np.asarray(heights, dtype=np.float64)
    if heights_d_c is not None:
        xi = xi / heights_d_c
    return xi, (xi.max() - xi) * d_c


__all__ = ["HEIGHT_LAWS", "K_LAWS", "HeightsRange", "KLawRange", "is_file", "read_file", "draws",
           "setbacks", "pillar_stiffness"]
