"""Sphinx configuration of pneumorph's documentation site.

Build it with ``sphinx-build -W --keep-going -b html docs docs/_build/html`` (the test
``tests/docs/test_site.py`` builds it the same way, so a warning fails the test command).
The Markdown pages are read by MyST, the docstrings (numpydoc format) by autodoc and
numpydoc; ``reference/`` holds one page per sub-package, each documenting the names of the
sub-package's ``__all__``.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import re
import sys
from typing import Any

import click
from docutils.nodes import Node
from sphinx.application import Sphinx
from sphinx.pycode import ModuleAnalyzer
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import make_refnode

import pneumorph

project = "pneumorph"
author = "the pneumorph authors"
copyright = "the pneumorph authors, GPL-3.0-or-later"
release = version = pneumorph.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# docs/scripts holds the scripts that regenerate the pages' figures and tables, not pages
exclude_patterns = ["_build", "scripts", "figures", "Thumbs.db", ".DS_Store"]

# -- MyST: the Markdown pages as they are on GitHub ------------------------------------------
myst_heading_anchors = 3  # links such as (#geometry) to a page's own headings

# -- autodoc and numpydoc -------------------------------------------------------------------
# each reference page asks for ``:members:`` and ``:undoc-members:`` (a public name without a
# docstring is listed all the same; the package's constants are documented by ``exported-data``)
autodoc_default_options = {"member-order": "groupwise"}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True  # a default is shown as written (GAConfig(), not its repr)
numpydoc_show_class_members = False  # autodoc lists the members; numpydoc's tables would repeat them
numpydoc_attributes_as_param_list = True  # a class's Attributes section is its fields, not new objects

# Every reference must name an object that exists (nitpicky, and ``_resolve_by_object``
# below for pneumorph's own). The types of other projects that the signatures name cannot
# resolve: the site is built offline in the test command, without intersphinx inventories.
# Those, and only those, are let through; so are the pieces of a generic annotation that
# Sphinx's signature parser splits at a comma (``dict[str``, ``tuple[float``).
nitpicky = True
nitpick_ignore_regex = [
    (r"py:class", r"(numpy|collections\.abc|matplotlib|trimesh|manifold3d)\..*"),
    (r"py:class", r"(pathlib\.)?Path|os\.PathLike"),
    (r"py:class", r"\w+\[.*"),
]

logger = logging.getLogger("pneumorph.docs")

html_theme = "alabaster"
html_title = f"pneumorph {release}"
html_static_path: list[str] = []


def _skip_undocumented_class_members(app: Sphinx, what: str, name: str, obj: Any, skip: bool,
                                     options: Any) -> bool | None:
    """Leave out a class's fields and its methods without a docstring of their own.

    ``undoc-members`` is on so that every name a sub-package exports is listed; a class's
    fields are described by its docstring's Attributes section already (their values would
    show the docstring of their type, ``int`` or ``tuple``).
    """
    if what != "class" or skip:
        return None
    if inspect.isroutine(obj) or isinstance(obj, (property, functools.cached_property)):
        return not (inspect.getdoc(obj) or "").strip() or None
    return True


_MISSING = object()


def _lookup(target: str) -> Any:
    """The object a dotted name in ``pneumorph`` names (a module, or a member of one), or ``_MISSING``."""
    parts = target.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for i, name in enumerate(parts[cut:], start=cut):
            fields = getattr(obj, "__dataclass_fields__", {})
            if i == len(parts) - 1 and inspect.isclass(obj) and (name in fields or name in getattr(
                    obj, "__annotations__", {})):
                return fields.get(name, name)  # a field without a default is no class attribute
            obj = getattr(obj, name, _MISSING)
            if obj is _MISSING:
                return _MISSING
        return obj
    return _MISSING


def _candidates(target: str, node: Any) -> list[str]:
    """Full names a reference's target may mean.

    A full name means itself. A short one (``:data:`WEIGHTINGS```, ``:class:`UnitSpec```) means a
    name in the scope of the docstring it is written in: the documented object, its class, its
    module, its package (the docstring's object is in the node's source, ``docstring of NAME``),
    or, in a signature, where the name is unique among the package's loaded modules.
    """
    if target.startswith("pneumorph"):
        return [target]
    where = re.search(r"docstring of ([\w.]+)", getattr(node, "source", None) or "")
    names = []
    if where:
        scope = where.group(1).split(".")
        scopes = [scope[:cut] for cut in range(len(scope), 0, -1)]
        # the module that defines the documented object (or its class: a property has no module)
        home = next((getattr(obj, "__module__", None) for obj in map(_lookup, map(".".join, scopes))
                     if isinstance(getattr(obj, "__module__", None), str)), None)
        names = [".".join([*prefix, target]) for prefix in [*scopes, *([home.split(".")] if home else [])]]
    head = target.partition(".")[0]
    found = {f"{module}.{target}" for module, mod in list(sys.modules.items())
             if module.startswith("pneumorph.") and mod is not None and head in vars(mod)
             and str(getattr(vars(mod)[head], "__module__", "")).startswith("pneumorph")}
    return names + (sorted(found) if len({id(_lookup(n)) for n in found}) == 1 else [])


def _resolve_by_object(app: Sphinx, env: Any, node: Any, contnode: Any) -> Any:
    """Resolve a reference to a pneumorph object by what it names, not by how it is spelt.

    Docstrings name objects by the module that defines them (``pneumorph.design.search.genetic.run_ga``),
    or by their short name in that module; the reference documents them where the
    sub-package exports them (``pneumorph.design.run_ga``). A reference to an object
    documented under another name links there; one to an object that exists but is not in
    the public reference (a module, an internal helper, a constant of a module) is shown as
    code without a link; one to an object that does not exist (a typo, a name that moved)
    stays unresolved, and nitpicky mode makes it a warning.
    """
    if node.get("refdomain") != "py":
        return None
    for name in _candidates(node.get("reftarget", ""), node):
        obj = _lookup(name)
        if obj is _MISSING:
            continue
        documented = _documented(env).get(id(obj)) if not isinstance(obj, _VALUES) else None
        if documented is None:
            return contnode
        docname, node_id, _objtype, _aliased = env.get_domain("py").objects[documented]
        return make_refnode(app.builder, node["refdoc"], docname, node_id, contnode, documented)
    return None


_VALUES = (int, float, str, bool, type(None))  # their ids are shared: never a documented object's
_DOCUMENTED: dict[int, tuple[int, dict[int, str]]] = {}


def _documented(env: Any) -> dict[int, str]:
    """``id(object) -> documented name`` for every pneumorph object in the reference."""
    objects = env.get_domain("py").objects
    known = _DOCUMENTED.get(id(env))
    if known is None or known[0] != len(objects):
        names: dict[int, str] = {}
        for name in sorted(objects, key=len, reverse=True):  # the shortest name of an object wins
            obj = _lookup(name) if name.startswith("pneumorph") else _MISSING
            if obj is not _MISSING and not isinstance(obj, _VALUES):
                names[id(obj)] = name
        known = _DOCUMENTED[id(env)] = (len(objects), names)
    return known[1]


class ExportedData(SphinxDirective):
    """``.. exported-data:: pneumorph.design``: the constants and type aliases of a sub-package's ``__all__``.

    autodoc's ``automodule`` documents the classes and functions a package re-exports, but
    not its constants (``PRESETS``, ``MODES``): their doc comments (``#:``) are in the module
    that defines them. This directive finds that module and documents each constant under the
    package's name, with its value when short. A constant without a doc comment is a warning.
    """

    required_arguments = 1

    def run(self) -> list[Node]:
        package = importlib.import_module(self.arguments[0])
        # the modules the package has imported to re-export their names (not all of its modules:
        # the bench's web application needs the ``web`` extra)
        modules = [m for name, m in list(sys.modules.items())
                   if m is not None and (name == package.__name__ or name.startswith(f"{package.__name__}."))]
        lines: list[str] = []
        for name in package.__all__:
            obj = getattr(package, name)
            if inspect.isclass(obj) or inspect.isroutine(obj) or inspect.ismodule(obj):
                continue  # automodule's
            doc = next((ModuleAnalyzer.for_module(m.__name__).find_attr_docs().get(("", name)) for m in modules
                        if vars(m).get(name) is obj and ("", name) in
                        ModuleAnalyzer.for_module(m.__name__).find_attr_docs()), None)
            if doc is None:
                logger.warning("%s.%s has no doc comment (#:) where it is defined", package.__name__, name,
                               location=self.get_location())
            lines += [f".. py:data:: {name}", f"   :module: {package.__name__}"]
            value = repr(obj)
            if len(value) <= 80 and "\n" not in value:
                lines += [f"   :value: {value}"]
            lines += ["", *(f"   {line}" for line in doc or []), ""]
        return self.parse_text_to_nodes("\n".join(lines))


class CommandHelp(SphinxDirective):
    """``.. command-help:: pneumorph.cli:cli``: every command's ``--help``, as the terminal shows it.

    The text comes from the click commands themselves (one section per command, in the
    order ``pneumorph --help`` lists them), so the page follows the command line.
    """

    required_arguments = 1

    def run(self) -> list[Node]:
        module, _, name = self.arguments[0].partition(":")
        root = getattr(importlib.import_module(module), name)
        lines: list[str] = []

        def walk(command: click.Command, path: list[str], parent: click.Context | None) -> None:
            ctx = click.Context(command, info_name=path[-1], parent=parent, terminal_width=88, max_content_width=88)
            title = f"``{' '.join(path)}``"
            lines.extend([title, "-" * len(title), "", "::", ""])
            lines.extend(f"   {line}" if line else "" for line in command.get_help(ctx).splitlines())
            lines.append("")
            if isinstance(command, click.Group):
                for sub in command.list_commands(ctx):
                    child = command.get_command(ctx, sub)
                    if child is not None and not child.hidden:
                        walk(child, [*path, sub], ctx)

        walk(root, ["pneumorph"], None)
        return self.parse_text_to_nodes("\n".join(lines), allow_section_headings=True)


class BenchApi(SphinxDirective):
    """``{bench-api}`` in a Markdown page: every route of the bench with its parameters, request and answer fields.

    The tables are read from the app's own OpenAPI description (``create_app(...).openapi()``,
    whose bodies and answers ``pneumorph.bench.schema`` describes), so the page follows the API.
    The text is Markdown, parsed by the page's parser (MyST).
    """

    def run(self) -> list[Node]:
        import tempfile
        from pathlib import Path

        from pneumorph.bench import create_app
        from pneumorph.bench.schema import field_rows

        with tempfile.TemporaryDirectory() as root:
            spec = create_app(Path(root) / "state", Path(root) / "cache.sqlite", answer_workers=0).openapi()
        lines: list[str] = []
        for path, operations in spec["paths"].items():
            for method, op in operations.items():
                lines += [f"### `{method.upper()} {path}`", "", op["summary"] + ".", ""]
                params = [(p["name"], f"{p['in']}, {p['schema']['type']}", p["required"], p["description"])
                          for p in op.get("parameters", [])]
                lines += _field_table("Parameters", params)
                for media, body in op.get("requestBody", {}).get("content", {}).items():
                    lines += _field_table(f"Request body ({media}): {body['schema']['description']}",
                                          field_rows(body["schema"]))
                for status, answer in op["responses"].items():
                    schema = answer.get("content", {}).get("application/json", {}).get("schema")
                    if status != "default":
                        lines += _field_table(f"Answer ({status}): {answer['description']}",
                                              field_rows(schema) if schema else []) or [
                            f"Answer ({status}): {answer['description']}.", ""]
        return self.parse_text_to_nodes("\n".join(lines), allow_section_headings=True)


def _field_table(title: str, rows: list[tuple[str, str, bool, str]]) -> list[str]:
    """A Markdown table of fields (name, type, whether required, what it is) under its title; none without rows."""
    if not rows:
        return []
    lines = [f"**{title}**", "", "| field | type | required | what |", "|---|---|---|---|"]
    lines += [f"| `{name}` | {kind} | {'yes' if required else ''} | {text.replace('|', '/')} |"
              for name, kind, required, text in rows]
    return [*lines, ""]


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("exported-data", ExportedData)
    app.add_directive("bench-api", BenchApi)
    app.add_directive("command-help", CommandHelp)
    app.connect("missing-reference", _resolve_by_object)
    app.connect("autodoc-skip-member", _skip_undocumented_class_members)
    return {"parallel_read_safe": True}
