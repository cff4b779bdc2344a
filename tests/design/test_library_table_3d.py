"""The 3D chain table shipped with the bending/near-rigid library against its model and 3D FE.

``examples/libraries/chain-3d-bending-rigid.json`` was fitted to ``Full3D`` over
``examples/libraries/units-bending-rigid.toml`` (150 solves). Its held-out validation holds
per unit type, it belongs to the model the CLI builds for that library, and on the sine
target the chain's scores of the designs in docs/unit-library.md lie within the chain's
error bound of their 3D FE errors there (5.296 and 5.722 mm, solved with `Full3D`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pneumorph.design import make_objective
from pneumorph.design.certified import chain_candidate, chain_errors, chain_scores
from pneumorph.models.chain import ChainModel, ChainTable, check_source
from pneumorph.models.factory import make_model

LIBRARIES = Path(__file__).resolve().parents[2] / "examples" / "libraries"
#: 3D FE errors to the sine target (A = 10 mm, 15 units, 45 kPa), docs/unit-library.md
FE_3D = {"aRRAArRRrararra": 5.296, "aRRAARrRRaRRaRA": 5.722}


def test_the_shipped_3d_library_table_fits_its_model_and_its_documented_fe_errors() -> None:
    table = ChainTable.load(LIBRARIES / "chain-3d-bending-rigid.json")
    model = make_model(15, {"fidelity": "3d", "library": str(LIBRARIES / "units-bending-rigid.toml")})
    check_source(table, model)  # the table belongs to the model `--library` builds
    assert table.alphabet == ("a", "r") and np.allclose(table.pressures, model.pressures())
    v = table.validation
    assert len(v["designs"]) == 20 and not set(v["designs"]) & set(table.training)
    assert max(v["centre_worst_mm"]) <= 0.2
    assert {t: round(max(e["centre_worst_mm"]), 3) for t, e in v["per_type"].items()} == {"a": 0.153, "r": 0.193}
    chain = ChainModel(table, 15)
    objective = make_objective("sin", 10.0, length=chain.length)
    bound = chain_errors(chain)["centre"][-1]  # at 45 kPa, where both designs score best
    for design, fe in FE_3D.items():
        c = chain_candidate(chain, objective, design)
        assert c.level == 9 and abs(c.value - fe) <= bound
    best = chain_scores(chain, objective)
    assert best.bits.shape[1] == 15 and chain.table.texts(best.bits[best.order()[:1]])[0] == "aRRAArRRrararra"
