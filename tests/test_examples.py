"""Every example configuration is valid and describes what its name says."""

from pathlib import Path

import pytest

from pneumorph.design import DesignConfig

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))


def test_the_dissertation_targets_are_all_there() -> None:
    names = {p.stem for p in EXAMPLES}
    assert {"sin-10", "sin-15", "sin-20", "cos-20", "cos-40", "cos-60"} <= names
    assert {"tip-max-x", "tip-min-x", "tip-max-y", "tip-min-distance"} <= names


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_is_a_valid_design_config(path: Path) -> None:
    c = DesignConfig.read(path)
    assert c.units == 15 and c.ga.population == 100 and c.ga.generations == 15
    kind, _, rest = path.stem.partition("-")
    if kind in ("sin", "cos"):
        assert c.objective == kind and c.amplitude == float(rest)
    else:
        assert c.objective == rest
