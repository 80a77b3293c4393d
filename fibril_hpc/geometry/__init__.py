"""Geometry: the lattice, the element grid, pillar footprints and heights, normalisation.

Owns :mod:`.scaling` (every normalisation factor), :mod:`.grid` (element grid, footprints,
labels, the random pillar lengths), :mod:`.tips` (shaped tips as height offsets) and
:mod:`.shapes` (validation indenters). Pure NumPy: no FFT, no solver, no files.

May import: :mod:`fibril_hpc.errors` only (the lowest layer with :mod:`fibril_hpc.kernels`).
"""
