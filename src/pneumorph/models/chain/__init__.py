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

from pneumorph.models.chain.fit import (
    build_table as build_table,
)
from pneumorph.models.chain.model import (
    ALPHABET_FORMAT as ALPHABET_FORMAT,
)
from pneumorph.models.chain.model import (
    BASE as BASE,
)
from pneumorph.models.chain.model import (
    TABLE_FORMAT as TABLE_FORMAT,
)
from pneumorph.models.chain.model import (
    TIP as TIP,
)
from pneumorph.models.chain.model import (
    ChainModel as ChainModel,
)
from pneumorph.models.chain.model import (
    ChainTable as ChainTable,
)
from pneumorph.models.chain.model import (
    check_source as check_source,
)
from pneumorph.models.chain.model import (
    covering_designs as covering_designs,
)
from pneumorph.models.chain.model import (
    design_array as design_array,
)
from pneumorph.models.chain.model import (
    design_strings as design_strings,
)
from pneumorph.models.chain.model import (
    in_space as in_space,
)
from pneumorph.models.chain.model import (
    mirror_codes as mirror_codes,
)
from pneumorph.models.chain.model import (
    possible_codes as possible_codes,
)
from pneumorph.models.chain.model import (
    source_description as source_description,
)
from pneumorph.models.chain.model import (
    source_key as source_key,
)
from pneumorph.models.chain.model import (
    training_model as training_model,
)
from pneumorph.models.chain.model import (
    window_codes as window_codes,
)
from pneumorph.models.chain.model import (
    window_symbols as window_symbols,
)
from pneumorph.models.chain.model import (
    window_text as window_text,
)
from pneumorph.models.chain.sources import (
    find_table as find_table,
)
from pneumorph.models.chain.sources import (
    serve_table as serve_table,
)
from pneumorph.models.chain.sources import (
    shipped_path as shipped_path,
)
from pneumorph.models.chain.sources import (
    table_for as table_for,
)

# the public place of these names is :mod:`pneumorph.models` (its reference page); here they are
# importable by their package too
__all__: list[str] = []
