"""Storage, journal and integrity: the crash-safe campaign file and everything that writes,
checks, merges or rescues it.

Owns :mod:`.record` (:class:`~.record.JobRecord`, the one field list), :mod:`.integrity`
(record checksums), :mod:`.journal` (the append-only checksummed journal), :mod:`.h5read`
(reading the HDF5 file record by record, checked), :mod:`.store` (the file's layout and
writes), :mod:`.writer` (the single writer: lock, identity, replay, checkpoints),
:mod:`.verify` (``verify`` and ``salvage``) and :mod:`.merge`.

May import: :mod:`fibril_hpc.campaign.plan` and below, the core's :mod:`fibril_hpc.io`.
"""
