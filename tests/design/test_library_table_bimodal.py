"""The 3D chain table over the bending and bimodal units (40 kPa) against its model and the 3D FE verifications.

``examples/libraries/chain-3d-bending-bimodal-40kpa-far.json`` is window +-2 with far-field terms
fitted to ``Full3D`` over ``examples/libraries/units-bending-bimodal.toml`` at 40 kPa (150
solves; docs/stages.md). For the two stages of the worked example (16 kPa ``y = 0.0015*x**2``,
40 kPa ``y = -0.0015*x**2``) the chain's costs of the six designs the certified search verified
lie within its bound of their 3D FE costs, and its best design is the certified winner.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pneumorph.design import make_objective
from pneumorph.design.certified.search import chain_scores
from pneumorph.design.objectives.targets import staged_target
from pneumorph.models.chain.model import ChainModel, ChainTable, check_source
from pneumorph.models.factory import make_model

LIBRARIES = Path(__file__).resolve().parents[2] / "examples" / "libraries"
#: 3D FE costs (mm) of the designs the certified search verified (docs/stages.md)
FE_3D = {"bbabbAabbbaAbaa": 5.869, "bbabbAabbbaAbaA": 5.904, "bbabbAabbbaAbab": 5.909, "bbabbAabbbaAbaB": 6.058,
         "bbabbAabbbaAbBA": 6.077, "bbabbAabbbaAbBB": 6.111}


def test_the_bimodal_library_table_fits_its_model_and_scores_the_verified_designs_within_its_bound() -> None:
    table = ChainTable.load(LIBRARIES / "chain-3d-bending-bimodal-40kpa-far.json")
    model = make_model(15, {"fidelity": "3d", "pressure_kpa": 40,
                            "library": str(LIBRARIES / "units-bending-bimodal.toml")})
    check_source(table, model)  # the table belongs to the model `--library ... --pressure 40` builds
    assert table.alphabet == ("a", "b") and table.window == 3 and np.allclose(table.pressures, model.pressures())
    v = table.validation
    assert len(v["designs"]) == 20 and not set(v["designs"]) & set(table.training)
    assert {t: round(max(e["centre_worst_mm"]), 4) for t, e in v["per_type"].items()} == {"a": 0.034, "b": 0.0576}
    chain = ChainModel(table, 15)
    staged = staged_target([(0.016, make_objective("y = 0.0015*x**2")), (0.040, make_objective("y = -0.0015*x**2"))])
    scores = chain_scores(chain, staged)
    order = scores.order()
    names = table.texts(scores.bits[order])
    assert names[0] == "bbabbAabbbaAbaa"
    for design, fe in FE_3D.items():
        i = order[names.index(design)]
        assert abs(scores.cost[i] - fe) <= scores.bound[i] + 5e-4, (design, scores.cost[i], fe)
