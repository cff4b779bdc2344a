"""The chain model: an actuator's response from a table of per-window chord turns and lengths.

Each concept has a module of its own; the names most used (``ChainModel``, ``ChainTable``,
``build_table``) are imported from :mod:`pneumorph.models`:

- :mod:`~pneumorph.models.chain.model`: ``ChainModel``, the response a table predicts;
- :mod:`~pneumorph.models.chain.table`: ``ChainTable``, the table, its file and
  fingerprint (the layouts in :mod:`~pneumorph.models.chain.tablefile`);
- :mod:`~pneumorph.models.chain.windows`, :mod:`~pneumorph.models.chain.terms`,
  :mod:`~pneumorph.models.chain.space`: a design's windows, far-field terms, chords in space;
- :mod:`~pneumorph.models.chain.fit`, :mod:`~pneumorph.models.chain.means`,
  :mod:`~pneumorph.models.chain.reference`, :mod:`~pneumorph.models.chain.training`,
  :mod:`~pneumorph.models.chain.validation`: the fit of a table from FE solves (its turns and
  lengths, its undeformed geometry) and its held-out check;
- :mod:`~pneumorph.models.chain.plan`, :mod:`~pneumorph.models.chain.sources`: what a build
  will cost, and where a table comes from (shipped, a user's folder, a new build).

Examples
--------
>>> from pneumorph.models.chain.sources import shipped_path
>>> from pneumorph.models.chain.table import ChainTable
>>> table = ChainTable.load(shipped_path("3d"))
>>> table.window, table.n_levels
(3, 10)
"""

__all__: list[str] = []  # ChainModel, ChainTable and build_table are re-exported by pneumorph.models
