"""The documentation site builds without a warning and documents every public name.

The site (``docs/``, Sphinx with MyST and numpydoc) is built once per test session the way
the README tells a user to build it, with warnings as errors, so a broken docstring, a
reference to a name that moved or a page left out of the table of contents fails here.
"""

from __future__ import annotations

import html
import importlib
import inspect
import pkgutil
import re
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

import pneumorph

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"
# the command line has no Python API of its own: docs/cli.rst shows every command's --help
NOT_IN_REFERENCE = {"pneumorph.cli", "pneumorph.__main__"}
pytestmark = pytest.mark.docs


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The built site (HTML), or the build's warnings as the failure."""
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-j", "1", "-q", "-b", "html", str(DOCS), str(out)],
        cwd=REPO, capture_output=True, text=True,
    )
    assert done.returncode == 0, done.stderr[-6000:]
    return out


def inventory(site: Path) -> set[str]:
    """The Python objects of the site's ``objects.inv`` (Sphinx's inventory format, version 2)."""
    data = (site / "objects.inv").read_bytes()
    header_end = 0
    for _ in range(4):  # four text lines, then the zlib-compressed entries
        header_end = data.index(b"\n", header_end) + 1
    entries = zlib.decompress(data[header_end:]).decode()
    return {m.group(1) for m in re.finditer(r"^(\S+) py:\w+ ", entries, flags=re.MULTILINE)}


def public_names() -> list[str]:
    """Every public name of the package: each sub-package's ``__all__``, and the public members
    of the top-level modules (``checks``, ``errors``) that define them."""
    names = [f"pneumorph.{name}" for name in pneumorph.__all__]
    for info in pkgutil.iter_modules(pneumorph.__path__, "pneumorph."):
        if info.name in NOT_IN_REFERENCE:
            continue
        module = importlib.import_module(info.name)
        if info.ispkg:
            packages = [module] + [importlib.import_module(sub.name) for sub in
                                   pkgutil.walk_packages(module.__path__, f"{info.name}.") if sub.ispkg]
            for package in packages:
                assert hasattr(package, "__all__"), f"{package.__name__} says what it exports in __all__"
                names += [f"{package.__name__}.{name}" for name in package.__all__]
        else:
            names += [f"{info.name}.{name}" for name, obj in vars(module).items()
                      if not name.startswith("_") and (inspect.isfunction(obj) or inspect.isclass(obj))
                      and obj.__module__ == info.name]
    return names


def test_the_site_builds_without_warnings(site: Path) -> None:
    assert (site / "index.html").is_file() and (site / "reference" / "pneumorph.design.html").is_file()
    for page in [*DOCS.glob("*.md"), *DOCS.glob("*.rst"), *DOCS.glob("tutorials/*.md"), *DOCS.glob("notes/*.md")]:
        assert (site / page.relative_to(DOCS).with_suffix(".html")).is_file(), page.name


def test_the_command_line_page_has_every_command(site: Path) -> None:
    import click

    from pneumorph.cli import cli

    text = html.unescape(re.sub(r"<[^>]+>", "", (site / "cli.html").read_text(encoding="utf-8")))
    names = cli.list_commands(click.Context(cli))
    assert len(names) > 10
    for name in names:
        assert f"Usage: pneumorph {name} [OPTIONS]" in text, name


def test_every_public_name_is_in_the_api_reference(site: Path) -> None:
    documented = inventory(site)
    names = public_names()
    assert len(names) > 200 and "pneumorph.design.run_ga" in names  # the walk found the sub-packages
    missing = [name for name in names if name not in documented]
    assert not missing, f"not in the API reference (docs/reference/): {missing}"


def test_the_example_pages_show_every_example_and_its_figures(site: Path) -> None:
    listed = (DOCS / "example-files.md").read_text(encoding="utf-8")
    for path in sorted((REPO / "examples").glob("*.toml")):
        assert f"../examples/{path.name}" in listed, f"{path.name} is not on docs/example-files.md"
    results = (site / "examples.html").read_text(encoding="utf-8")
    for path in sorted((DOCS / "figures" / "examples").glob("*.png")):
        assert path.name in results, f"{path.name} is not on the examples page"
        assert (site / "_images" / path.name).is_file(), path.name


def test_the_bench_api_page_lists_every_route_and_field(site: Path) -> None:
    pytest.importorskip("fastapi")
    from pneumorph.bench.schema import ROUTES, field_rows

    text = html.unescape(re.sub(r"<[^>]+>", "", (site / "bench-api.html").read_text(encoding="utf-8")))
    text = text.replace("\u2019", "'").replace("\u2026", "...")  # Sphinx's smart quotes and ellipses
    for (path, method), (summary, body, _status, answer) in ROUTES.items():
        assert f"{method.upper()} {path}" in text and summary in text, (method, path)
        for schema in [body[1] if body else None, answer]:
            for name, _kind, _required, description in field_rows(schema or {}):
                assert name in text and description.split(" (")[0].replace("`", "") in text, (path, name)
