"""What a user gives: the scene and solver options, their YAML form, presets, ranges, limits.

Owns :mod:`.scene` (the frozen, validated :class:`~.scene.Scene`), :mod:`.options` (its
:class:`~.options.SolverOptions`), :mod:`.config` (YAML in and out, built-in scenes),
:mod:`.presets` (named accuracy presets), :mod:`.ranges` (declarative field ranges that check
and write the error text), :mod:`.heights` (pillar height and stiffness laws, measured files)
and :mod:`.limits` (grid size, memory and job-count checks before any work starts).

May import: :mod:`fibril_hpc.path` and everything below it (the limits estimate the solver's
memory from the preconditioner a scene would get).
"""
