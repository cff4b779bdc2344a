"""The FE models over a unit library: fingerprints kept, mixed designs solved in 2D."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from pneumorph.errors import OrientationError, SearchConfigError, SettingsError
from pneumorph.geometry.library import UnitLibrary, builtin_library
from pneumorph.geometry.unit import UnitSpec
from pneumorph.materials import get_filler
from pneumorph.models.factory import make_model
from pneumorph.models.fe import Full3D, RampSpec, Reduced2D

#: the fingerprints of the default models before unit libraries existed (caches and shipped tables rest on them)
FINGERPRINT_2D = "cdfe22c3b5df0046"
FINGERPRINT_3D = "3b6cc938464fbc6c"
RAMP = RampSpec(pressure=0.01)


def coarse_library() -> UnitLibrary:
    """The built-in bending, near-rigid and short units, meshed coarsely (3 mm elements) for quick 2D solves.

    (The extending unit's 3 mm walls put lines across the height that a 3 mm mesh of the bending
    unit does not have, so it joins the others only at the built-in 1.5 mm.)
    """
    lib = builtin_library()
    keep = ("a", "r", "s")
    return UnitLibrary(keep, tuple(replace(lib[s], element_size=3.0) for s in keep),
                       tuple(lib.modes[lib.symbols.index(s)] for s in keep), name="coarse")


def test_every_existing_configuration_keeps_its_fingerprint(tmp_path: Path) -> None:
    one = tmp_path / "one.toml"
    one.write_text('[library]\nname = "mine"\n[[units]]\nsymbol = "q"\nunit = {}\n')
    assert Reduced2D(15).fingerprint() == FINGERPRINT_2D
    assert Full3D(15).fingerprint() == FINGERPRINT_3D
    assert Reduced2D(15, UnitSpec()).fingerprint() == FINGERPRINT_2D
    assert Reduced2D(15, library=UnitLibrary.single()).fingerprint() == FINGERPRINT_2D
    assert Full3D(15, library=UnitLibrary.single()).fingerprint() == FINGERPRINT_3D
    assert make_model(15).fingerprint() == FINGERPRINT_2D
    assert make_model(15, {"fidelity": "3d"}).fingerprint() == FINGERPRINT_3D
    # a one-type library file is its unit: the same model, whatever the library's name or symbol
    assert make_model(15, {"library": str(one)}).fingerprint() == FINGERPRINT_2D
    assert make_model(15, {"library": str(one), "fidelity": "3d"}).fingerprint() == FINGERPRINT_3D
    assert "library" not in Reduced2D(15).describe() and "fillers" not in Reduced2D(15).describe()


def test_a_library_of_several_types_is_in_the_fingerprint() -> None:
    lib = builtin_library()
    m2, m3 = Reduced2D(15, library=lib), Full3D(15, library=lib)
    assert m2.fingerprint() not in (FINGERPRINT_2D, m3.fingerprint())
    assert m2.describe()["library"] == lib.to_dict()
    assert m2.describe()["unit"] == UnitSpec().to_dict()  # the first type, as before
    assert Reduced2D(15, library=coarse_library()).fingerprint() != m2.fingerprint()
    # the 3D model has no filler: no filler law of any type in its description
    units = m3.describe()["library"]["units"]
    assert units and not any(k.startswith("filler_") for u in units for k in u["unit"])
    assert make_model(15, {"library": "builtin"}).fingerprint() == m2.fingerprint()
    assert make_model(15, {"library": "builtin", "fidelity": "3d"}).fingerprint() == m3.fingerprint()
    # a variant keeps the library
    assert m2.variant().fingerprint() == m2.fingerprint()
    assert m3.with_units(4).library is lib


def test_each_unit_type_has_its_filler_law_in_2d() -> None:
    lib = builtin_library()
    m = Reduced2D(15, library=lib)
    # the bending unit's calibrated law; the others have none calibrated yet and take Eq 5.2
    assert m.fillers["a"] == UnitSpec().filler_law() and m.filler == UnitSpec().filler_law()
    assert m.fillers["e"] == get_filler() and m.fillers["s"] == get_filler()
    assert m.describe()["fillers"]["e"] == get_filler().to_dict()


def test_mixed_designs_solve_in_2d_and_responses_keep_their_text() -> None:
    lib = coarse_library()
    mixed = Reduced2D(3, library=lib, ramp_spec=RAMP)
    r = mixed.evaluate("aSr")
    assert r.converged and r.orientation == "aSr" and r.n_units == 3
    # a unit of each type where it belongs: the short unit's centre 7 mm after its start
    r = mixed.evaluate("asa")
    assert np.allclose(np.diff(r.reference_centres[:, 0]), [(10.5 + 7.0) / 2, (7.0 + 10.5) / 2])
    # a 0/1 design over the library is the one-type design, solved the same to the last bit
    over = mixed.evaluate("010")
    alone = Reduced2D(3, lib["a"], RAMP).evaluate("010")
    assert over.orientation == "aAa" and alone.orientation == "010"
    assert np.array_equal(over.centres, alone.centres) and np.array_equal(over.curl, alone.curl)
    # an extending-only design meshes without layer cells and takes the extending unit's own law
    lib = builtin_library()
    ee = Reduced2D(2, library=lib, ramp_spec=RAMP).evaluate("eE")
    single = Reduced2D(2, lib["e"], RAMP).evaluate("01")
    assert np.allclose(ee.centres, single.centres, atol=1e-9, rtol=0)
    # its symmetric section lengthens without turning (to the solver's tolerance)
    assert abs(ee.curl[-1]) < 1e-3 and ee.tip[-1][0] > ee.reference_tip[0] + 0.05


def test_bad_designs_and_settings_are_refused_before_solving(tmp_path: Path) -> None:
    m = Reduced2D(3, library=builtin_library())
    with pytest.raises(OrientationError, match=r"'x'.*allowed: a/A"):
        m.evaluate("aax")
    with pytest.raises(OrientationError, match="expected 3"):
        m.evaluate("aa")
    with pytest.raises(SettingsError, match="not both"):
        Reduced2D(3, UnitSpec(pitch=9.0), library=builtin_library())
    with pytest.raises(SettingsError, match="goes to library="):
        Reduced2D(3, builtin_library())  # type: ignore[arg-type]
    with pytest.raises(SearchConfigError, match="not both"):
        make_model(3, {"library": "builtin", "unit": {}})
    twice = tmp_path / "twice.toml"
    twice.write_text('[[units]]\nsymbol = "a"\n[[units]]\nsymbol = "a"\n')
    with pytest.raises(SearchConfigError, match=r"\[model\] library: .*symbol 'a' is given twice"):
        make_model(3, {"library": str(twice)})
