"""Results and files of single simulations: result objects, the HDF5 file, plots, safe writing.

Owns :mod:`.results` (normalised curves, per-preload outcomes, provenance), :mod:`.store`
(the single-run HDF5 layout, written and read back), :mod:`.plot` (figures of one run) and
:mod:`.files` (writability checks, temporary files that vanish on failure, directory fsync:
shared by every writer, the campaign's too).

May import: :mod:`fibril_hpc.inputs` and everything below it; never the model or the API.
"""
