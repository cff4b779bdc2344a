"""The 2D chain table over the four built-in unit types, shipped as its far-field terms, against 2D FE.

``examples/libraries/chain-2d-builtin-30kpa-far.json`` is window +-2 with far-field terms
fitted to ``Reduced2D`` over the built-in library at 30 kPa from 1,444 covering designs
(docs/chain-model.md). Its file holds the terms; reading it writes out the 1,097,600 windows
of +-3. The design the certified search finds for the sine target, and its closest rivals,
lie within the chain's bound of their 2D FE errors.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from pneumorph.design import make_objective
from pneumorph.design.certified.search import chain_candidate, chain_errors
from pneumorph.design.objectives.fitness import score
from pneumorph.models.chain.model import ChainModel, ChainTable, check_source
from pneumorph.models.chain.tablefile import TERMS_FORMAT
from pneumorph.models.factory import make_model

TABLE = Path(__file__).resolve().parents[2] / "examples" / "libraries" / "chain-2d-builtin-30kpa-far.json"


#: 2D FE errors (mm) to the sine target (A = 10 mm, 15 units, 30 kPa) of the certified winner and its closest rival
FE_2D = {"saRASSSAesessaS": 6.798, "saRASSSAesrsass": 6.798}


@pytest.mark.slow
def test_the_four_type_table_is_its_terms_and_scores_designs_within_its_bound() -> None:
    assert json.loads(TABLE.read_text())["format"] == TERMS_FORMAT
    table = ChainTable.load(TABLE)
    model = make_model(15, {"fidelity": "2d", "library": "builtin", "pressure_kpa": 30})
    check_source(table, model)
    assert table.alphabet == ("a", "e", "r", "s") and table.symmetric == ("e",) and table.window == 3
    assert len(table.codes) == 1_097_600 and len(table.training) == 1_444
    v = table.validation
    assert len(v["designs"]) == 20 and 0.02 < max(v["centre_worst_mm"]) < 0.03
    chain = ChainModel(table, 15)
    objective = replace(make_objective("sin", 10.0), length=chain.length)  # L as the certified search sets it
    bound = chain_errors(chain)["centre"][-1]
    for design, printed in FE_2D.items():
        c = chain_candidate(chain, objective, design)
        fe = score(model.evaluate(design), objective)
        assert c.level == fe.level == 9 and abs(fe.value - printed) < 5e-4
        assert abs(c.value - fe.value) <= bound
