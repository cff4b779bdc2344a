"""What a run searches when the certified search cannot: the settings' own fall-backs to the GA."""

from __future__ import annotations

from pneumorph.design import DesignConfig


def test_a_certified_search_under_gravity_is_the_gas_and_says_why():
    config, why = DesignConfig(model={"gravity": "hanging"}, certify=True, epsilon=0.1).searchable()
    assert (config.search, config.certify, config.epsilon) == ("ga", False, 0.0)
    assert why is not None and "gravity" in why


def test_a_free_certified_search_is_kept():
    config = DesignConfig()
    assert config.searchable() == (config, None)
    assert DesignConfig(search="ga", model={"gravity": "hanging"}).searchable()[1] is None


def test_the_fallback_of_a_model_the_chain_cannot_represent_is_the_ga_in_2d_unless_the_fidelity_was_given():
    config = DesignConfig(model={"fidelity": "3d"}, chain_table="table.json")
    assert (config.fallback().search, config.fallback().fidelity, config.fallback().chain_table) == ("ga", "2d", None)
    assert config.fallback(fidelity_given=True).fidelity == "3d"
