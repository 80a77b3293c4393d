"""The laws of a campaign's science, pure functions on numbers (no files, no MPI).

Owns :mod:`.fit` (the "linear, then plateau" laws of F~_A(F~_P), fitted in log F~_A; the
``F_P: auto`` planner places preloads around their kink), :mod:`.reading` (one (k~, sigma~)
read without a law: the plateau, the first-contact slope c0 and the adhesion coefficient c),
:mod:`.alphabeta` (c(sigma~) = alpha/sigma~ - beta, cut at 0, and its zero), :mod:`.loss` (the
measured critical roughness: where the plateau falls to a few pillars), :mod:`.intervals` (seed
intervals by a bootstrap over seed labels paired across groups, the preset's discretisation
bias), :mod:`.verdict` (what the page may claim, decided in one place, as states and numbers),
:mod:`.study` (all of it per k~) and :mod:`.size` (the plateau against the brush size n_side).
Numbers and states only: the words are ``campaign/analysis/verdict_text.py``'s. Used by the
``F_P: auto`` planner and by the report.

May import: nothing of the campaign wing (its lowest layer); the core's errors.
"""
