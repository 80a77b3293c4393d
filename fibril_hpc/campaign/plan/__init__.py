"""Grid and planning: what a campaign is and what it runs next.

Owns :mod:`.spec` (grid YAML -> validated :class:`~.spec.CampaignSpec` -> jobs),
:mod:`.sweep` (the ``sweep:`` mapping: n_side and the lab fields), :mod:`.axes` (a record's
brush size, from its stored scene), :mod:`.keys` (the stable job keys and campaign hash: a
contract old files are resumed by),
:mod:`.shard` (disjoint shards of a grid), :mod:`.auto` (``F_P: auto``: the preloads a loading
path gets, round by round) and :mod:`.estimate` (the ``--dry-run`` cost model).

May import: :mod:`fibril_hpc.campaign.laws` and the core (inputs and below).
"""
