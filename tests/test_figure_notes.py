"""The note an empty figure panel carries is wrapped at word boundaries (it was cut every 60
characters, mid-word), at most six lines, an ellipsis where it is cut."""

from __future__ import annotations

from fibril_hpc.campaign.analysis.figures_coeff import note_lines


def test_a_note_is_wrapped_at_words_and_keeps_its_line_breaks():
    why = ("k̃=0.001: the fit has fewer than three σ̃ with adhesion left on every seed; "
           "k̃=10: an undefined law because its plateau does not fall")
    out = note_lines("no α to draw:\n" + why)
    lines = out.split("\n")
    assert lines[0] == "no α to draw:"
    assert all(len(ln) <= 60 for ln in lines) and len(lines) > 2
    assert " ".join(lines[1:]).split() == why.split()          # no word cut or lost
    assert "…" not in out


def test_a_long_note_is_cut_to_six_lines_with_an_ellipsis():
    out = note_lines("word " * 200).split("\n")
    assert len(out) == 7 and out[-1] == "…"
    assert all(ln.split() and set(ln.split()) == {"word"} for ln in out[:6])
