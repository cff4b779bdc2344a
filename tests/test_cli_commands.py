"""The ``pneumorph`` group loads a command's module only when that command runs: its table of commands
(``COMMANDS``) names every command's module and summary, and ``pneumorph --help`` lists them as the commands
themselves would, without importing one."""

from __future__ import annotations

import importlib
import subprocess
import sys

import click
import pytest

from pneumorph.cli import COMMANDS, cli


def _eager() -> click.Group:
    """The same group with every command imported and added, as click builds it without a table."""
    group = click.Group("pneumorph", params=cli.params, help=cli.help,
                        context_settings={"help_option_names": ["-h", "--help"]})
    for name, (module, _) in COMMANDS.items():
        group.add_command(getattr(importlib.import_module(module), name), name)
    return group


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_is_its_modules_and_its_summary_is_its_helps_first_sentence(name: str) -> None:
    module, summary = COMMANDS[name]
    command = getattr(importlib.import_module(module), name)
    assert isinstance(command, click.Command) and command.name == name
    assert summary == command.get_short_help_str(10_000)
    assert cli.get_command(click.Context(cli), name) is command


@pytest.mark.parametrize("width", [50, 80, 120, 200])
def test_the_list_of_commands_is_the_commands_own(width: int) -> None:
    def help_text(group: click.Group) -> str:
        ctx = click.Context(group, info_name="pneumorph", terminal_width=width, max_content_width=width,
                            **group.context_settings)
        return group.get_help(ctx)

    text = help_text(cli)
    assert text == help_text(_eager())
    assert all(f"  {name}  " in text for name in COMMANDS) and "simulate     Inflate one actuator design" in text


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


@pytest.mark.parametrize("typed", ["simulat", "desing", "nothing"])
def test_a_mistyped_command_gets_the_same_error_and_suggestion(typed: str) -> None:
    from click.testing import CliRunner

    lazy, eager = (CliRunner().invoke(group, [typed, "-o", "01"], prog_name="pneumorph") for group in (cli, _eager()))
    assert lazy.exit_code == eager.exit_code == 2
    assert lazy.output == eager.output
    assert ("Did you mean" in lazy.output) == (typed != "nothing")
