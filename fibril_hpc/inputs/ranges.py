"""Declarative ranges of input fields: one object both checks a value and writes the error text.

A range is attached to a dataclass field as ``metadata={"range": ...}``; :func:`check_fields`
validates every such field of an instance. The campaign grid reuses the same ranges for its swept
lists (:meth:`Real.allowed` with ``plural=True``), so a range is written once.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields

from ..errors import ConfigError


def _fmt(x) -> str:
    if x == math.inf:
        return "inf"
    if float(x).is_integer() and abs(x) >= 1e6:
        e = int(round(math.log10(abs(x))))
        if 10**e == abs(x):
            return ("-" if x < 0 else "") + f"1e{e}"
    return f"{x:.3g}" if isinstance(x, float) and not float(x).is_integer() else f"{x:g}"


def _is_int(v) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def as_float(name: str, v, allowed: str) -> float:
    """``v`` as a float (numbers, and the words ``inf``/``infinity``; never bool, NaN or a
    number written as a quoted text such as ``"0.01"``, which is refused in one line)."""
    if isinstance(v, str):
        s = v.strip().lower()
        if s in ("inf", "+inf", "infinity", ".inf"):
            return math.inf
        try:
            float(s)
        except ValueError:
            raise ConfigError(name, v, allowed) from None
        raise ConfigError(name, v, allowed + " (a number, not a quoted text)")
    if not isinstance(v, numbers.Real) or isinstance(v, bool):
        raise ConfigError(name, v, allowed)
    v = float(v)
    if math.isnan(v):
        raise ConfigError(name, v, allowed)
    return v


@dataclass(frozen=True)
class Real:
    """A real number in an interval; ``inf`` is allowed only when ``hi`` is inf and closed.

    ``note`` is appended to the text (e.g. what inf means); ``none`` allows None with the given
    meaning (e.g. ``"null (no cap)"``).
    """

    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    hi_open: bool = False
    note: str = ""
    none: str = ""

    def contains(self, x: float) -> bool:
        """Whether ``x`` lies in the interval."""
        if math.isinf(x) and not (x == self.hi == math.inf and not self.hi_open):
            return False
        lo_ok = x > self.lo if self.lo_open else x >= self.lo
        hi_ok = x < self.hi if self.hi_open else x <= self.hi
        return lo_ok and hi_ok

    def allowed(self, plural: bool = False) -> str:
        """The text of the allowed values (``plural``: for a list of them)."""
        a = "numbers" if plural else "a number"
        finite_hi = self.hi != math.inf
        if self.lo == -math.inf and not finite_hi:
            text = "finite numbers" if plural else "a finite number"
        elif not finite_hi:
            text = f"{a} {'>' if self.lo_open else '>='} {_fmt(self.lo)}"
        elif self.lo == -math.inf:
            text = f"{a} {'<' if self.hi_open else '<='} {_fmt(self.hi)}"
        else:
            text = (f"{a} in {'(' if self.lo_open else '['}{_fmt(self.lo)}, {_fmt(self.hi)}"
                    f"{')' if self.hi_open else ']'}")
        text += self.note
        return (self.none + " or " + text) if self.none and not plural else text

    def check(self, name: str, v):
        """The value as a float, or a one-line :class:`ConfigError` naming ``name``."""
        if v is None and self.none:
            return None
        x = as_float(name, v, self.allowed())
        if not self.contains(x):
            raise ConfigError(name, v, self.allowed())
        return x


@dataclass(frozen=True)
class Int:
    """An integer in [lo, hi] (``hi_text`` spells a bound that :func:`_fmt` would not)."""

    lo: int
    hi: int
    hi_text: str = ""
    none: str = ""

    def allowed(self, plural: bool = False) -> str:
        """The text of the allowed values."""
        a = "integers" if plural else "an integer"
        text = f"{a} in [{_fmt(self.lo)}, {self.hi_text or _fmt(self.hi)}]"
        return (self.none + " or " + text) if self.none and not plural else text

    def check(self, name: str, v):
        """The value as an int, or a one-line :class:`ConfigError` naming ``name``."""
        if v is None and self.none:
            return None
        if not _is_int(v) or not (self.lo <= v <= self.hi):
            raise ConfigError(name, v, self.allowed())
        return int(v)


@dataclass(frozen=True)
class Choice:
    """One of a few strings."""

    options: tuple

    def allowed(self, plural: bool = False) -> str:  # noqa: ARG002
        """The text of the allowed values."""
        q = [f"'{o}'" for o in self.options]
        return q[0] if len(q) == 1 else ", ".join(q[:-1]) + " or " + q[-1]

    def check(self, name: str, v):
        """The value, or a one-line :class:`ConfigError` naming ``name``."""
        if not isinstance(v, str) or v not in self.options:
            raise ConfigError(name, v, self.allowed())
        return v


@dataclass(frozen=True)
class Flag:
    """True or false (a YAML boolean, not a number or a string)."""

    def allowed(self, plural: bool = False) -> str:  # noqa: ARG002
        """The text of the allowed values."""
        return "true or false"

    def check(self, name: str, v):
        """The value, or a one-line :class:`ConfigError` naming ``name``."""
        if not isinstance(v, bool):
            raise ConfigError(name, v, self.allowed())
        return v


def check_list(name: str, v, rng: Real) -> tuple | None:
    """A number or a non-empty list of them, each in ``rng``; sorted, no duplicates."""
    if v is None:
        return None
    allowed = rng.allowed() + " or a non-empty list of them"
    items = list(v) if isinstance(v, (list, tuple)) else [v]
    if not items:
        raise ConfigError(name, v, allowed)
    out = []
    for item in items:
        x = as_float(name, item, allowed)
        if not rng.contains(x):
            raise ConfigError(name, item, allowed)
        out.append(x)
    if len(set(out)) != len(out):
        raise ConfigError(name, v, allowed + " (no duplicates)")
    return tuple(sorted(out))


def range_of(cls, name: str):
    """The range attached to field ``name`` of dataclass ``cls``."""
    return next(f.metadata["range"] for f in fields(cls) if f.name == name)


def check_fields(obj, prefix: str = "") -> None:
    """Validate (and normalise) every field of a frozen dataclass that carries a range.

    Fields with ``metadata["many"]`` take a number or a list (:func:`check_list`).
    """
    for f in fields(obj):
        rng = f.metadata.get("range")
        if rng is None:
            continue
        v = getattr(obj, f.name)
        if f.metadata.get("many"):
            value = check_list(prefix + f.name, v, rng)
        else:
            value = rng.check(prefix + f.name, v)
        object.__setattr__(obj, f.name, value)


__all__ = ["Real", "Int", "Choice", "Flag", "as_float", "check_list", "check_fields",
           "range_of"]
