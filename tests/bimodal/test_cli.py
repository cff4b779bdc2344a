"""``pneumorph bimodal`` on a one-void actuator."""

from __future__ import annotations

import json

import pytest

from pneumorph.bimodal.model import bulk_from_poisson
from pneumorph.cli import main


def test_json_run(tmp_path, capsys) -> None:
    code = main(["bimodal", "-c", "0.3", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
                 "--json",
                 "--out", str(tmp_path)])
    assert code == 0
    d = json.loads(capsys.readouterr().out)
    assert d["pressures_kpa"] == [5.0] and d["completed"]
    # the default composite: the Ecoflex matrix with the paper along the actuator
    assert d["metadata"]["model"]["materials"]["bilinear"] == "ecoflex_0030"
    assert d["metadata"]["model"]["composite"].startswith("fibre") and d["metadata"]["model"]["paper"] == "measured"
    assert {p.split("/")[-1] for p in d["files"]} == {"bimodal-cr0_3.json", "bimodal-cr0_3-tip.png",
                                                      "bimodal-cr0_3-shape.png"}


def test_text_run_with_poisson(capsys) -> None:
    code = main(["bimodal", "-c", "0.2", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
                 "-q", "--bilinear-nu", "0.45"])
    assert code == 0
    out = capsys.readouterr().out
    assert "switch pressure" in out and "none below 5 kPa" in out
    assert out.splitlines()[-1] == "nothing written: --out DIR keeps the response (JSON) and the figures"


def test_text_run_says_where_its_files_went(tmp_path, capsys) -> None:
    code = main(["bimodal", "-c", "0.3", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
                 "-q", "--out", str(tmp_path / "b")])
    assert code == 0
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"written to {tmp_path / 'b'}/ (bimodal-cr0_3.json, bimodal-cr0_3-tip.png, bimodal-cr0_3-shape.png)")


def test_homogenised_composite_and_its_poisson_ratio(capsys) -> None:
    """``--composite homogenised`` is the Table B.1 material; ``--bilinear-nu`` sets the bulk modulus of the
    composite's own material: K = 2 mu0 (1 + nu) / (3 (1 - 2 nu)) of Table B.1's or of the Ecoflex matrix's mu0."""
    from pneumorph.materials import get

    base = ["bimodal", "-c", "0.2", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
            "--json", "--bilinear-nu", "0.45"]
    for composite, material in (("homogenised", "bilinear_0_2"), ("fibre", "ecoflex_0030")):
        assert main([*base, "--composite", composite]) == 0
        m = json.loads(capsys.readouterr().out)["metadata"]["model"]
        assert m["materials"]["bilinear"] == material
        assert m["bulk_moduli_kpa"]["bilinear"] == pytest.approx(1e3 * get(material).shear_modulus * 2 * 1.45 / 0.3)


def test_the_ideal_paper(capsys) -> None:
    """``--paper ideal``: the crimp slack until its analytic straightening, below it the plain Ecoflex layer's
    actuator (the same as ``--paper measured`` would be only if the cast paper carried nothing before)."""
    base = ["bimodal", "-c", "0.2", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
            "--json"]
    tips = {}
    for paper in ("ideal", "measured"):
        assert main([*base, "--paper", paper]) == 0
        d = json.loads(capsys.readouterr().out)
        assert d["metadata"]["model"]["paper"] == paper
        tips[paper] = d["tip_uy_mm"][0]
    assert abs(tips["ideal"] - tips["measured"]) > 0.01 * abs(tips["ideal"])


def test_the_default_end_is_the_geometrys(capsys) -> None:
    """``--end-cap`` left out is :class:`BimodalSpec`'s end cap (its help says which), kept in the JSON's spec."""
    from pneumorph.bimodal.geometry import BimodalSpec

    assert main(["bimodal", "--help"]) == 0
    assert f"the geometry's, {BimodalSpec().end_cap:g} mm" in " ".join(capsys.readouterr().out.split())
    base = ["bimodal", "-c", "0.3", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
            "--json"]
    for given, cap in (([], BimodalSpec().end_cap), (["--end-cap", "0"], 0.0)):
        assert main([*base, *given]) == 0
        assert json.loads(capsys.readouterr().out)["metadata"]["model"]["spec"]["end_cap"] == cap


def test_bad_crimp_ratio(capsys) -> None:
    assert main(["bimodal", "-c", "0.35"]) == 2
    assert "0.35" in capsys.readouterr().err


def test_bulk_from_poisson() -> None:
    # K = 2 mu (1 + nu) / (3 (1 - 2 nu)); nu = 0.25 gives K = 5/3 mu
    assert bulk_from_poisson(3.0, 0.25) == pytest.approx(5.0)


def test_a_ramp_that_ends_early_is_not_a_success(tmp_path, capsys) -> None:
    """One Newton iteration and no cut-back cannot reach the first level: the table is printed, the outputs
    written, and the command ends with one line naming the cause and exit 2 (not 0)."""
    code = main(["bimodal", "-c", "0.3", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure",
                 "--max-iterations", "1", "--max-cutbacks", "0", "-q", "--out", str(tmp_path)])
    captured = capsys.readouterr()
    assert code == 2
    assert "ramp ended early" in captured.out
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: simulation failed, converged up to 0 kPa of 5 kPa")
    assert "printed and written" in err[0]
    assert (tmp_path / "bimodal-cr0_3.json").is_file()


def test_the_plan_is_estimated_by_the_mesh_and_a_mesh_past_the_memory_is_refused(monkeypatch, tmp_path,
                                                                                   capsys) -> None:
    """The full-size actuator (15 voids, 2.5 mm: 15,807 nodes with a 1.5 mm end wall, 16,291 with the default 6 mm
    one, the meshes the estimate is measured on) is planned at LEVEL_SECONDS x 16,291^(4/3) = 7.8 s a level on a
    quiet machine; 100 voids at 1 mm (863,373 nodes, 135 GB) are
    refused in one line before the solve, nothing written."""
    from pneumorph.bimodal.geometry import BimodalSpec, mesh_actuator
    from pneumorph.bimodal.model import BimodalModel
    from pneumorph.cli.bilinear.bimodal import LEVEL_SECONDS
    from pneumorph.io.progress import duration_text

    def stopped(self: BimodalModel, on_level: object = None) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(BimodalModel, "solve", stopped)
    monkeypatch.setattr("pneumorph.io.progress.os.getloadavg", lambda: (0.0, 0.0, 0.0))  # a quiet machine
    assert len(mesh_actuator(BimodalSpec(voids=15, element_size=2.5, end_cap=0.0)).points) == 15_807
    assert len(mesh_actuator(BimodalSpec(voids=15, element_size=2.5)).points) == 16_291
    each = LEVEL_SECONDS * 16_291 ** (4 / 3)
    assert each == pytest.approx(7.85, abs=0.01)
    assert main(["bimodal", "-c", "0.2", "--out", str(tmp_path / "full")]) == 130
    plan = capsys.readouterr().err.splitlines()[0]
    assert plan == (f"bimodal ramp of the voids' volume to 9 V0 in 12 steps: 12 levels, estimated "
                    f"{duration_text(12 * each)} ({duration_text(each)} each, 1 worker)")
    out = tmp_path / "long"
    assert main(["bimodal", "-c", "0.2", "--voids", "100", "--element-size", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and not out.exists()
    assert "--voids 100 --element-size 1: a mesh of about 863,373 nodes, 135.0 GB for the solve" in err


@pytest.mark.parametrize(("option", "vector"), [([], None), (["--gravity", "none"], None),
                                                (["--gravity", "hanging"], [9806.65, 0.0, 0.0])])
def test_gravity_reaches_the_model_and_its_description(monkeypatch, capsys, option, vector) -> None:
    """``--gravity hanging`` is the model's standard gravity along x (hanging from the clamped base), in the
    description the JSON keeps (``metadata.model.gravity_mm_s2``); without it the description has none, as before.
    The solve is replaced by one that records the model it was asked of."""
    from pneumorph.bimodal.model import BimodalModel
    from pneumorph.errors import SettingsError

    seen = []

    def solve(self, **kwargs):
        seen.append((self.gravity, self.describe()))
        raise SettingsError("solve reached")

    monkeypatch.setattr(BimodalModel, "solve", solve)
    argv = ["bimodal", "-c", "0.2", "--voids", "1", "--element-size", "5", "--pmax", "5", "--control", "pressure"]
    assert main([*argv, "-q", *option]) == 2
    assert capsys.readouterr().err.strip() == "error: solve reached"
    ((gravity, described),) = seen
    assert (None if gravity is None else list(gravity)) == vector
    assert described.get("gravity_mm_s2") == vector


def test_the_summary_says_the_actuator_hangs() -> None:
    from pneumorph.cli.bilinear.bimodal import format_result

    d = {"crimp_ratio": 0.2, "completed": True, "pressures_kpa": [5.0], "tip_ux_mm": [0.1], "tip_uy_mm": [0.2],
         "switch": {"turning_kpa": None, "peak_mm": None, "switch_kpa": None},
         "metadata": {"dofs": 10, "wall_time_s": 1.0,
                      "model": {"composite": "homogenised", "bulk_moduli_kpa": {"bilinear": 58.3}}}}
    assert not format_result(d).splitlines()[0].endswith("under gravity")
    d["metadata"]["model"]["gravity_mm_s2"] = [9806.65, 0.0, 0.0]
    assert format_result(d).splitlines()[0].endswith(", its bulk modulus 58.3 kPa, hanging under gravity")


def test_the_plan_counts_its_nodes_without_meshing(monkeypatch, tmp_path, capsys) -> None:
    """A mesh past the memory is refused from its node count alone (node_count, from the grid lines): no mesh of
    the actuator is built before the refusal."""
    import pneumorph.bimodal.geometry as geometry

    def meshing(*args: object, **kwargs: object) -> None:
        raise AssertionError("the plan meshed the actuator")

    monkeypatch.setattr(geometry, "mesh_actuator", meshing)
    out = tmp_path / "long"
    assert main(["bimodal", "-c", "0.2", "--voids", "100", "--element-size", "1", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "a mesh of about 863,373 nodes, 135.0 GB for the solve" in err and not out.exists()
