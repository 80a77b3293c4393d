"""Reading a campaign back and what it found: data frames, status, exports, the report.

Owns :mod:`.data` (:func:`~.data.load_campaign`), :mod:`.status` (what a file holds and what is
left), :mod:`.export` (CSV, Parquet), :mod:`.report` (the page: fits, figures, tables),
:mod:`.figures` and :mod:`.tables`.

May import: :mod:`fibril_hpc.campaign.storage` and below. Independent of
:mod:`fibril_hpc.campaign.run`.
"""
