"""The ``pneumorph`` group loads a command's module only when that command runs: its table of commands
(``COMMANDS``) names every command's module and summary, and ``pneumorph --help`` lists them as the commands
themselves would, without importing one. The ``materials`` group does the same with its table
(``MATERIALS_COMMANDS``), and a command's own ``--help`` imports none of the numerical code."""

from __future__ import annotations

import importlib
import subprocess
import sys

import click
import pytest

from pneumorph.cli import COMMANDS, cli
from pneumorph.cli.materials.group import MATERIALS_COMMANDS, materials

TABLES = [(cli, COMMANDS), (materials, MATERIALS_COMMANDS)]


def _command(where: str, name: str) -> click.Command:
    module, _, attribute = where.partition(":")
    return getattr(importlib.import_module(module), attribute or name)


def _eager(group: click.Group = cli) -> click.Group:
    """The same group with every command imported and added, as click builds it without a table."""
    table = dict(TABLES)[group]  # type: ignore[call-overload]
    eager = click.Group(group.name, params=group.params, help=group.help, context_settings=group.context_settings)
    for name, (where, _) in table.items():
        eager.add_command(_command(where, name), name)
    return eager


@pytest.mark.parametrize(("group", "name"), [(group, name) for group, table in TABLES for name in sorted(table)])
def test_every_command_is_its_modules_and_its_summary_is_its_helps_first_sentence(group: click.Group,
                                                                                  name: str) -> None:
    where, summary = dict(TABLES)[group][name]  # type: ignore[call-overload]
    command = _command(where, name)
    assert isinstance(command, click.Command) and command.name == name
    assert summary == command.get_short_help_str(10_000)
    assert group.get_command(click.Context(group), name) is command


@pytest.mark.parametrize("width", [50, 80, 120, 200])
def test_the_list_of_commands_is_the_commands_own(width: int) -> None:
    def help_text(group: click.Group, parent: click.Context | None = None) -> str:
        # a subgroup's help in the context it has under ``pneumorph`` (its -h comes from there): click keeps a
        # command's help option once made, so a context of its own would depend on what ran before
        ctx = click.Context(group, parent=parent, info_name="materials" if parent else "pneumorph",
                            terminal_width=width, max_content_width=width, **group.context_settings)
        return group.get_help(ctx)

    text = help_text(cli)
    assert text == help_text(_eager())
    assert all(f"  {name}  " in text for name in COMMANDS) and "simulate     Inflate one actuator design" in text
    top = click.Context(cli, info_name="pneumorph", **cli.context_settings)
    listed = help_text(materials, top)
    assert listed == help_text(_eager(materials), top)
    assert "-h, --help" in listed
    assert all(f"  {name}  " in listed for name in MATERIALS_COMMANDS)


def test_every_command_the_modules_define_is_reachable_from_the_table() -> None:
    """Every click command that a module under ``pneumorph.cli`` defines is a command of the table or of one of its
    groups (a new command missing from the table would be missing from ``pneumorph``)."""
    import pkgutil

    import pneumorph.cli as package

    reachable: set[int] = set()

    def walk(command: click.Command) -> None:
        reachable.add(id(command))
        if isinstance(command, click.Group):
            ctx = click.Context(command)
            for name in command.list_commands(ctx):
                walk(command.get_command(ctx, name))

    walk(cli)
    defined = {f"{info.name}.{name}": value for info in pkgutil.walk_packages(package.__path__, "pneumorph.cli.")
               for name, value in vars(importlib.import_module(info.name)).items()
               if isinstance(value, click.Command)}
    assert len(defined) > len(COMMANDS)
    assert [where for where, command in defined.items() if id(command) not in reachable] == []


def test_the_group_lists_without_importing_a_command() -> None:
    code = ("import sys; from pneumorph.cli import main; code = main(['--help']); "
            "print(code, sorted(m for m in sys.modules if m.startswith('pneumorph.cli.')))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.splitlines()[-1] == "0 []"
    assert "Commands:" in done.stdout and "unit " in done.stdout


MATERIALS_HELP = [f"materials {name}" for name in sorted(MATERIALS_COMMANDS)] + [
    f"materials characterise {name}" for name in ("bilinear", "poisson", "thermal")]


def test_a_commands_help_imports_no_numerical_code() -> None:
    """``pneumorph X --help`` (and ``pneumorph materials X --help``, down to ``materials characterise X``) builds X's
    options from :mod:`pneumorph.checks` and click alone: the models, the evaluators, pneumorph.io, the material code
    and NumPy (half a second of imports) are imported when X runs."""
    heavy = ("numpy", "scipy", "pneumorph.models", "pneumorph.execution", "pneumorph.io", "pneumorph.materials")
    names = sorted(COMMANDS) + MATERIALS_HELP
    code = ("import sys; from pneumorph.cli import main\n"
            f"for name in {names!r}:\n"
            "    code = main([*name.split(), '--help'])\n"
            f"    print(name, code, [m for m in {heavy!r} if m in sys.modules], file=sys.stderr)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stderr.splitlines() == [f"{name} 0 []" for name in names]


@pytest.mark.parametrize("typed", ["simulat", "desing", "nothing"])
def test_a_mistyped_command_gets_the_same_error_and_suggestion(typed: str) -> None:
    from click.testing import CliRunner

    lazy, eager = (CliRunner().invoke(group, [typed, "-o", "01"], prog_name="pneumorph") for group in (cli, _eager()))
    assert lazy.exit_code == eager.exit_code == 2
    assert lazy.output == eager.output
    assert ("Did you mean" in lazy.output) == (typed != "nothing")
