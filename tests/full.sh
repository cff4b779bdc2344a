#!/usr/bin/env bash
# The full tier, in order: ruff, mypy (the settings of [tool.ruff] and [tool.mypy] in
# pyproject.toml), the `docs` tests (the documentation site, the README's commands, the API
# page's example), then every other test, each marker included (`slow`, `browser`, `cluster`).
# Stops at the first step that fails. Arguments go to the last pytest run (`bash tests/full.sh -x`).
#
# The fast tier, while you work: .venv/bin/python -m pytest
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON="${PYTHON:-.venv/bin/python}"
export MPLBACKEND="${MPLBACKEND:-Agg}"

step() { printf '\n== %s\n' "$*"; }

step "ruff"
"$PYTHON" -m ruff check --output-format concise src tests benchmarks docs/scripts docs/conf.py

step "mypy"
"$PYTHON" -m mypy --no-incremental  # the files and settings of [tool.mypy]

step "docs: the site builds; the README's commands and the API page's example run"
"$PYTHON" -m pytest -m docs

step "tests: every marker"
"$PYTHON" -m pytest -m "not docs" "$@"
