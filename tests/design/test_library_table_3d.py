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
from pneumorph.design.certified.search import chain_candidate, chain_errors, chain_scores
from pneumorph.models.chain.model import ChainModel, ChainTable, check_source
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


#: 3D FE errors of the designs the certified search verified with the table with far-field terms (docs/unit-library.md)
FE_3D_FAR = {"aRRAArRRrararra": 5.296, "aRRAArRRraraRra": 5.306, "aRRAArRRrararrr": 5.308, "aRRAArRRrararrA": 5.314,
             "aRRAArRrrararra": 5.319, "aRRAArRRrararrR": 5.322, "aRRAArRRraraRrr": 5.322}


def test_the_library_table_with_far_field_terms_scores_the_verified_designs_within_its_bound() -> None:
    """Window +-2 with far-field terms (a table of +-3) from the same 130 covering designs: 26 times closer on
    the held-out designs, and every design the certified search verified lies within its bound of its 3D FE
    error (the FE values to the printed 0.001 mm)."""
    table = ChainTable.load(LIBRARIES / "chain-3d-bending-rigid-far.json")
    plain = ChainTable.load(LIBRARIES / "chain-3d-bending-rigid.json")
    model = make_model(15, {"fidelity": "3d", "library": str(LIBRARIES / "units-bending-rigid.toml")})
    check_source(table, model)
    assert table.window == 3 and table.training == plain.training
    assert table.validation["designs"] == plain.validation["designs"]
    v = table.validation
    assert {t: round(max(e["centre_worst_mm"]), 4) for t, e in v["per_type"].items()} == {"a": 0.0075, "r": 0.0066}
    assert 25 * max(v["centre_worst_mm"]) < max(plain.validation["centre_worst_mm"])
    chain = ChainModel(table, 15)
    objective = make_objective("sin", 10.0, length=chain.length)
    bound = chain_errors(chain)["centre"][-1] * np.sqrt(15 * (1 + (2 * np.pi * 10.0 / chain.length) ** 2))
    for design, fe in FE_3D_FAR.items():
        c = chain_candidate(chain, objective, design)
        assert c.level == 9 and abs(c.value - fe) <= bound + 5e-4, (design, c.value, fe, bound)
    best = chain_scores(chain, objective)
    assert chain.table.texts(best.bits[best.order()[:1]])[0] == "aRRAArRRrararra"
