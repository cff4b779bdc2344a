"""Command-line interface: a thin layer over the public API.

Each sub-command group lives in its own module and only parses arguments, calls the API
and prints results (human-readable, or JSON with ``--json``). Units at this edge are the
ones users speak (kPa for pressure); the API works in mm, N, MPa.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
from typing import Any

import click

from pneumorph import __version__
from pneumorph.errors import PneumorphError, note_sigint, sigints

#: Every command: the module that defines it (a ``click`` command of the same name) and the first sentence of its
#: help, which ``pneumorph --help`` lists. A command's module is imported only when that command runs or shows its
#: own help, so a command pays for its own imports only (``simulate --help`` none of ``design``'s).
COMMANDS: dict[str, tuple[str, str]] = {
    "bimodal": ("pneumorph.cli.bilinear.bimodal", "3D FE of the bimodal actuator: tip displacement in volume or "
                "pressure steps, switch pressure."),
    "calibrate": ("pneumorph.cli.calibrate", "Fit the filler law E(P) of the 2D model to the 3D model (chapter 5) "
                  "and check it."),
    "chain": ("pneumorph.cli.chain", "Chain tables: per-window chord turns and lengths fitted to FE solves "
              "(documentation page chain-model, docs/chain-model.md in the source)."),
    "composite": ("pneumorph.cli.bilinear.composite", "Bilinear paper-silicone composite: analytical transition "
                  "strain, coupon FE, strain gauges."),
    "correlate": ("pneumorph.cli.casting.correlate", "Align SCAN (STL, PLY, OBJ, OFF, XYZ, or a CSV of x,y traced on "
                  "a photo) to the model's inflated shape by least squares, and report RMS and maximum distances "
                  "on the surface, along the outline and along the centreline."),
    "design": ("pneumorph.cli.design", "Design the actuator whose inflated shape best matches a target or tip goal."),
    "export": ("pneumorph.cli.casting.export", "Write DESIGN's parts (the Mold Star body with its cavities, the "
               "Smooth-Sil layer pieces, the base block) as watertight STL files, with --mould the printable casting "
               "mould of the body, and with --inp the 3D model as a CalculiX/Abaqus deck (documentation page "
               "manufacturing, docs/manufacturing.md in the source)."),
    "identify": ("pneumorph.cli.casting.identify", "Fit the body silicone's bulk and shear modulus scales and the "
                 "three mould thicknesses (side walls, Mold Star wall, Smooth-Sil layer) to scans of cast actuators, "
                 "by least squares on the distances `correlate` measures; report each with its standard error, the "
                 "correlations, the residuals before and after, the combinations of parameters the scans do not "
                 "determine (held at nominal, the others still identified) and which further scan would determine "
                 "them."),
    "materials": ("pneumorph.cli.materials.group", "Silicone and composite materials: list, show, fit, "
                  "characterise."),
    "scan": ("pneumorph.cli.casting.scan", "Scans of cast actuators: a synthetic one of a design, for trying the "
             "loop design -> cast -> scan -> identify before a real cast (documentation page identify, "
             "docs/identify.md in the source)."),
    "sensitivity": ("pneumorph.cli.sensitivity", "How far a design's inflated shape moves with the model's "
                    "simplifications, mould tolerances and material data (appendices D and E; documentation page "
                    "sensitivity, docs/sensitivity.md in the source)."),
    "serve": ("pneumorph.cli.serve", "Open the designer's bench: type or draw a target, see the certified design at "
              "once."),
    "simulate": ("pneumorph.cli.simulate", "Inflate one actuator design and report its shape at every pressure "
                 "level."),
    "study": ("pneumorph.cli.study", "Best fitness against GA population size over several seeds (lowest, largest, "
              "mean)."),
    "unit": ("pneumorph.cli.unit", "The articulating unit: geometry optimisation (documentation page unit-library, "
             "docs/unit-library.md in the source)."),
}


class LazyGroup(click.Group):
    """A group whose commands are imported on first use, listed from a table (the ``pneumorph`` group's:
    :data:`COMMANDS`): each name's module (``module`` or ``module:attribute``, the attribute by default the name)
    and the first sentence of its help."""

    def __init__(self, *args: Any, table: dict[str, tuple[str, str]] | None = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.table = table if table is not None else {}

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted({*self.table, *self.commands})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in self.table:
            module, _, attribute = self.table[cmd_name][0].partition(":")
            self.add_command(getattr(importlib.import_module(module), attribute or cmd_name), cmd_name)
        return self.commands.get(cmd_name)

    def resolve_command(self, ctx: click.Context, args: list[str]) -> tuple[str | None, click.Command | None,
                                                                           list[str]]:
        """As click's; a mistyped command's close names from the table (click's own from the loaded commands)."""
        try:
            return super().resolve_command(ctx, args)
        except click.exceptions.NoSuchCommand:
            raise click.exceptions.NoSuchCommand(args[0], possibilities=self.list_commands(ctx), ctx=ctx) from None

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """The commands and their summaries as click lists them, from the table: no command imported."""
        names = self.list_commands(ctx)
        limit = formatter.width - 6 - max(len(name) for name in names)
        stand_ins = [click.Command(name, help=self.table[name][1]) if name in self.table and name not in self.commands
                     else self.commands[name] for name in names]
        rows = [(name, command.get_short_help_str(limit)) for name, command in zip(names, stand_ins, strict=True)
                if not command.hidden]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, table=COMMANDS, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", "-V", prog_name="pneumorph")
def cli() -> None:
    """pneumorph - generative design of soft pneumatic actuators."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that a run stops as on Ctrl-C (exit 143)."""


_terminated = threading.Event()


def _on_sigterm(signum: int, frame: object) -> None:
    _terminated.set()
    raise Terminated()


def _usage_line(exc: click.UsageError) -> str:
    where = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
    text = " ".join(exc.format_message().split())
    if isinstance(exc, click.BadParameter) and exc.param is not None:  # our types name the option themselves
        names = [*getattr(exc.param, "opts", []), (exc.param.name or "").upper()]
        head, _, rest = text.partition(": ")
        if head.startswith("Invalid value for") and any(rest.startswith(n) for n in names if n):
            text = rest
    elif text.startswith("Invalid value for '--"):  # raised with a hint whose text names the option again
        head, _, rest = text.partition(": ")
        if rest.startswith("--"):
            text = rest
    return text + where


def check_repeats(argv: list[str]) -> None:
    """Refuse an option given more than once where only one value is kept (click keeps the last, unchecked).

    >>> check_repeats(["simulate", "-o", "01", "--pressure", "abc", "--pressure=10"])
    Traceback (most recent call last):
    ...
    click.exceptions.UsageError: --pressure is given 2 times; give it once
    >>> check_repeats(["design", "--objective", "max-x", "--out", "a"])
    """
    command: click.Command = cli
    i = 0
    while isinstance(command, click.Group) and i < len(argv):
        sub = command.get_command(click.Context(command), argv[i])  # a command's module loaded only if named
        if sub is None:
            break
        command, i = sub, i + 1
    single = {name: p for p in command.params if isinstance(p, click.Option) and not p.multiple and not p.count
              for name in (*p.opts, *p.secondary_opts)}
    seen: dict[str, list[str]] = {}
    for token in argv[i:]:
        if token == "--":
            break
        key = token.split("=", 1)[0] if token.startswith("--") else token
        if key in single:
            seen.setdefault(single[key].name or key, []).append(key)
    for keys in seen.values():
        if len(keys) > 1:
            raise click.UsageError(f"{keys[0]} is given {len(keys)} times; give it once")


def _on_sigint(signum: int, frame: object) -> None:
    note_sigint()
    raise KeyboardInterrupt


def _on_signal_at_exit(signum: int, frame: object) -> None:
    """Ctrl-C or SIGTERM after ``main`` returned, while the interpreter shuts down (threads joined, exit handlers):
    the same line and exit code as during the run, at once (a KeyboardInterrupt here would be a traceback, and the
    default handler kills the process without a line)."""
    interrupt = signum == signal.SIGINT
    if interrupt:
        note_sigint()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # closed, or interrupted in its own write: what it holds is lost either way
            pass
    try:
        os.write(2, b"aborted\n" if interrupt else b"terminated\n")
    finally:
        os._exit(130 if interrupt else 143)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code.

    Every error a user can cause prints one line and returns 2: bad options and arguments
    (click's usage errors) and every :class:`~pneumorph.errors.PneumorphError`, except a
    lost Dask cluster (:class:`~pneumorph.errors.ClusterLostError`): one line with the
    command that resumes, exit 3. Ctrl-C
    returns 130, SIGTERM 143 (both after the run has written what it had); anything else
    is a defect of pneumorph: one line asking for a report, exit 1 (``PNEUMORPH_DEBUG=1``
    shows the traceback).

    Ctrl-C is the same at every moment of a run: a press that a library swallowed (trimesh
    catches ``BaseException`` around its optional imports) or that turned into another error
    (an ``ImportError`` of a half-imported module) still ends the run with "aborted" and 130,
    as does a press after the run's last line. Run as the process's own command line
    (``argv`` None), that holds to the process's end: a press (or SIGTERM) after ``main`` has
    returned, while the interpreter shuts down, prints "aborted" ("terminated") and ends the
    process at once with 130 (143); the run's outputs are complete by then.
    """
    previous: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:  # an ignored SIGTERM (nohup) stays ignored
            previous[signal.SIGTERM] = signal.signal(signal.SIGTERM, _on_sigterm)
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # an ignored Ctrl-C stays ignored
            previous[signal.SIGINT] = signal.signal(signal.SIGINT, _on_sigint)
    _terminated.clear()
    pressed = sigints()
    try:
        try:
            code = _run(argv, pressed)
        except KeyboardInterrupt:  # pressed while a line was being printed
            code = 130
            click.echo("aborted", err=True)
        if code == 0 and sigints() != pressed:  # pressed after the last line, or swallowed by a library
            click.echo("aborted", err=True)
            code = 130
    except KeyboardInterrupt:  # pressed again while saying so
        code = 130
    finally:
        for number, handler in previous.items():  # as the process's command line: to its very end
            signal.signal(number, _on_signal_at_exit if argv is None else handler)
    return code


def _run(argv: list[str] | None, pressed: int) -> int:
    """Run the command; its exit code, with the one line that goes with it printed."""
    try:
        check_repeats(list(sys.argv[1:] if argv is None else argv))
        cli.main(args=argv, prog_name="pneumorph", standalone_mode=False)
    except Terminated:
        click.echo("terminated", err=True)
        return 143
    except (click.exceptions.Abort, KeyboardInterrupt):
        if _terminated.is_set():  # click turns the SIGTERM's Terminated into Abort inside a command
            return _say("terminated", 143)
        click.echo("aborted", err=True)
        return 130
    except click.UsageError as exc:
        return _interrupted(pressed) or _say(f"error: {_usage_line(exc)}", 2)
    except click.ClickException as exc:
        return _interrupted(pressed) or _say(f"error: {' '.join(exc.format_message().split())}", exc.exit_code)
    except PneumorphError as exc:
        if _interrupted(pressed):
            return 130
        text = " ".join(str(exc).split())
        code = getattr(exc, "exit_code", 2)
        if code == 3:  # the cluster went away: the same command resumes from the cache
            import shlex

            text += f"; resume with: pneumorph {shlex.join(sys.argv[1:] if argv is None else argv)}"
        return _say(f"error: {text}", code)
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        return 143 if code == 130 and _terminated.is_set() else code  # a run that stopped on SIGTERM
    except Exception as exc:  # a defect, not a user error
        if _interrupted(pressed):
            return 130
        if os.environ.get("PNEUMORPH_DEBUG"):
            raise
        return _say(f"internal error: {type(exc).__name__}: {' '.join(str(exc).split())} - please report it "
                    "(PNEUMORPH_DEBUG=1 shows the traceback)", 1)
    return 0


def _say(line: str, code: int) -> int:
    click.echo(line, err=True)
    return code


def _interrupted(pressed: int) -> int:
    """130 with "aborted" printed if Ctrl-C came since the run began (an error that follows it is its
    consequence: an ImportError of a module the press left half imported), else 0."""
    if sigints() == pressed:
        return 0
    return _say("aborted", 130)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
