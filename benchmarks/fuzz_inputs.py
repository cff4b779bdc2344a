"""A systematic round of bad input over every file and number the command line reads, each case bounded.

The cases are not drawn at random but enumerated from the command tree: every option or argument that
reads a file (``InputFile``, and the options that take a file by name: ``--library``, ``--target
path:FILE``) meets a device (``/dev/zero``, ``/dev/urandom``), a named pipe, a folder, a sparse file of
1 GB, a file with a byte-order mark, binary garbage, JSON nested 100,000 deep and 60 MB of short rows;
every number option (``Real``, ``Count``, ``RealList``) meets ``nan``, ``inf``, ``-1``, ``0``, ``1e300``
and text. Each case starts from a baseline that would run (tiny 2D models, coarse elements) and runs in a
subprocess whose solvers are tripwires: a solve reached ends it with exit 99 (the value was accepted). A case is judged:

- *internal error*: ``internal error`` or a traceback on stderr (exit 1);
- *accepted bad input*: exit 0 or 99 for a value no option takes (a device, a pipe, a folder, 1 GB,
  garbage, deep JSON, 60 MB of rows, ``nan``, ``inf``, text, ``1e300``);
- *runaway*: more than :data:`TIMEOUT` s of CPU, :data:`WALL_LIMIT` s of wall time or :data:`MAX_RSS_MB` MB
  (the child's peak resident memory);
- *untidy refusal*: exit 2 with more than one line, or files left behind;
- otherwise clean (refused in one line, or, for ``-1``, ``0`` and a byte-order mark, accepted).

    OMP_NUM_THREADS=1 python benchmarks/fuzz_inputs.py [--cases 550] [--seed 0] [--json F]

All path cases are run (414); the number cases fill the rest, every number option once (128) before any twice.
``--only COMMAND`` (or ``--only "COMMAND OPTION"``, repeatable) runs every case of those commands or options
alone, e.g. a command's newest options:

    OMP_NUM_THREADS=1 python benchmarks/fuzz_inputs.py --only simulate --only bimodal
"""

from __future__ import annotations

import argparse
import json
import os
import random
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))  # the command tree of this checkout, as its cases run it
sys.path.insert(0, str(ROOT / "benchmarks"))  # the baselines beside this script, also when a test loads it
from fuzz_baselines import BASE, UNIT, case_env, spoil  # noqa: E402
from fuzz_baselines import FILES as BASELINE_FILES  # noqa: E402

TIMEOUT = 10.0  # CPU seconds of a case (interpreter start included): past it, a runaway
WALL_LIMIT = 60.0  # a case still running after this wall time is stopped (a shared machine stretches wall times)
MAX_RSS_MB = 300.0

LAUNCHER = """
import os, sys

def _reached(*args, **kwargs):
    sys.stderr.write("fuzz: a solve was reached\\n")
    sys.stderr.flush()
    os._exit(99)

import pneumorph.models.fe as fe
import pneumorph.bimodal.model as bimodal
import pneumorph.composite.coupon as coupon
import pneumorph.execution as execution
import pneumorph.execution.evaluators as evaluators
import uvicorn

fe.FEModel.solve = fe.FEModel.evaluate = _reached
bimodal.BimodalModel.solve = _reached
coupon.simulate_coupon = _reached
uvicorn.run = _reached
execution.make_evaluator = evaluators.make_evaluator = lambda *a, **k: evaluators.SerialEvaluator()
from pneumorph.cli import main
sys.exit(main(sys.argv[1:]))
"""

#: the scan of correlate and identify: a bending centreline with a zigzag of 0.5 mm
TRACE = "x,y\n" + "".join(f"{42.0 * i / 119:.4f},{6.0 + 0.002 * (42.0 * i / 119) ** 2 + (i % 2) * 0.5:.4f}\n"
                          for i in range(120))
FILES = {**BASELINE_FILES, "trace.csv": TRACE}
#: the options that take a file by name in a text option (a library's name or its file; a path target)
NAMED_FILES = {"design": ["--library", "--target"], "simulate": ["--library"], "chain build": ["--library"],
               "export": ["--library"], "correlate": ["--library"], "materials fit": ["stress.csv"]}

# The hostile files and what each must get: "refuse" (any value of its kind is bad) or "either" (read correctly).
PATHS = {"/dev/zero": "refuse", "/dev/urandom": "refuse", "pipe": "refuse", "folder": "refuse",
         "huge.bin": "refuse", "bom": "either", "garbage.bin": "refuse", "deep.json": "refuse", "bulk.csv": "refuse"}
#: 60 MB of rows "1,2" under a header "x,y": text under the text limit, but fifteen million rows or points
NUMBERS = {"nan": "refuse", "inf": "refuse", "-1": "either", "0": "either", "1e300": "refuse", "abc": "refuse"}


@dataclass
class Case:
    command: str
    option: str
    value: str
    argv: list[str]
    expect: str


@dataclass
class Outcome:
    command: str
    option: str
    value: str
    code: int
    seconds: float
    cpu_s: float
    rss_mb: float
    verdict: str
    stderr_tail: list[str] = field(default_factory=list)


def _leaves() -> dict[str, Any]:
    import click

    from pneumorph.cli import cli

    def walk(group: click.Group, path: tuple[str, ...] = ()) -> dict[str, Any]:
        out: dict[str, Any] = {}
        ctx = click.Context(group)
        for name in group.list_commands(ctx):  # the top group imports each command here
            command = group.get_command(ctx, name)
            if isinstance(command, click.Group):
                out.update(walk(command, (*path, name)))
            else:
                out[" ".join((*path, name))] = command
        return out

    return walk(cli)


def all_cases() -> tuple[list[Case], list[Case]]:
    """(path cases, number cases) of every command."""
    from pneumorph.cli.options import params as P

    paths, numbers = [], []
    for key, command in sorted(_leaves().items()):
        bases = [b for b in (key, f"{key}-config") if b in BASE]
        for base in bases:
            argv = BASE[base]
            files = []
            for param in command.params:
                if not isinstance(param.type, P.InputFile):
                    continue
                if param.param_type_name == "argument":
                    named = argv[len(key.split())]  # the baseline's positional file, if it has one
                    if named in FILES and named not in files:
                        files.append(named)
                elif base == key:
                    files.append(max(param.opts, key=len))
            if base == key:
                files += NAMED_FILES.get(key, [])
            for option in files:
                for value, expect in PATHS.items():
                    given = f"path:{value}" if option == "--target" else value
                    paths.append(Case(base, option, given, spoil(argv, option, given), expect))
            if base != key:
                continue
            for param in command.params:
                if isinstance(param.type, (P.Real, P.Count, P.RealList)) and param.param_type_name == "option":
                    option = max(param.opts, key=len)
                    for value, expect in NUMBERS.items():
                        numbers.append(Case(key, option, value, spoil(argv, option, value), expect))
    return paths, numbers


def cases(count: int = 400, seed: int = 0, only: list[str] | None = None) -> list[Case]:
    """Every path case, then number cases up to ``count``: every number option once, then drawn (seeded); with
    ``only``, every case of those commands (``"simulate"``) or options (``"simulate --volume-change"``)."""
    paths, numbers = all_cases()
    if only:
        return [c for c in paths + numbers if c.command in only or f"{c.command} {c.option}" in only]
    rng = random.Random(seed)
    rng.shuffle(numbers)
    first: dict[tuple[str, str], Case] = {}
    for c in numbers:
        first.setdefault((c.command, c.option), c)
    rest = [c for c in numbers if first[(c.command, c.option)] is not c]
    chosen = list(first.values()) + rest
    return paths + chosen[:max(0, count - len(paths))]


_BULK: list[Path] = []


def _bulk() -> Path:
    """The bulk file, written once per round (each case's folder links to it)."""
    if not _BULK:
        path = Path(tempfile.mkdtemp(prefix="fuzz-inputs-bulk-")) / "bulk.csv"
        with path.open("w", encoding="utf-8") as fh:
            fh.write("x,y\n")
            for _ in range(15):
                fh.write("1,2\n" * 2**20)
        _BULK.append(path)
    return _BULK[0]


def _prepare(folder: Path, bulk: bool = False) -> None:
    for name, text in FILES.items():
        (folder / name).write_text(text, encoding="utf-8")
    (folder / "folder").mkdir()
    os.mkfifo(folder / "pipe")
    with (folder / "huge.bin").open("wb") as fh:
        fh.truncate(2**30)
    (folder / "bom").write_bytes(b"\xef\xbb\xbf" + UNIT.encode())
    (folder / "garbage.bin").write_bytes(random.Random(0).randbytes(4096))
    (folder / "deep.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    if bulk:
        (folder / "bulk.csv").symlink_to(_bulk())


def _listing(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def run_case(case: Case, python: str = sys.executable) -> Outcome:
    """Run one case in a fresh folder, bounded by :data:`TIMEOUT`; judge how it ended."""
    folder = Path(tempfile.mkdtemp(prefix="fuzz-inputs-"))
    try:
        _prepare(folder, bulk=case.value.endswith("bulk.csv"))
        (folder / "launch.py").write_text(LAUNCHER, encoding="utf-8")
        before = _listing(folder)
        env = case_env(folder)
        t0 = time.perf_counter()
        with open(folder / "err", "wb") as err, open(os.devnull, "wb") as out:
            child = subprocess.Popen([python, "launch.py", *case.argv], cwd=folder, env=env, stdout=out, stderr=err,
                                     stdin=subprocess.DEVNULL)
            code, cpu, rss = _wait(child)
        seconds = time.perf_counter() - t0
        lines = [x for x in (folder / "err").read_text(errors="replace").splitlines() if x.strip()]
        left = {p for p in _listing(folder) - before - {"err"} if not p.startswith("xdg")}
        verdict = _judge(case, code, lines, left, cpu, rss)
        return Outcome(case.command, case.option, case.value, code, round(seconds, 2), round(cpu, 2), round(rss, 1),
                       verdict, lines[-2:])
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _high_water_mb(pid: int) -> float | None:
    """The process's own peak resident memory (VmHWM), MB, or None where /proc does not tell.

    Not ``ru_maxrss``: Linux keeps that across ``exec``, so a child forked from a large process (a test
    worker) would report its parent's size.
    """
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    except OSError:
        return None
    return None


def _wait(child: subprocess.Popen[bytes]) -> tuple[int, float, float]:
    """The child's exit code (-1: stopped at :data:`WALL_LIMIT`), its CPU seconds and its peak resident memory, MB."""
    deadline = time.monotonic() + WALL_LIMIT
    peak: float | None = None
    while True:
        seen = _high_water_mb(child.pid)  # read while it runs: its own memory after exec
        peak = seen if peak is None or (seen is not None and seen > peak) else peak
        pid, status, usage = os.wait4(child.pid, os.WNOHANG)
        if pid:
            child.returncode = os.waitstatus_to_exitcode(status)
            break
        if time.monotonic() > deadline:
            child.kill()
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = -1
            break
        time.sleep(0.05)
    return child.returncode, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024 if peak is None else peak


def _judge(case: Case, code: int, lines: list[str], left: set[str], cpu: float, rss: float) -> str:
    text = "\n".join(lines)
    if code == -1 or cpu > TIMEOUT or rss > MAX_RSS_MB:
        return "runaway"
    if "Traceback" in text or "internal error" in text or code == 1:
        return "internal error"
    if code in (0, 99):
        return "accepted bad input" if case.expect == "refuse" else "clean"
    if code == 2:
        if len(lines) != 1 or not lines[0].startswith("error: ") or left:
            return "untidy refusal"
        return "clean"
    return f"exit {code}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=550)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--only", action="append", metavar="COMMAND[ OPTION]",
                        help="every case of this command or option alone (repeatable)")
    args = parser.parse_args()
    todo = cases(args.cases, args.seed, args.only)
    if not todo:
        parser.error(f"no case of {args.only}: a command is named as BASE names it ('chain build')")
    t0 = time.perf_counter()
    outcomes = [run_case(c) for c in todo]  # one at a time: each case's time and memory are its own
    wall = time.perf_counter() - t0
    counts: dict[str, int] = {}
    for o in outcomes:
        counts[o.verdict] = counts.get(o.verdict, 0) + 1
    own = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    paths = sum(c.value.removeprefix("path:") in PATHS for c in todo)
    slowest, cpu, largest = (max(o.seconds for o in outcomes), max(o.cpu_s for o in outcomes),
                             max(o.rss_mb for o in outcomes))
    print(f"{len(outcomes)} cases ({paths} of files, {len(todo) - paths} of numbers; seed {args.seed}) in "
          f"{wall:.0f} s; slowest {slowest:.1f} s wall, {cpu:.1f} s CPU; largest {largest:.0f} MB (children's peak "
          f"{own:.0f} MB)")
    print("  " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for o in outcomes:
        if o.verdict != "clean":
            print(f"FINDING {o.command} {o.option} {o.value!r}: {o.verdict} (exit {o.code}, {o.seconds} s, "
                  f"{o.cpu_s} s CPU, {o.rss_mb} MB); {' | '.join(o.stderr_tail)[:300]}")
    for bulk in _BULK:
        shutil.rmtree(bulk.parent, ignore_errors=True)
    if args.json:
        args.json.write_text(json.dumps({"wall_s": wall, "outcomes": [asdict(o) for o in outcomes]}, indent=1))
    return 1 if any(o.verdict != "clean" for o in outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
