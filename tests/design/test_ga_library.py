"""The GA over a unit library: genes are type-and-orientation codes, designs are letters.

A two-type toy (a bending unit and a rigid one) stands in for the FE models; every one of
its 4^6 designs is scored by brute force, and the GA must find the optimum.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from pneumorph.design.objectives.fitness import score
from pneumorph.design.objectives.targets import make_objective
from pneumorph.design.search.genetic import GAConfig, _design, mut_other_code, run_ga
from pneumorph.geometry.alphabet import parse_design
from pneumorph.geometry.library import UnitLibrary
from pneumorph.geometry.unit import UnitSpec
from pneumorph.models.response import Response
from tests.design.toy_model import ToyModel

LIBRARY = UnitLibrary(("a", "r"), (UnitSpec(), UnitSpec(solid=True)), ("bending", "near-rigid"), name="toy")


class LibraryToy(ToyModel):
    """The toy chain over the library: ``a``/``A`` turn as the toy's 0/1 units, ``r``/``R`` do not turn."""

    def __init__(self, n_units: int = 6) -> None:
        super().__init__(n_units=n_units)
        self.library = LIBRARY

    def evaluate(self, orientation: str) -> Response:
        design = parse_design(orientation, self.library, self.n_units)
        self.calls.append(design.text)
        bits = np.array([int(c) for c in design.orientation])
        rigid = np.array([s == "r" for s in design.symbols])
        n, ell = self.n_units, self.unit_length
        p = self.pressures()
        ref = np.column_stack([ell * (np.arange(n) + 0.5), np.zeros(n)])
        centres, tips, curls = np.zeros((len(p), n, 2)), np.zeros((len(p), 2)), np.zeros(len(p))
        for k, pk in enumerate(p):
            pos, phi = np.zeros(2), 0.0
            for i, t in enumerate(np.where(rigid, 0.0, self._turns(bits, pk))):
                phi += t / 2
                centres[k, i] = pos + 0.5 * ell * np.array([math.cos(phi), math.sin(phi)])
                phi += t / 2
                pos = centres[k, i] + 0.5 * ell * np.array([math.cos(phi), math.sin(phi)])
            tips[k], curls[k] = pos, math.degrees(phi)
        return Response(design.text, p, centres, ref, tips, np.array([n * ell, 0.0]), curls, True, float(p[-1]),
                        metadata={"fidelity": self.fidelity})


def test_codes_are_written_in_the_librarys_letters() -> None:
    assert _design([0, 1, 1, 0]) == "0110"  # one type: the orientation digits
    assert _design([0, 1, 2, 3], ("a", "r")) == "aArR"
    rng = random.Random(0)
    genes = [rng.randrange(6) for _ in range(2000)]
    mutated = mut_other_code(list(genes), 1.0, 6, rng)[0]
    assert all(m != g for m, g in zip(mutated, genes, strict=True))  # always another code
    counts = np.bincount(mutated, minlength=6)
    assert counts.min() > 250  # every code reached (2000 draws over 6 codes: about 333 each)


def test_a_symmetric_unit_is_written_in_one_letter() -> None:
    """The extending unit turned over is itself: a genome's E is written e, so it is solved once."""
    assert _design([0, 3, 2, 1], ("a", "e"), symmetric=(1,)) == "aeeA"
    library = UnitLibrary(("a", "e"), (UnitSpec(), UnitSpec(wall=3.0, layer=0.0)), ("bending", "extending"),
                          name="toy-ae")
    model = LibraryToy()
    model.library = library
    objective = make_objective("sin", 6.0, length=model.n_units * model.unit_length)
    result = run_ga(model, objective, GAConfig(seed=0, population=20, generations=5, indpb=1 / 6))
    assert model.calls and not any("E" in d for d in model.calls)
    assert len(model.calls) == len(set(model.calls))  # no design solved twice under two names
    assert "E" not in result.best.design


@pytest.mark.slow
def test_ga_over_a_library_finds_the_brute_force_optimum() -> None:
    model = LibraryToy()
    objective = make_objective("sin", 6.0, length=model.n_units * model.unit_length)
    designs = ["".join(_design(list(np.unravel_index(i, (4,) * 6)), ("a", "r"))) for i in range(4**6)]
    values = {d: score(model.evaluate(d), objective).value for d in designs}
    optimum = min(values.values())
    assert min(v for d, v in values.items() if set(d) <= {"a", "A"}) > optimum  # the rigid units matter
    found = 0
    for seed in range(5):
        result = run_ga(model, objective, GAConfig(seed=seed, population=30, generations=60, indpb=1 / 6,
                                                  budget=4**6 // 3))
        assert set(result.best.design) <= set("aArR") and len(result.scores) <= 4**6 // 3
        assert result.best.value == pytest.approx(values[result.best.design])
        found += result.best.value == optimum
    assert found >= 4
