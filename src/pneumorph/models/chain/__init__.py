"""The chain model: an actuator's response from a table of per-window chord turns and lengths.

The public import place of the chain surrogate; each concept has a module of its own:

- :mod:`~pneumorph.models.chain.model`: :class:`ChainModel`, the response a table predicts;
- :mod:`~pneumorph.models.chain.table`: :class:`ChainTable`, the table, its file and
  fingerprint (the layouts in :mod:`~pneumorph.models.chain.tablefile`);
- :mod:`~pneumorph.models.chain.windows`, :mod:`~pneumorph.models.chain.terms`,
  :mod:`~pneumorph.models.chain.space`: a design's windows, far-field terms, chords in space;
- :mod:`~pneumorph.models.chain.fit`, :mod:`~pneumorph.models.chain.means`,
  :mod:`~pneumorph.models.chain.training`, :mod:`~pneumorph.models.chain.validation`: the
  fit of a table from FE solves and its held-out check;
- :mod:`~pneumorph.models.chain.plan`, :mod:`~pneumorph.models.chain.sources`: what a build
  will cost, and where a table comes from (shipped, a user's folder, a new build).

Examples
--------
>>> from pneumorph.models.chain import ChainTable, shipped_path
>>> table = ChainTable.load(shipped_path("3d"))
>>> table.window, table.n_levels
(3, 10)
"""

from pneumorph.models.chain.fit import build_table
from pneumorph.models.chain.model import (
    ALPHABET_FORMAT,
    BASE,
    TABLE_FORMAT,
    TIP,
    ChainModel,
    ChainTable,
    check_source,
    covering_designs,
    design_array,
    design_strings,
    in_space,
    mirror_codes,
    possible_codes,
    source_description,
    source_key,
    training_model,
    window_codes,
    window_symbols,
    window_text,
)
from pneumorph.models.chain.sources import find_table, serve_table, shipped_path, table_for

__all__ = ["ALPHABET_FORMAT", "BASE", "TABLE_FORMAT", "TIP", "ChainModel", "ChainTable", "build_table", "check_source",
           "covering_designs", "design_array", "design_strings", "find_table", "in_space", "mirror_codes",
           "possible_codes", "serve_table", "shipped_path", "source_description", "source_key", "table_for",
           "training_model", "window_codes", "window_symbols", "window_text"]
