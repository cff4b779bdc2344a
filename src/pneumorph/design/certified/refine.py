"""The certificate's discretisation error: the verified designs again on a finer mesh.

A certified search ranks designs of the FE model *on its mesh*. The mesh itself moves every
value (docs/mesh-convergence.md: the default 1.5 mm hex20 mesh of the 3D model is stiffer
than the converged body), and where two designs lie closer than that, a finer mesh may swap
them. :func:`refine_verified` solves the FE-verified designs of a run again with a smaller
element size, scores them on both meshes, estimates each converged value by Richardson
extrapolation with an order observed in the mesh study (:data:`MESH_ORDER`), and says
whether the winner holds: whether any other verified design could beat it within the
estimated errors.

Examples
--------
>>> rows = [refined_row("01", 7.40, 7.26, 1.5, 0.75, "min", order=2.0),
...         refined_row("10", 7.53, 7.37, 1.5, 0.75, "min", order=2.0)]
>>> [round(r["extrapolated"], 3) for r in rows], [round(r["error"], 3) for r in rows]
([7.213, 7.317], [0.14, 0.16])
>>> v = verdict(rows, "01", "min", order=2.0)
>>> v["holds"], v["could_overtake"], round(v["gaps"]["10"]["limit"], 3)
(True, [], 0.103)
>>> verdict(rows, "01", "min", order=0.5)["could_overtake"]   # a slower convergence: the gap could close
['10']
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from pneumorph.sensitivity.mesh import SAFETY_TWO, converge, refined, representative_size

#: The order of convergence assumed between the default and the refined mesh, per model: the
#: smallest of the orders observed for the tip and the curl of a short actuator on nested
#: meshes (docs/mesh-convergence.md; a smaller order gives a larger, safer error). 3D: one unit
#: on 1.5, 0.75 and 0.375 mm, orders 1.21 (tip x and y) and 1.26 (curl); 2D: one and three
#: units on 1.5, 0.75, 0.375 (and 0.1875) mm, orders 1.42-1.64.
MESH_ORDERS = {"2d": 1.4, "3d": 1.2}
MESH_ORDER = MESH_ORDERS["3d"]
#: designs a run with ``refine`` solves again on the finer mesh at least: the winner and two runners-up, so that
#: the verdict compares the winner with someone even where one batch of verification is a single design
REFINE_TOP = 3


def refined_row(design: str, coarse: float, fine: float, h_coarse: float, h_fine: float, sense: str,
                order: float = MESH_ORDER) -> dict[str, Any]:
    """One design on two meshes: both values, the Richardson estimate and its error (GCI, Fs = 3).

    ``h_coarse`` and ``h_fine`` are representative cell sizes (mm).
    """
    conv = converge((h_coarse, h_fine), (coarse, fine), order=order)
    assert conv.extrapolated is not None
    return {"design": design, "value": coarse, "refined": fine, "change": fine - coarse,
            "extrapolated": conv.extrapolated, "error": conv.error, "sense": sense}


def verdict(rows: Sequence[dict[str, Any]], winner: str, sense: str, order: float = 1.0,
            ratio: float = 2.0) -> dict[str, Any]:
    """Whether ``winner`` holds on the refined mesh and which designs could overtake it.

    ``holds``: no other design is better on the refined mesh. ``could_overtake``: the
    designs whose *gap* to the winner, extrapolated like a value (Richardson with ``order``
    over the cell-size ``ratio`` of the two meshes), could close within its own error
    estimate. The gap, not each value, is extrapolated: the mesh moves designs alike (the
    default mesh is stiffer for all of them), so the error of a difference is far smaller
    than the sum of the two values' errors.
    """
    sign = 1.0 if sense == "min" else -1.0
    ok = [r for r in rows if r.get("refined") is not None]
    best = min(ok, key=lambda r: sign * r["refined"]) if ok else None
    mine = next((r for r in ok if r["design"] == winner), None)
    could, gaps = [], {}
    if mine is not None:
        for r in ok:
            if r["design"] == winner:
                continue
            coarse, fine = sign * (r["value"] - mine["value"]), sign * (r["refined"] - mine["refined"])
            gain = (fine - coarse) / (ratio**order - 1)
            limit, error = fine + gain, SAFETY_TWO * abs(gain)
            gaps[r["design"]] = {"gap": coarse, "refined_gap": fine, "limit": limit, "error": error}
            if limit - error < 0:
                could.append(r["design"])
    return {"holds": best is not None and best["design"] == winner,
            "refined_best": None if best is None else best["design"], "could_overtake": could, "gaps": gaps}


#: The shipped mesh study of the default 3D model (``pneumorph sensitivity mesh``; docs/mesh-convergence.md)
STUDY_FILE = "mesh-study-3d.json"


def load_study(name: str = STUDY_FILE) -> dict[str, Any] | None:
    """The shipped mesh study (its ``mesh.json``), or None if the package has none.

    Read through the one bounded reader (:func:`pneumorph.io.reading.read_json`): a study file
    replaced by hand is refused in one line naming it, as any JSON a user gives.
    """
    from importlib.resources import files

    from pneumorph.errors import DataFormatError
    from pneumorph.io.reading import read_json

    path = Path(str(files("pneumorph.models") / "data" / name))
    if not path.is_file():
        return None
    data = read_json(path, "mesh study", DataFormatError)
    if not isinstance(data, dict):
        raise DataFormatError(f"mesh study {path}: not a mesh study (a JSON object)")
    return data


def mesh_note(model: Any, objective: Any, values: dict[str, float], winner: str,
              study: dict[str, Any] | None = None) -> dict[str, Any] | None:
    """What the mesh study says about a run's verified values, without solving anything.

    Applies where the study's model is the run's (fidelity, units, unit and its element size,
    materials, pressure) and its objective the run's; None otherwise.

    Returns
    -------
    dict or None
        ``sizes_mm`` (the study's coarsest and finest element sizes), ``value_change``
        (least and most change of the objective from the coarsest to the finest mesh over
        the study's designs), ``gap_change`` (the most any gap between two of them changed),
        and ``within``: the verified designs closer to the winner than ``gap_change``,
        whose order the mesh could swap.
    """
    study = load_study() if study is None else study
    if study is None or getattr(model, "dim", None) is None:
        return None
    described = study.get("provenance", {}).get("model", {})
    mine = model.describe()
    keys = ("fidelity", "unit", "n_units", "materials", "pressure_mpa", "library", "quadrature")
    if any(described.get(k) != mine.get(k) for k in keys) or study.get("objective") != objective.label:
        return None
    by_design: dict[str, dict[float, float]] = {}
    for p in study["points"]:
        if p.get("value") is not None:
            by_design.setdefault(p["design"], {})[float(p["element_size_mm"])] = float(p["value"])
    sizes = sorted({h for v in by_design.values() for h in v}, reverse=True)
    if len(sizes) < 2 or sizes[0] != float(model.unit.element_size):
        return None
    coarse, fine = sizes[0], sizes[-1]
    both = {d: v for d, v in by_design.items() if coarse in v and fine in v}
    if len(both) < 2:
        return None
    changes = [v[fine] - v[coarse] for v in both.values()]
    names = sorted(both)
    gap_change = max(abs((both[a][fine] - both[b][fine]) - (both[a][coarse] - both[b][coarse]))
                     for i, a in enumerate(names) for b in names[i + 1:])
    within = [d for d, v in values.items() if d != winner and abs(v - values[winner]) < gap_change]
    return {"sizes_mm": [coarse, fine], "designs": len(both), "value_change": [min(changes), max(changes)],
            "gap_change": gap_change, "within": within}


def check_refine(model: Any, element_size: float, parallel: int = 1) -> None:
    """Refuse a refinement that is not finer than ``model``'s mesh or would not fit in memory (before any solve).

    Raises
    ------
    SearchConfigError
        Not an FE model, or ``element_size`` not below the model's.
    MeshLimitError
        The refined solves (``parallel`` at once) would need more memory than is available.
    GeometryError
        An element size the unit refuses (below its thinnest wall's fraction).
    """
    from pneumorph.errors import SearchConfigError
    from pneumorph.sensitivity.mesh import check_refinement

    size = float(getattr(getattr(model, "unit", None), "element_size", 0.0) or 0.0)
    if not callable(getattr(model, "mesh", None)) or size <= 0:
        raise SearchConfigError("refine needs an FE model with an element size (the 2D or 3D model)")
    if element_size >= size:
        raise SearchConfigError(f"refine = {element_size:g} mm is not finer than the model's element size "
                                f"({size:g} mm); give a smaller one, e.g. {size * 2 / 3:.3g} or {size / 2:g}")
    check_refinement(model, [element_size], parallel=parallel)


def refine_verified(model: Any, objective: Any, designs: Sequence[str], values: dict[str, float], winner: str,
                    element_size: float, evaluator: Any, order: float | None = None,
                    say: Callable[[str], None] = lambda text: None) -> dict[str, Any]:
    """Solve ``designs`` again at ``element_size`` (mm) and compare them with their ``values`` on ``model``'s mesh.

    Parameters
    ----------
    model : FEModel
        The model the designs were verified with.
    objective : ProfileTarget or TipGoal
    designs : sequence of str
        The verified designs (the winner among them).
    values : dict
        Their objective values on ``model``'s mesh.
    winner : str
    element_size : float
        The refined element size, mm (smaller than the model's).
    evaluator : Evaluator
        Solves the refined designs (cached: a rerun resumes).
    order : float, optional
        The order of convergence assumed (default: :data:`MESH_ORDERS` of the model's fidelity).

    Returns
    -------
    dict
        ``element_size_mm`` of both meshes, their representative ``cell_size_mm``, ``order``,
        ``rows`` (each design's values, change, extrapolation and error; ``failure`` where
        the refined solve failed) and the :func:`verdict`.
    """
    from pneumorph.design.objectives.fitness import score
    from pneumorph.models.chain.plan import solve_estimate

    if order is None:
        order = MESH_ORDERS.get(str(getattr(model, "fidelity", "3d")), MESH_ORDER)
    fine = refined(model, element_size)
    h0 = representative_size(model.mesh(winner))
    h1 = representative_size(fine.mesh(winner))
    cells = len(fine.mesh(winner).cells), len(model.mesh(winner).cells)
    say(f"refining: {len(designs)} verified design(s) at {element_size:g} mm elements "
        f"({cells[0]:,} cells against {cells[1]:,}){solve_estimate(model, len(designs), cells[0] / cells[1])}")
    found: dict[int, dict[str, Any]] = {}
    for i, outcome in evaluator.iter_evaluate(fine, list(designs)):
        design = designs[i]
        if outcome.ok:
            s = score(outcome.response, objective)
            row = refined_row(design, values[design], float(s.value), h0, h1, objective.sense, order)
            row["refined_pressure_kpa"] = None if s.pressure is None else round(float(s.pressure) * 1e3, 9)
        else:
            row = {"design": design, "value": values[design], "refined": None, "failure": outcome.failure}
        found[i] = row
        state = f"{row['refined']:.4g}" if row["refined"] is not None else f"failed: {row['failure']}"
        say(f"  {design}: {values[design]:.4g} -> {state}")
    rows = [found[i] for i in sorted(found)]
    return {"element_size_mm": [float(model.unit.element_size), float(element_size)],
            "cell_size_mm": [h0, h1], "order": order, "safety_factor": SAFETY_TWO, "rows": rows,
            **verdict(rows, winner, objective.sense, order, h0 / h1)}


__all__ = ["MESH_ORDER", "MESH_ORDERS", "REFINE_TOP", "STUDY_FILE", "check_refine", "load_study", "mesh_note",
           "refine_verified", "refined_row", "verdict"]
