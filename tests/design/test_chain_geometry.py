"""Scoring all designs from the kept prefix geometry equals growing them with the objective."""

from __future__ import annotations

import numpy as np
import pytest

from pneumorph.design.certified.search import chain_errors, chain_geometry, grow_designs
from pneumorph.design.objectives.targets import make_objective
from pneumorph.models.chain.model import ChainModel
from pneumorph.models.chain.sources import find_table
from pneumorph.models.factory import make_model

OBJECTIVES = ["sin", "cos", "y = 0.3*x - 0.002*x**2", "r = 60 - 2*theta", "max-x", "min-y", "min-distance",
              "max-curl", "reach"]


@pytest.fixture(scope="module", params=[("2d", 8), ("3d", 15)], ids=["2d-8", "3d-15"])
def chain(request: pytest.FixtureRequest) -> ChainModel:
    fidelity, n = request.param
    return ChainModel(find_table(make_model(n, {"fidelity": fidelity})), n)


@pytest.mark.parametrize("spec", OBJECTIVES)
def test_kept_geometry_gives_the_grown_scores(chain: ChainModel, spec: str) -> None:
    profile = "=" in spec or spec in ("sin", "cos")
    objective = make_objective(spec, 10.0, point=(60.0, 40.0) if spec == "reach" else None,
                               length=chain.length if profile else None)
    errors = chain_errors(chain)
    kept = grow_designs(chain, objective, errors)  # every design: the kept geometry
    grown = grow_designs(chain, objective, errors, threshold=1e300)  # the same, grown with the objective
    assert np.array_equal(kept.bits, grown.bits) and len(kept.bits) == 2**chain.n_units
    np.testing.assert_allclose(kept.per_level, grown.per_level, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(kept.level, grown.level)
    np.testing.assert_allclose(kept.optimistic, grown.optimistic, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(kept.bound, grown.bound, rtol=1e-12)
    # and the chain model's own prediction of a few designs
    picks = [0, 1, 2**chain.n_units // 3, 2**chain.n_units - 1]
    _centres, tip, curl = chain.predict(kept.bits[picks])
    geom = chain_geometry(chain)
    np.testing.assert_allclose(geom.tip[picks], tip, atol=1e-9)
    np.testing.assert_allclose(geom.curl[picks], curl, atol=1e-9)


def test_the_geometry_is_kept_per_chain_model(chain: ChainModel) -> None:
    assert chain_geometry(chain) is chain_geometry(chain)
    other = ChainModel(chain.table, chain.n_units)
    assert chain_geometry(other) is not chain_geometry(chain)


@pytest.mark.parametrize(("spec", "amplitude", "periods"), [("sin", 10.0, 1.0), ("cos", 20.0, 1.0), ("sin", 3.0, 0.5),
                                                         ("y = 0.3*x", 1.0, 1.0), ("y = 0.001*x**2", 1.0, 1.0)])
def test_best_scores_keep_the_top_and_every_design_that_could_beat_the_best(chain: ChainModel, spec: str,
                                                                             amplitude: float, periods: float) -> None:
    from pneumorph.design.certified.search import best_scores, chain_scores

    objective = make_objective(spec, amplitude, periods, length=chain.length)
    full = chain_scores(chain, objective)
    best = best_scores(chain, objective, top=10)
    f, b = full.order()[:10], best.order()[:10]
    assert np.array_equal(full.bits[f], best.bits[b])
    np.testing.assert_allclose(best.cost[b], full.cost[f], rtol=1e-12)
    worst_case = full.cost[f[0]] + full.bound[f[0]]
    assert (best.optimistic < worst_case).sum() == (full.optimistic < worst_case).sum()
    # every design left out is at least as bad as the floor says
    listed = {bytes(r) for r in best.bits}
    left = np.array([bytes(r) not in listed for r in full.bits])
    assert best.complete or full.optimistic[left].min() >= best.floor
