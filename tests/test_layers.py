"""The package's shape, read from its source: layers that only point down, no circle between
modules, modules and functions a reader can hold (docs/architecture.md, "Layers" and "Sizes").

Every import is read with :mod:`ast`, at the top of a module, inside its functions and under
``if TYPE_CHECKING:`` alike (an import for the types is a dependency too).
"""

from __future__ import annotations

import ast
import re
from collections import Counter, defaultdict
from dataclasses import dataclass
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "pneumorph"

# Bottom to top (docs/architecture.md, "Layers"). A module may import its own part (sub-package
# or top-level module) and any part of a lower layer; parts of one layer do not import each other.
LAYERS: list[tuple[str, ...]] = [
    ("pneumorph",),  # the package's own __init__: its version
    ("errors",),
    ("checks",),
    ("io",),
    ("materials", "fem"),
    ("geometry",),
    ("plot",),
    ("models",),
    ("execution", "composite", "bimodal", "correlation", "export"),
    ("sensitivity",),
    ("design",),
    ("calibration", "unitopt", "identify", "bench"),
    ("cli",),
    ("__main__",),
]
LAYER = {part: number for number, layer in enumerate(LAYERS) for part in layer}

MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80
# Modules and functions still over the limits, each named with its reason and plan in
# docs/architecture.md ("Sizes"). The lists may only shrink: an entry under its limit fails too.
LONG_MODULES: dict[str, int] = {}
LONG_FUNCTIONS: dict[str, int] = {
    "pneumorph.fem.fast.kernels:ogden_3d": 121,
    "pneumorph.fem.fast.kernels:ogden_plane_strain": 82,
    "pneumorph.fem.stepping:ramp": 130,
}


@dataclass(frozen=True)
class Import:
    importer: str
    target: str
    line: int


def modules() -> dict[str, Path]:
    """Every module of the package by dotted name (a package by its own name)."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def imports(name: str, path: Path, known: dict[str, Path]) -> list[Import]:
    """The package's modules that ``name`` imports, at any level of the module."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1])
                source = f"{base}.{node.module}" if node.module else base
            else:
                source = node.module or ""
            # ``from package import module`` imports the module; ``from module import name`` the module
            targets = [f"{source}.{alias.name}" if f"{source}.{alias.name}" in known else source
                       for alias in node.names]
        for target in targets:
            if target.split(".")[0] == "pneumorph":
                while target not in known:  # ``import pneumorph.a.b`` of a name inside a module
                    target = target.rpartition(".")[0]
                found.append(Import(name, target, node.lineno))
    return found


def all_imports() -> list[Import]:
    known = modules()
    return [found for name, path in known.items() for found in imports(name, path, known)]


def part(module: str) -> str:
    """The layer's part a module belongs to: its sub-package or top-level module."""
    pieces = module.split(".")
    return pieces[1] if len(pieces) > 1 else pieces[0]


def test_every_part_has_a_layer() -> None:
    assert {part(name) for name in modules()} == set(LAYER)


def test_imports_only_point_down() -> None:
    wrong = []
    for found in all_imports():
        here, there = part(found.importer), part(found.target)
        if here != there and LAYER[there] >= LAYER[here]:
            wrong.append(f"{found.importer}:{found.line} imports {found.target} ({here} is not above {there})")
    assert not wrong, "\n".join(sorted(set(wrong)))


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_no_circle_between_modules() -> None:
    edges: dict[str, set[str]] = defaultdict(set)
    for name in modules():
        edges[name]
    for found in all_imports():
        if found.target != found.importer:
            edges[found.importer].add(found.target)
    assert not cycles(edges)


def test_the_circle_finder_finds_circles() -> None:
    edges: dict[str, set[str]] = defaultdict(set, {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}})
    assert cycles(edges) == [["a", "b", "c"]]


def test_no_private_name_is_imported_from_another_module() -> None:
    """What another module imports is public: a leading underscore means "this module's own"."""
    known = modules()
    wrong = []
    for name, path in known.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("pneumorph"):
                wrong += [f"{name}:{node.lineno} imports {alias.name} from {node.module}" for alias in node.names
                          if alias.name.startswith("_") and not alias.name.startswith("__")]
    assert not wrong, "\n".join(wrong)


def test_the_names_of_checks_are_imported_from_checks() -> None:
    """A module uses a choice or limit of :mod:`pneumorph.checks` by its one name there, not through an alias of its
    own (which makes a second place to import it from)."""
    found = set()
    for name, path in modules().items():
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
            if isinstance(value, ast.Attribute) and isinstance(value.value, ast.Name) and value.value.id == "checks":
                found.add(f"{name}:{value.attr}")
    assert not found, f"aliases of names of pneumorph.checks: {sorted(found)}"


def _module_lines() -> dict[str, int]:
    return {name: len(path.read_text(encoding="utf-8").splitlines()) for name, path in modules().items()}


def _function_lines() -> dict[str, int]:
    """Every function's lines (decorators left out, its docstring in), by ``module:qualified name``."""
    found = {}
    for name, path in modules().items():
        tree = ast.parse(path.read_text(encoding="utf-8"))

        def visit(node: ast.AST, prefix: str, module: str = name) -> None:
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                    qualified = f"{prefix}{child.name}"
                    if not isinstance(child, ast.ClassDef):
                        found[f"{module}:{qualified}"] = (child.end_lineno or child.lineno) - child.lineno + 1
                    visit(child, qualified + ".")

        visit(tree, "")
    return found


@pytest.mark.parametrize(("measure", "limit", "exceptions"), [
    (_module_lines, MAX_MODULE_LINES, LONG_MODULES),
    (_function_lines, MAX_FUNCTION_LINES, LONG_FUNCTIONS),
], ids=["modules", "functions"])
def test_sizes_a_reader_can_hold(measure, limit: int, exceptions: dict[str, int]) -> None:
    sizes = measure()
    over = {name: lines for name, lines in sizes.items() if lines > limit}
    new = {name: lines for name, lines in over.items() if name not in exceptions}
    grown = {name: (lines, exceptions[name]) for name, lines in over.items()
             if name in exceptions and lines > exceptions[name]}
    stale = sorted(name for name in exceptions if sizes.get(name, 0) <= limit)
    assert not new, f"over {limit} lines: {new}"
    assert not grown, f"exceptions grown past their recorded size (now, recorded): {grown}"
    assert not stale, f"no longer over {limit} lines, take them off the list: {stale}"


ARCHITECTURE = SRC.parent / "docs" / "architecture.md"
#: an entry of the map's tree: its indent, then a folder (``fem/``) or modules (``scoring.py, population.py``)
#: followed by two spaces or the line's end
MAP_ENTRY = re.compile(r"^( *)((?:[\w./]+/|\w+\.py)(?:, \w+\.py)*)(?:\s{2,}|$)")


def map_names() -> Counter[str]:
    """The modules the map of docs/architecture.md ("Layout") names, by path from the repository's root.

    A module is named by its entry in the tree, or inside the text of its folder's entry (``composite/ ...
    (crimp.py, ...)``); the folders nest by indent."""
    block = ARCHITECTURE.read_text(encoding="utf-8").split("## Layout", 1)[1].split("```", 2)[1]
    folders: list[tuple[int, str]] = []
    named: Counter[str] = Counter()
    folder = None
    for line in block.splitlines():
        entry, text = MAP_ENTRY.match(line), line
        if entry:
            indent, names = len(entry.group(1)), entry.group(2).split(", ")
            while folders and folders[-1][0] >= indent:
                folders.pop()
            if names[0].endswith("/"):
                folders.append((indent, names[0].rstrip("/")))
                folder, text = "/".join(name for _, name in folders), line[entry.end():]
            else:
                named.update("/".join([name for _, name in folders] + [module]) for module in names)
                folder = None
        if folder is not None:
            named.update(f"{folder}/{module}" for module in re.findall(r"\b(\w+\.py)\b", text))
    return named


def test_the_map_names_every_module_once() -> None:
    """docs/architecture.md's map names every module of the package once, and no module that is not there (a
    package's ``__init__.py`` is its folder's entry)."""
    modules_ = {f"src/{path.relative_to(SRC).as_posix()}" for path in PACKAGE.rglob("*.py")
                if path.name != "__init__.py"}
    named = {name: count for name, count in map_names().items()
             if name.startswith("src/pneumorph/") and not name.endswith("/__init__.py")}
    missing, stale = sorted(modules_ - set(named)), sorted(set(named) - modules_)
    assert not missing, f"modules missing from the map: {missing}"
    assert not stale, f"the map names modules that are not there: {stale}"
    assert all(count == 1 for count in named.values()), {name: count for name, count in named.items() if count > 1}
