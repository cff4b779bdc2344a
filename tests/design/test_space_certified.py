"""The certified search over sideways units, end to end against the full 3D model.

The chain table is that of the built-in spatial library on 5-unit designs at 10 kPa, made with
`pneumorph chain build --model 3d --library spatial --units 5 --pressure 10 --window 1 --short --heldout 2
--all-heldout --out tests/data/chain-3d-spatial-5u-10kpa.json` (19 covering designs solved on the full width;
held-out worst centre error 0.156 mm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pneumorph.design.certified.certificate import certificate_text
from pneumorph.design.certified.search import certified_search, planar_codes
from pneumorph.design.objectives.targets import make_objective
from pneumorph.models.chain.model import ChainModel, ChainTable, check_source
from pneumorph.models.factory import make_model

TABLE = Path(__file__).parents[1] / "data" / "chain-3d-spatial-5u-10kpa.json"
pytestmark = pytest.mark.slow  # a certified search over the spatial library, verified by full-width 3D solves


@pytest.fixture(scope="module")
def searched() -> tuple:
    model = make_model(5, {"fidelity": "3d", "library": "spatial", "pressure_kpa": 10})
    table = ChainTable.load(TABLE)
    check_source(table, model)  # fitted on the full width, it serves the model that solves planar designs on half
    chain = ChainModel(table, 5)
    objective = make_objective("helix", 3.0, length=chain.length)
    return model, chain, certified_search(model, chain, objective, verify=1)


def test_the_winner_leaves_the_plane_and_beats_the_best_planar_design_by_fe(searched: tuple) -> None:
    model, chain, result = searched
    winner, planar = result.winner, result.certificate["planar"]
    assert set(winner.design) & set("lL") and not set(planar["design"]) & set("lL")
    assert winner.response.axes == 3 and np.abs(winner.response.tip[-1, 2] - 7.5) > 0.3  # off the plane, in FE
    assert winner.value < planar["fe"] - 0.1  # the plane alone cannot follow the helix as well
    assert result.solves == 2  # the winner and the best planar design
    assert planar_codes(model, chain).tolist() == [0, 1]


def test_the_chain_in_space_predicts_the_verified_designs_within_its_bound(searched: tuple) -> None:
    _, chain, result = searched
    fe, predicted = result.winner.response, chain.evaluate(result.winner.design)
    worst = float(np.linalg.norm(predicted.centres - fe.centres, axis=-1).max())
    assert worst <= max(chain.table.validation["centre_worst_mm"])  # what the certificate's bound assumes
    assert abs(result.winner_chain.value - result.winner.value) <= result.certificate["bound"]
    lines = certificate_text(result.certificate, "mm", result.winner.design, "3d")
    planar = result.certificate["planar"]["design"]
    assert lines[-1].startswith(f"In the plane: the best design without sideways units is {planar}")
