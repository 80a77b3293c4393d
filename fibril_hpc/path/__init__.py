"""The load path: displacement-controlled loading to the preloads, then pull-off to complete
detachment, event by event.

Owns :mod:`.loading` (the event-driven path driver), :mod:`.machine` (a compliant loading
machine around it), :mod:`.records` (curve points, snapshots, branch results: plain data) and
:mod:`.criterion` (the detachment criterion's calibration factor; the calibration run itself is
passed in by the caller, so this layer never imports the API above it).

May import: :mod:`fibril_hpc.solve` and everything below it.
"""
