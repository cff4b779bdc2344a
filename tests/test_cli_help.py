"""``--help`` points at the documentation in one form that a wheel user can follow: the page's name, and where the
page is in the source (a wheel has no docs folder; the documentation site has the same pages)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import click

from pneumorph.cli import cli

DOCS = Path(__file__).resolve().parents[1] / "docs"
FORM = re.compile(r"documentation page ([\w-]+), docs/([\w-]+)\.md in the source")


def _texts(command: click.Command, path: str = "pneumorph") -> Iterator[tuple[str, str]]:
    yield path, command.help or ""
    for param in command.params:
        yield f"{path} {getattr(param, 'opts', [param.name])[0]}", getattr(param, "help", None) or ""
    if isinstance(command, click.Group):
        ctx = click.Context(command)
        for name in command.list_commands(ctx):
            sub = command.get_command(ctx, name)
            assert sub is not None, name
            yield from _texts(sub, f"{path} {name}")


def test_every_help_text_names_its_documentation_page_in_one_form() -> None:
    pointers = 0
    for where, text in _texts(cli):
        flat = " ".join(text.split())
        for match in re.finditer(r"docs/", flat):
            pointer = FORM.search(flat, max(0, match.start() - 40))
            assert pointer is not None and pointer.start(2) - len("docs/") == match.start(), (where, flat)
            name, page = pointer.groups()
            assert name == page and (DOCS / f"{page}.md").is_file(), (where, page)
            pointers += 1
    assert pointers >= 10  # design, export, chain, sensitivity, simulate, unit and the execution options
