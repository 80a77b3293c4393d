"""Reading a campaign back and what it found: data frames, status, exports, the report.

Owns :mod:`.data` (:func:`~.data.load_campaign`), :mod:`.status` (what a file holds and what is
left), :mod:`.export` (CSV, Parquet), :mod:`.report` (the report's orchestrator),
:mod:`.report_data` (its numbers, from :mod:`fibril_hpc.campaign.laws`), :mod:`.figures`,
:mod:`.figures_coeff` and :mod:`.figures_size` (its figures; the last for a grid sweeping
n_side), :mod:`.verdict_text` (the one place that puts the laws' states and numbers into
words), :mod:`.tables` and :mod:`.page` (``README.md`` and the self-contained ``report.html``).

May import: :mod:`fibril_hpc.campaign.storage` and below. Independent of
:mod:`fibril_hpc.campaign.run`.
"""
