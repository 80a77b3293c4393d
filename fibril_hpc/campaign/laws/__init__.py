"""The laws of a campaign's science, pure functions on numbers (no files, no MPI).

Owns :mod:`.fit` (the "linear, then plateau" law of F~_A(F~_P) per (k~, sigma~), and
c(sigma~) = alpha/sigma~ - beta). Used by the ``F_P: auto`` planner (where to place preloads)
and by the report (what the campaign found).

May import: nothing of the campaign wing (its lowest layer); the core's errors.
"""
