"""The page's one notation, and each note said once.

The science modules (:mod:`..laws`) write their notes in ASCII ("sigma~", "k~", "F~_A",
"alpha"), which is also what the CSV cells keep (plain text any tool reads). The page
(``README.md`` and ``report.html``) shows one notation, the symbols of the paper and of
``docs/report.md``: σ̃, k̃, F̃_A, α, β, χ², φ, c₀. :func:`page_text` turns the first into the
second; every string the page shows (headline, notes, table cells, captions) goes through it.

:func:`once` joins notes so that each is said once: exact repeats, and notes already contained
in a longer one, are dropped.
"""

from __future__ import annotations

import re

#: ASCII -> the page's symbols, applied in this order (longer names first)
_SYMBOLS = (
    (r"sigma~_c", "σ̃_c"), (r"sigma~", "σ̃"), (r"k~_m", "k̃_m"), (r"k~", "k̃"),
    (r"F~_A", "F̃_A"), (r"F~_P", "F̃_P"), (r"F~_1", "F̃_1"), (r"F~", "F̃"),
    (r"Delta~", "Δ̃"), (r"d~", "d̃"),
    (r"chi\^2", "χ²"), (r"phi\^\(1/4\)", "φ^¼"), (r"N\^\(3/4\)", "N^¾"),
    (r"(?<![\w.`])alpha(?![\w`])", "α"), (r"(?<![\w.`])beta(?![\w`])", "β"),
    (r"(?<![\w.`])phi(?![\w`])", "φ"), (r"(?<![\w.`])c0(?![\w`])", "c₀"),
    (r"(?<=\d) x (?=[\d(])", " × "), (r"(?<=\d) x that", " × that"),
    (r"\(x (?=\d)", "(× "),
)
_COMPILED = tuple((re.compile(a), b) for a, b in _SYMBOLS)
#: what the page must never show once :func:`page_text` ran (tests/test_report_page.py)
ASCII_LEFT = re.compile(r"sigma~|k~|F~_|chi\^2|(?<![\w.`])(alpha|beta)(?![\w`])")


def page_text(text) -> str:
    """``text`` in the page's notation (symbols for the ASCII names; code spans in backticks,
    CSV and field names such as ``alpha_beta.csv`` or ``sigma_tilde`` are left as they are)."""
    s = str(text)
    parts = s.split("`")
    for i in range(0, len(parts), 2):          # outside `code` spans only
        for pat, rep in _COMPILED:
            parts[i] = pat.sub(rep, parts[i])
    return "`".join(parts)


def clauses(text, sep: str = "; ") -> list:
    """The clauses of a note joined by ``sep``, split only outside brackets ("(a; b)" stays
    one clause)."""
    out, cur, depth, i, t = [], [], 0, 0, str(text or "")
    while i < len(t):
        ch = t[i]
        depth += ch in "(["
        depth -= ch in ")]" and depth > 0
        if depth == 0 and t.startswith(sep, i):
            out.append("".join(cur))
            cur, i = [], i + len(sep)
            continue
        cur.append(ch)
        i += 1
    out.append("".join(cur))
    return [x.strip() for x in out if x.strip()]


def _key(note: str) -> str:
    return " ".join(page_text(note).split()).strip(" ;.").lower()


def once(parts, sep: str = "; ") -> str:
    """The notes of ``parts`` joined by ``sep``, each said once: empty ones, exact repeats (in
    either notation) and notes contained in a longer one are dropped; clauses of a note joined
    by ``sep`` count as notes of their own."""
    items = []
    for p in parts:
        items += clauses(p, sep)
    keys = [_key(x) for x in items]
    out, seen = [], set()
    for x, k in zip(items, keys):
        if k in seen or any(k != o and k in o for o in keys):
            continue
        seen.add(k)
        out.append(x)
    return sep.join(out)


__all__ = ["page_text", "once", "clauses", "ASCII_LEFT"]
