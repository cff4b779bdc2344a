"""The bench API's fields as JSON Schema: every route's request and answer in the app's OpenAPI description.

FastAPI derives a route's query and path parameters from its signature, but the bench reads
its bodies itself (:func:`~pneumorph.bench.query.parse_query`, so that a bad field is one
error naming it) and answers with plain data, so neither would be described. This module
describes them; :func:`describe` adds them to ``app.openapi()``. The documentation site
renders that description as tables (``docs/bench-api.md``), and the tests check real
answers against it field by field, so the page and the API cannot part.
"""

from __future__ import annotations

from typing import Any

from pneumorph.bench.jobs import STATES
from pneumorph.bench.query import KINDS, MAX_TOP, MODELS, STAGE_KINDS
from pneumorph.design.objectives.paths import PATH_PRESETS
from pneumorph.design.objectives.targets import PRESETS, TIP_GOALS

Schema = dict[str, Any]


def _obj(description: str, required: dict[str, Schema], optional: dict[str, Schema] | None = None) -> Schema:
    return {"type": "object", "description": description, "properties": {**required, **(optional or {})},
            "required": list(required), "additionalProperties": False}


def _t(kind: str, description: str, **extra: Any) -> Schema:
    return {"type": kind, "description": description, **extra}


def _list(items: Schema, description: str) -> Schema:
    return {"type": "array", "description": description, "items": items}


def _null(schema: Schema) -> Schema:
    return {**schema, "type": [schema["type"], "null"]}


_NUMBER = {"type": "number"}
_POINTS = _list(_list(_NUMBER, "a point: x, y (and z) in mm"), "points (mm)")
_LEVELS = _list(_list(_list(_NUMBER, "x, y (and z), mm"), "the points of one level"), "one list per pressure level")

ERROR = _obj("Every refusal: 422 bad input, 404, 405, 413, 415, 403, 400, 429, 507, 500.", {
    "error": _obj("What is wrong", {
        "field": _t("string", "the input the message belongs beside (`target`, `amplitude`, `unit`, `body`, ...)"),
        "message": _t("string", "one line saying what is wrong and what is accepted")})})

TARGET = _obj("The target; `kind` says which other fields it reads.", {
    "kind": _t("string", "the kind of target", enum=list(KINDS))}, {
    "name": _t("string", "preset: its name (default sin)", enum=list(PRESETS)),
    "amplitude": _t("number", "preset, expression: A in mm (default 10)"),
    "periods": _t("number", "preset: periods over the actuator (default 1)"),
    "expression": _t("string", "expression: a profile such as `y = 0.1*x` (x, L, A in mm; the safe parser)"),
    "goal": _t("string", "tip: the goal", enum=list(TIP_GOALS)),
    "point": _list(_NUMBER, "tip with goal reach: the point [x, y] or [x, y, z] (mm)"),
    "points": {**_POINTS, "description": "curve: the drawn stroke [[x, y], ...] (mm, smoothed; a stroke that "
                                         "turns back in x is a path); path: its points, [x, y] or [x, y, z]"},
    "top_points": {**_POINTS, "description": "curve: the same curve seen from above, [[x, z], ...] (mm)"},
    "preset": _t("string", "path: a preset instead of points", enum=list(PATH_PRESETS)),
    "stages": _list(_obj("A stage: a target at one pressure of the ramp", {
        "pressure_kpa": _t("number", "a level of the ramp (kPa)"),
        "target": _t("object", f"a target of kind {', '.join(STAGE_KINDS)} (a tip goal only reach)")}, {
        "weight": _t("number", "its weight in the root-sum-square (default 1)")}),
        "stages: the stages, at distinct levels")})

QUERY = _obj("A design query.", {"target": TARGET}, {
    "model": _t("string", "the model (default 3d)", enum=list(MODELS)),
    "top": _t("integer", f"how many designs to list, 1 to {MAX_TOP} (default 10)"),
    "unit": _t("string", "builtin (default), a library, or an uploaded unit's id (`GET /api/units`)"),
    "obstacle": _obj("An object beside the actuator (2D model only): the answer's winner is solved against it by the "
                     "2D FE model with contact", {
                         "centre": _list(_NUMBER, "the circle's centre [x, y] (mm: x from the clamped base, y from "
                                                  "the bottom face), within 1.25 lengths of the base"),
                         "radius": _t("number", "its radius (mm), > 0 and at most half the length")})})

_SAMPLES = _null(_obj("The target's samples over the actuator (heights above the axis, mm); null for a tip goal "
                      "or a path", {"x": _list(_NUMBER, "x (mm)"), "y": _list(_NUMBER, "y (mm)")},
                      {"z": _list(_NUMBER, "z off the plane (mm), a target in space")}))
_PATH = _null(_obj("A path placed on the actuator (mm); null for any other target", {
    "name": _t("string", "the path's name"), "x": _list(_NUMBER, "x (mm)"), "y": _list(_NUMBER, "y (mm)")},
    {"z": _list(_NUMBER, "z from the mid-plane (mm), a path in space")}))
_POINT = _null(_list(_NUMBER, "a tip goal's point (mm); null otherwise"))

ANSWER = _obj("The chain model's certified answer.", {
    "query_id": _t("string", "an id of the query (a hash of its parsed form)"),
    "label": _t("string", "the target in words"),
    "model": _t("string", "the model", enum=list(MODELS)),
    "units": _t("integer", "units of the actuator"),
    "length_mm": _t("number", "the actuator's length (mm)"),
    "pressures_kpa": _list(_NUMBER, "the ramp's pressure levels (kPa)"),
    "sense": _t("string", "min: an error to make small; max: a reach to make large", enum=["min", "max"]),
    "value_unit": _t("string", "the unit of the values (mm, or deg for an angle)"),
    "winner": _obj("The best design", {
        "design": _t("string", "the design, one character per unit"), "value": _t("number", "its value"),
        "level": _t("integer", "the pressure level of its best value"),
        "pressure_kpa": _t("number", "that level's pressure (kPa)")}),
    "certificate": _obj("Why no other design can beat the winner", {
        "bound": _t("number", "the chain model's error bound on the winner's value"),
        "candidates": _t("integer", "designs whose optimistic value could still beat the winner's worst case"),
        "designs": _t("integer", "designs of the search space"),
        "scored": _t("integer", "designs scored exactly (the others are bounded above the threshold)"),
        "complete": _t("boolean", "whether every design was scored"),
        "certified": _t("boolean", "whether no unlisted design can beat the winner"),
        "statement": _t("string", "the certificate in words")}),
    "top": _list(_obj("A design of the top list", {
        "rank": _t("integer", "1 for the winner"), "design": _t("string", "the design"),
        "value": _t("number", "its value"), "pressure_kpa": _t("number", "the pressure of its best value (kPa)"),
        "optimistic": _t("number", "its value less the bound")}), "the best designs, best first"),
    "target": _SAMPLES,
    "point": _POINT,
    "profiles": {**_LEVELS, "description": "the winner's base, unit centres and tip at every level, heights above "
                                           "the axis (mm)"},
    "stages": _null(_list(_obj("A stage", {
        "pressure_kpa": _t("number", "its pressure (kPa)"), "level": _t("integer", "its level of the ramp"),
        "label": _t("string", "its target in words"), "weight": _t("number", "its weight"),
        "target": _SAMPLES, "path": _PATH, "point": _POINT}), "a staged target's stages; null otherwise")),
    "path": _PATH,
    "axis_mm": _t("number", "the axis's height above the actuator's bottom face (mm)"),
    "centrelines": _null({**_LEVELS, "description": "a path's target or an object on the page: the winner's base, "
                                                    "centres and tip at every level as the model reports them (mm); "
                                                    "null otherwise"}),
    "elapsed_ms": _t("number", "time to compute the answer (ms)"),
    "memo": _t("boolean", "whether the answer was remembered from an earlier query")}, {
    "contact": _obj("With an object: the winner solved against it by the 2D FE model with contact", {
        "obstacle": _obj("The object as an obstacle table", {
            "kind": _t("string", "cylinder (a circle in 2D)"), "centre": _list(_NUMBER, "[x, y] (mm)"),
            "radius": _t("number", "mm")}),
        "design": _t("string", "the design solved (the winner)"),
        "failure": _null(_t("string", "why the ramp stopped (then no levels); null when it converged")),
        "levels": _list(_obj("One pressure level", {
            "pressure_kpa": _t("number", "the level's pressure (kPa)"),
            "force_n": _list(_NUMBER, "the force on the object [fx, fy] (N; 2D: per mm of depth times the width)"),
            "force_magnitude_n": _t("number", "its magnitude (N)"),
            "contact_length_mm": _t("number", "the contact length (mm)"),
            "clearance_mm": _t("number", "the least gap of the surface nodes to the object (mm; <= 0 in contact)"),
            "base_reaction_n": _list(_NUMBER, "the clamp's force on the actuator (N): the object's, balanced"),
            "points": _POINTS,
            "node_pressures_kpa": _list(_NUMBER, "the contact pressure of each node in contact (kPa)"),
            "centreline": _list(_list(_NUMBER, "x, y (mm)"), "the base, unit centres and tip (mm)")}),
            "every level of the ramp")})})

INFO = _obj("The bench's settings.", {
    "version": _t("string", "pneumorph's version"),
    "models": _list(_t("string", "a model"), "the models"),
    "default_model": _t("string", "the model of a query that names none"),
    "units": _t("integer", "units of the actuator"),
    "length_mm": _t("number", "the 3D actuator's length (mm)"),
    "pressures_kpa": _list(_NUMBER, "the ramp's pressure levels (kPa)"),
    "presets": _list(_t("string", "a preset"), "the profile presets"),
    "path_presets": _list(_t("string", "a path preset"), "the path presets"),
    "tip_goals": _list(_t("string", "a tip goal"), "the tip goals"),
    "axis_mm": _t("number", "the axis's height above the bottom face (mm)"),
    "defaults": _t("object", "the page's first target")})

PROFILES = _obj("A design's predicted lines at every level.", {
    "design": _t("string", "the design, as asked"),
    "profiles": {**_LEVELS, "description": "base, unit centres and tip, heights above the axis (mm)"},
    "centrelines": {**_LEVELS, "description": "the same points as the model reports them (mm)"}})

SHAPE = _obj("A design's 3D outer surface at one level.", {
    "source": _t("string", "fe once the design is verified, else chain", enum=["fe", "chain"]),
    "positions": _list(_NUMBER, "x, y, z of each vertex, flat (mm)"),
    "indices": _list({"type": "integer"}, "three vertex indices a triangle, flat")}, {
    "bounds": _list(_list(_NUMBER, "x, y, z (mm)"), "the lowest and highest corner")})

UNITS = _obj("The units this session may name.", {"units": _list(_obj("A unit", {
    "id": _t("string", "what a query's `unit` names"), "name": _t("string", "its name"),
    "model": _t("string", "the models it answers for")}), "the built-in unit, the libraries, uploaded units")})

JOB_REQUEST = _obj("A job: a verification of a query by FE, or an export of a design.", {
    "kind": _t("string", "verify or export", enum=["verify", "export"])}, {
    "query": {**QUERY, "description": "verify: the query whose answer FE verifies"},
    "design": _t("string", "export: the design"),
    "unit": _t("string", "export: the unit (default builtin)")})

TABLE_REQUEST = _obj("A unit file whose chain table to build.", {
    "unit": _t("string", "the unit's TOML file (a [unit] table, at most 64 kB)", format="binary")}, {
    "model": _t("string", "the model (default 3d)", enum=list(MODELS))})

JOB_ID = _obj("The job started.", {"job_id": _t("string", "the job's id, for `GET /api/jobs/{job_id}`")})

JOB = _obj("A job as the page sees it.", {
    "id": _t("string", "its id"), "kind": _t("string", "verify, export or table"),
    "state": _t("string", "its state", enum=list(STATES)),
    "progress": _t("number", "from 0 to 1"), "message": _t("string", "what it is doing"),
    "log": _list(_t("string", "a line"), "its last 200 lines of log"),
    "result": _null(_t("object", "what it found, once done: the verification's values and certificate, the "
                                 "export's files, the table's unit id")),
    "created": _t("number", "when it was queued (seconds since 1970)"),
    "params": _t("object", "what it was asked"),
    "files": _list(_obj("A file", {"name": _t("string", "its name"),
                                   "url": _t("string", "where to get it")}), "its files")})

JOBS = _obj("This session's jobs.", {"jobs": _list(JOB, "newest last")})

#: per route (path, method): summary, request body schema and media type (or None), the answer's status and schema
ROUTES: dict[tuple[str, str], tuple[str, tuple[str, Schema] | None, int, Schema | None]] = {
    ("/api/info", "get"): ("The bench's settings", None, 200, INFO),
    ("/api/design", "post"): ("A query's certified answer", ("application/json", QUERY), 200, ANSWER),
    ("/api/profiles", "get"): ("A design's profiles and centrelines", None, 200, PROFILES),
    ("/api/shape", "get"): ("A design's 3D surface", None, 200, SHAPE),
    ("/api/units", "get"): ("The session's units", None, 200, UNITS),
    ("/api/jobs/table", "post"): ("Build an uploaded unit's chain table", ("multipart/form-data", TABLE_REQUEST),
                                  202, JOB_ID),
    ("/api/jobs", "post"): ("Start a verification or an export", ("application/json", JOB_REQUEST), 202, JOB_ID),
    ("/api/jobs", "get"): ("This session's jobs", None, 200, JOBS),
    ("/api/jobs/{job_id}", "get"): ("A job", None, 200, JOB),
    ("/api/jobs/{job_id}", "delete"): ("Cancel a job, or delete a finished one", None, 200, JOB),
    ("/api/jobs/{job_id}/files/{name}", "get"): ("A job's file (its bytes)", None, 200, None),
}

_PARAMETERS = {
    "design": "the design, one character per unit", "model": "the model, 3d (default) or 2d",
    "unit": "builtin (default), a library, or an uploaded unit's id", "level": "the pressure level, from 0",
    "job_id": "the job's id", "name": "the file's name, as the job lists it"}


def _json(schema: Schema) -> dict[str, Any]:
    return {"application/json": {"schema": schema}}


def field_rows(schema: Schema, prefix: str = "") -> list[tuple[str, str, bool, str]]:
    """Every field of ``schema``, nested ones by their dotted path (``top[].design``): name, type, required, text.

    Examples
    --------
    >>> field_rows(ERROR)[1]
    ('error.field', 'string', True, 'the input the message belongs beside (`target`, `amplitude`, `unit`, `body`, ...)')
    """
    rows = []
    for name, field in schema.get("properties", {}).items():
        path = f"{prefix}{name}"
        kind = field["type"] if isinstance(field["type"], str) else " or ".join(field["type"])
        text = field.get("description", "") + (f" (one of {', '.join(field['enum'])})" if "enum" in field else "")
        rows.append((path, kind, name in schema.get("required", []), text))
        items = field.get("items", {})
        rows += field_rows(field, f"{path}.") + field_rows(items, f"{path}[].")
    return rows


def describe(app: Any) -> dict[str, Any]:
    """Add the bodies, answers and error format of :data:`ROUTES` to ``app.openapi()``, and return it.

    Parameters
    ----------
    app : fastapi.FastAPI
        The bench (:func:`~pneumorph.bench.create_app`); its description is cached, so the
        app's own ``openapi()`` answers with these fields afterwards.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from pneumorph.bench import create_app
    >>> root = Path(tempfile.mkdtemp())
    >>> spec = create_app(root / "state", root / "cache.sqlite", answer_workers=0).openapi()
    >>> spec["paths"]["/api/design"]["post"]["requestBody"]["content"]["application/json"]["schema"]["required"]
    ['target']
    """
    spec: dict[str, Any] = app.openapi()
    spec.setdefault("components", {}).pop("schemas", None)  # FastAPI's validation error: the bench has its own
    for (path, method), (summary, body, status, answer) in ROUTES.items():
        operation = spec["paths"][path][method]
        operation["summary"] = summary
        for parameter in operation.get("parameters", []):
            parameter["description"] = _PARAMETERS[parameter["name"]]
        if body is not None:
            operation["requestBody"] = {"required": True, "content": {body[0]: {"schema": body[1]}}}
        ok = {"description": answer["description"] if answer else "the file",
              **({"content": _json(answer)} if answer else {})}
        operation["responses"] = {str(status): ok, "default": {"description": "an error", "content": _json(ERROR)}}
    return spec


__all__ = ["ANSWER", "ERROR", "QUERY", "ROUTES", "Schema", "describe"]
