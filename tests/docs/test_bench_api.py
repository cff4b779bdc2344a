"""The bench API page's examples get the answers it shows, and real answers have exactly the described fields.

docs/bench-api.md shows requests and their answers as pairs of ``http`` blocks; each request
is sent to the bench in-process (FastAPI's TestClient) and its answer compared with the page's:
the same status, the same keys at every level, equal values (numbers to 1e-9 relative), a
list on the page the first items of the real one. The app's OpenAPI description
(:mod:`pneumorph.bench.schema`), which the page renders as tables, is checked against the
app's routes and against real answers, field by field: a field the answer has and the
description lacks, or the other way round, fails.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("fastapi")
from fastapi.testclient import TestClient

from pneumorph.bench import Job, create_app
from pneumorph.bench.schema import ANSWER, ERROR, ROUTES, field_rows

PAGE = Path(__file__).resolve().parents[2] / "docs" / "bench-api.md"
BASE = "http://127.0.0.1:8000"  # a host the bench serves (its loopback names)
# values that differ from run to run or release to release: compared by type only
VARYING = {"version", "elapsed_ms"}


@pytest.fixture(scope="module")
def client(tmp_path_factory: pytest.TempPathFactory) -> TestClient:
    root = tmp_path_factory.mktemp("bench")
    return TestClient(create_app(root / "state", root / "cache.sqlite", answer_workers=0), base_url=BASE)


def examples() -> list[tuple[str, str]]:
    """The page's (request, answer) pairs of ``http`` blocks, in order."""
    blocks = re.findall(r"```http\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S)
    assert len(blocks) % 2 == 0 and all(b.startswith("HTTP/1.1 ") for b in blocks[1::2]), "request, answer, ..."
    return list(zip(blocks[::2], blocks[1::2], strict=True))


def parse_http(text: str) -> tuple[str, dict[str, str], Any]:
    """The first line, the headers and the JSON body (or None) of a block."""
    head, _, body = text.partition("\n\n")
    first, *lines = head.strip().splitlines()
    headers = dict(line.split(": ", 1) for line in lines)
    return first, headers, json.loads(body) if body.strip() else None


def shown_in(shown: Any, real: Any, where: str = "") -> list[str]:
    """How the page's value ``shown`` differs from the real answer's (keys all kept, lists cut short)."""
    if isinstance(shown, dict) and isinstance(real, dict):
        if set(shown) != set(real):
            return [f"{where}: keys {sorted(set(shown) ^ set(real))} differ"]
        return [d for key in shown for d in (
            ([] if type(shown[key]) is type(real[key]) else [f"{where}.{key}: type"]) if key in VARYING
            else shown_in(shown[key], real[key], f"{where}.{key}"))]
    if isinstance(shown, list) and isinstance(real, list):
        if (real and not shown) or len(shown) > len(real):
            return [f"{where}: {len(shown)} items shown of {len(real)}"]
        return [d for i, item in enumerate(shown) for d in shown_in(item, real[i], f"{where}[{i}]")]
    if isinstance(shown, float | int) and isinstance(real, float | int) and not isinstance(real, bool):
        return [] if math.isclose(shown, real, rel_tol=1e-9, abs_tol=1e-12) else [f"{where}: {shown} != {real}"]
    return [] if shown == real else [f"{where}: {shown!r} != {real!r}"]


def test_the_pages_examples_get_the_answers_it_shows(client: TestClient) -> None:
    pairs = examples()
    assert len(pairs) >= 8
    for request, answer in pairs:
        first, headers, body = parse_http(request)
        method, target, _ = first.split(" ")
        got = client.request(method, target, headers=headers, content=json.dumps(body) if body is not None else None)
        status, shown_headers, shown = parse_http(answer)
        assert status.split(" ")[1] == str(got.status_code), (first, got.text[:300])
        assert got.headers["content-type"] == shown_headers["content-type"]
        assert not shown_in(shown, got.json()), (first, shown_in(shown, got.json())[:5])


def test_the_comparison_fails_where_the_page_would_be_wrong() -> None:
    real = {"a": [1.0, 2.0], "b": {"c": "x"}}
    assert not shown_in({"a": [1.0], "b": {"c": "x"}}, real)
    assert shown_in({"a": [1.5], "b": {"c": "x"}}, real)  # a wrong value
    assert shown_in({"a": [1.0]}, real)  # a field left out
    assert shown_in({"a": [1.0, 2.0, 3.0], "b": {"c": "x"}}, real)  # more items than the answer has


def unmatched(value: Any, schema: dict[str, Any], where: str = "") -> list[str]:
    """Where ``value`` breaks ``schema``: type, enum, a required field missing or an undescribed one present."""
    kinds = schema.get("type", [])
    kinds = [kinds] if isinstance(kinds, str) else kinds
    python = {"object": dict, "array": list, "string": str, "boolean": bool, "null": type(None),
              "integer": int, "number": float | int}
    if kinds and not any(isinstance(value, python[k]) and not (k in ("integer", "number") and isinstance(value, bool))
                         for k in kinds):
        return [f"{where}: {type(value).__name__} is not {kinds}"]
    if "enum" in schema and value not in schema["enum"]:
        return [f"{where}: {value!r} not in {schema['enum']}"]
    if isinstance(value, dict) and "properties" in schema:
        out = [f"{where}.{k}: not described" for k in value if k not in schema["properties"]]
        out += [f"{where}.{k}: missing" for k in schema.get("required", []) if k not in value]
        return out + [d for k, v in value.items() if k in schema["properties"]
                      for d in unmatched(v, schema["properties"][k], f"{where}.{k}")]
    if isinstance(value, list) and "items" in schema:
        return [d for i, v in enumerate(value[:50]) for d in unmatched(v, schema["items"], f"{where}[{i}]")]
    return []


def answer_schema(path: str, method: str) -> dict[str, Any]:
    schema = ROUTES[(path, method)][3]
    assert schema is not None
    return schema


@pytest.mark.parametrize("query", [
    {"target": {"kind": "preset", "name": "sin", "amplitude": 10}, "model": "2d", "top": 3},
    {"target": {"kind": "path", "preset": "hook"}, "model": "2d", "top": 1},
    {"target": {"kind": "tip", "goal": "reach", "point": [120, 60]}, "model": "2d", "top": 2},
    {"target": {"kind": "stages", "stages": [
        {"pressure_kpa": 18, "target": {"kind": "expression", "expression": "y = 0.05*x"}},
        {"pressure_kpa": 45, "target": {"kind": "preset", "name": "sin"}, "weight": 2}]}, "model": "2d", "top": 2},
    {"target": {"kind": "curve", "points": [[0, 0], [80, 5], [157.5, 20]], "top_points": [[0, 0], [157.5, 10]]},
     "model": "2d", "top": 2},
    {"target": {"kind": "preset", "name": "sin"}, "model": "2d", "top": 1,
     "obstacle": {"centre": [170.0, 4.0], "radius": 4.0}},  # the winner solved against it by 2D FE
], ids=["preset", "path", "tip", "stages", "curve-in-space", "object"])
def test_answers_have_exactly_the_described_fields(client: TestClient, query: dict[str, Any]) -> None:
    got = client.post("/api/design", json=query)
    assert got.status_code == 200, got.text[:300]
    assert not unmatched(got.json(), ANSWER)
    assert not unmatched(client.post("/api/design", json=query).json(), ANSWER)  # the remembered answer too


def test_the_other_answers_have_exactly_the_described_fields(client: TestClient, tmp_path: Path) -> None:
    for path in ("/api/info", "/api/units", "/api/jobs"):
        assert not unmatched(client.get(path).json(), answer_schema(path, "get")), path
    lines = client.get("/api/profiles", params={"design": "0" * 15, "model": "2d"}).json()
    assert not unmatched(lines, answer_schema("/api/profiles", "get"))
    job = Job("j1", "s", "export", tmp_path, {"design": "0" * 15}, files=["actuator.stl"], result={"files": 1})
    assert not unmatched(job.to_dict(), answer_schema("/api/jobs/{job_id}", "get"))
    assert not unmatched(client.get("/api/jobs/none").json(), ERROR)
    assert unmatched({**lines, "extra": 1}, answer_schema("/api/profiles", "get"))  # the check can fail
    assert unmatched({"design": "0"}, answer_schema("/api/profiles", "get"))


def test_every_route_and_field_is_described(client: TestClient) -> None:
    spec = client.app.openapi()  # type: ignore[attr-defined]
    # FastAPI lists the app's routes in the description whatever ROUTES says: each must be described
    assert {(path, method) for path, operations in spec["paths"].items() for method in operations} == set(ROUTES)
    for path, operations in spec["paths"].items():
        for method, op in operations.items():
            assert op["summary"] and all(p["description"] for p in op.get("parameters", [])), (path, method)
            schemas = [c["schema"] for part in [op.get("requestBody", {}), *op["responses"].values()]
                       for c in part.get("content", {}).values()]
            rows = [row for schema in schemas for row in field_rows(schema)]
            assert all(text for _, _, _, text in rows), (path, method)
    assert len(field_rows(ANSWER)) > 50  # the walk reached the nested fields
