"""An end-to-end fuzz round of the command line: bad-but-plausible input on tiny real models.

Each case starts from a command line that runs in seconds (a 2D model of 2-4 units, coarse
``element_size = 3.0`` unit files, low pressures; export needs no solve) and spoils one thing,
drawn by a seeded generator: the output path (pseudo-filesystems, a file, under a file, empty,
through a symlink), the unit file's and the scan's contents, a photo, curve configs and config
keys (base_block, gravity vectors, tolerance, robust, library), options that would be ignored,
an option given twice, huge-but-valid values. Some cases are valid (nested new folders, names
with spaces) and must run. Every case runs in its own folder in a subprocess with the real
solvers, so errors raised after a solve (writing, figures, photos) are reached; 3D solves are
not run: the launcher stops a case that reaches one (exit 99, "reached a 3D solve"), which
counts as accepted.

A case passes when it ends with exit 0 (and was not expected to be refused), 99 (a 3D solve was
reached and was allowed), or exit 2 with exactly one line on stderr, no "internal error" or
"Traceback", and nothing left in the case's folder.

    OMP_NUM_THREADS=1 MPLBACKEND=Agg python benchmarks/fuzz_round.py [--cases 400] [--seed 0] [--jobs 2]
        [--json F]

``tests/test_cli_fuzz_e2e.py`` runs a seeded subset of the same cases.
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))  # the baselines beside this script, also when a test loads it
from fuzz_baselines import BASE as BASELINES  # noqa: E402
from fuzz_baselines import REPEATABLE, RUN_TOML, UNIT, case_env  # noqa: E402

TIMEOUT = 120.0

# The launcher: the real command line, but a 3D solve ends the case (exit 99) instead of running.
LAUNCHER = """
import os, sys
import pneumorph.models.fe as fe

def _no_3d(*args, **kwargs):
    sys.stderr.write("fuzz: reached a 3D solve\\n")
    sys.stderr.flush()
    os._exit(99)

fe.Full3D.solve = _no_3d
from pneumorph.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _png(width: int, height: int, body: bytes | None = None) -> bytes:
    """A PNG of grey pixels (or a header claiming ``width`` x ``height`` over ``body``)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = body if body is not None else b"".join(b"\x00" + b"\x80" * width for _ in range(height))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def _trace(n: int = 120, length: float = 42.0) -> str:
    """A 2D trace (x, y in mm) along a 4-unit actuator's centreline, bending a little."""
    return "x,y\n" + "".join(f"{length * i / (n - 1):.4f},{6.0 + 0.002 * (length * i / (n - 1)) ** 2:.4f}\n"
                             for i in range(n))


def files() -> dict[str, bytes]:
    """The files every case's folder starts with."""
    return {
        "unit.toml": UNIT.encode(),
        "trace.csv": _trace().encode(),
        "photo.png": _png(64, 48),
        "stress.csv": b"stretch,stress\n1.0,0.0\n1.5,0.2\n2.0,0.35\n2.5,0.5\n",
        "a-file": b"not a folder\n",
    }


# -- baselines: command lines that run in seconds (benchmarks/fuzz_baselines.py), by this round's names ------

#: this round's commands and the baselines they start from
COMMANDS = {"design": "design", "design-config": "design-config", "simulate": "simulate", "correlate": "correlate",
            "export": "export", "sensitivity": "sensitivity tolerances", "chain": "chain build",
            "unit": "unit optimise", "identify": "identify", "materials": "materials fit", "study": "study"}
#: a baseline's output under the name a case replaces (OUT, OUT.json, OUT.png)
_OUTPUTS = {"run": "OUT", "run.json": "OUT.json", "run.png": "OUT.png"}
BASE: dict[str, list[str]] = {name: [_OUTPUTS.get(token, token) for token in BASELINES[path]]
                              for name, path in COMMANDS.items()}


def _out_option(argv: list[str]) -> str | None:
    for i, token in enumerate(argv):
        if token in ("OUT", "OUT.json", "OUT.png"):
            return argv[i - 1] if argv[i - 1].startswith("-") else None
    return None


# -- mutations ------------------------------------------------------------------------------
# Each returns (argv, extra files) or None where it does not apply; "expect" is "refuse", "run"
# or "either" (valid or not, it must end cleanly).


@dataclass
class Case:
    number: int
    command: str
    mutation: str
    value: str
    argv: list[str]
    files: dict[str, str]
    expect: str


def _set(argv: list[str], option: str, value: str) -> list[str] | None:
    if option not in argv:
        return None
    i = argv.index(option)
    return [*argv[:i + 1], value, *argv[i + 2:]]


OUT_PATHS = [("/proc/fuzz", "refuse"), ("/sys/fuzz", "refuse"), ("/proc/self/x/y", "refuse"),
             ("a-file", "refuse"), ("a-file/sub", "refuse"), ("", "refuse"), ("proc-link/x", "refuse"),
             ("deep/new/nested/OUTNAME", "run"), ("with space/ü-OUTNAME", "run")]

UNIT_FILES = [
    ("filler_coefficients = [\"a\", \"b\"]", "refuse"), ("filler_range_kpa = \"x\"", "refuse"),
    ("filler_range_kpa = [45.0, 0.0]", "refuse"), ("pitch = 1e4", "refuse"), ("pitch = nan", "refuse"),
    ("wall = -1.0", "refuse"), ("element_size = 1e-3", "refuse"), ("solid = true", "refuse"),
    ("pitch = \"ten\"", "refuse"), ("unknown_key = 1", "refuse"), ("element_size = 3.0\nwall = 1e9", "refuse"),
    ("cavity_height = 0", "refuse"), ("BINARY", "refuse"), ("EMPTY", "either"), ("NESTED", "refuse"),
]

SCANS = [
    ("EMPTY", "refuse"), ("x,y\n", "refuse"), ("x,y\nnan,1\n" + "1,2\n" * 40, "refuse"),
    ("x,y\n1,2\n3,4\n5,6\n", "refuse"), ("x,y\n" + "1e300,1e300\n" * 50, "refuse"),
    ("x,y\n" + "a,b\n" * 50, "refuse"), ("u,v\n" + "1,2\n" * 50, "refuse"), ("x,y\n" + "1,2\n" * 200, "refuse"),
    ("BINARY", "refuse"), ("x,y,z\n" + "".join(f"{i},{i % 3},0\n" for i in range(100)), "refuse"),
]

PHOTOS = [("not an image", "refuse"), ("HUGE_PNG", "refuse"), ("EMPTY", "refuse"), ("photo.png", "run"),
          ("TRUNCATED_PNG", "refuse")]

CURVES = [("[[0, 0], [20, true], [40, 1]]", "refuse"), ('[["0", "0"], ["20", "1"], ["40", "2"]]', "refuse"),
          ("[[0, 0], [1e-9, 0]]", "refuse"), ("[[-100, 0], [-50, 1]]", "refuse"), ("[[0, 0]]", "refuse"),
          ("[[0, 0], [20, nan], [40, 1]]", "refuse"), ("[[0, 0], [20, 1], [40, 2]]", "run"),
          ("[[0, 0], [20, 1e300], [40, 1]]", "refuse"), ("[]", "refuse"), ("[[0, 0, 0], [1, 1, 1]]", "refuse")]

CONFIG_KEYS = [
    ("model", "base_block", "{ length = 1e9 }", "refuse"), ("model", "base_block", "{ length = -1 }", "refuse"),
    ("model", "base_block", '"big"', "refuse"), ("model", "base_block", "{ nope = 1 }", "refuse"),
    ("model", "gravity", "[0, -9810]", "either"), ("model", "gravity", "[0, 0, 0, 0]", "refuse"),
    ("model", "gravity", "[nan, 0]", "refuse"), ("model", "gravity", "[1e300, 0]", "refuse"),
    ("model", "gravity", '["a", "b"]', "refuse"), ("design", "tolerance", "-0.1", "refuse"),
    ("design", "tolerance", "5", "refuse"), ("design", "tolerance", "nan", "refuse"),
    ("design", "tolerance", '"0.1"', "refuse"), ("design", "robust", '"best"', "refuse"),
    ("design", "robust", "1", "refuse"), ("design", "robust", '"worst"', "refuse"),
    ("model", "library", '"nope"', "refuse"), ("model", "library", "1", "refuse"),
    ("model", "library", '"missing.toml"', "refuse"), ("design", "robust_samples", "0", "refuse"),
    ("model", "increments", "100000000", "refuse"), ("design", "units", "100000", "refuse"),
]

IGNORED = {
    "design": [["--objective", "max-y", "--amplitude", "5"], ["--objective", "max-y", "--periods", "2"],
               ["--workers", "2"], ["--scheduler", "tcp://x:1"],
               ["--robust-samples", "5"], ["--point", "1", "2"], ["--verify", "2"], ["--margin", "1"],
               ["--no-build"]],
    "simulate": [["--library", "builtin", "--unit", "unit.toml"]],
    "sensitivity": [["--workers", "2"], ["--scheduler", "tcp://x:1"]],
    "chain": [["--workers", "3"]],
    "unit": [["--workers", "2"], ["--scheduler", "tcp://x:1"]],
    "identify": [["--workers", "2"]],
    "study": [["--workers", "2"]],
    "export": [["--clearance", "1"], ["--draft", "2"], ["--pressure", "10"]],
    "correlate": [["--fit-scale", "--scale", "0", "--scan-unit", "cm"]],
}

HUGE = {
    "design": [("--units", "100000"), ("--pressure", "1e9"), ("--seed", str(2 ** 64)), ("--units", "60")],
    "simulate": [("--increments", "1000000000"), ("--pressure", "1e308"), ("-o", "0" * 100000)],
    "correlate": [("--pressure", "1e9"), ("--scale", "1e6"), ("--design", "01" * 400)],
    "export": [("0110", "0" * 5000)],
    "sensitivity": [("--samples", "100000000"), ("--units", "100000"), ("--tolerance", "1e9")],
    "chain": [("--units", "100000"), ("--heldout", "1000000000"), ("--window", "1000")],
    "unit": [("--pop", "1000000"), ("--units", "100000"), ("--gen", "1000000000")],
    "identify": [("--seed", str(2 ** 70)), ("--tolerance", "1e9"), ("--pressure", "1e12")],
    "materials": [("--model", "ogden-99")],
    "study": [("--populations", ",".join(["4"] * 10000)), ("--seeds", "1000000000"), ("--gen", "1000000000")],
}


# Options that may be given more than once (each value is kept).
MULTIPLE = {(name, option) for name, path in COMMANDS.items() for option in REPEATABLE.get(path, ())}


def _mutations(rng: random.Random, command: str) -> tuple[str, str, list[str], dict[str, str], str] | None:
    """One mutation of ``command``'s baseline: (name, value, argv, files, expect)."""
    base = list(BASE[command])
    kinds = ["repeat"]
    kinds += ["out"] * 2 if _out_option(base) else []
    kinds += ["unit"] * 2 if "--unit" in base or command in ("design-config", "study") else []
    kinds += ["scan"] * 2 if command in ("correlate", "identify") else []
    kinds += ["photo"] * 2 if command == "correlate" else []
    kinds += ["curve"] * 2 if command == "design-config" else []
    kinds += ["config"] * 3 if command in ("design-config", "study") else []
    kinds += ["ignored"] if command in IGNORED else []
    kinds += ["huge"] if command in HUGE else []
    kind = "valid" if rng.random() < 0.08 else rng.choice(kinds)
    extra: dict[str, str] = {}
    if command in ("design-config", "study"):
        extra["run.toml"] = RUN_TOML
    if kind == "out" and _out_option(base):
        path, expect = rng.choice(OUT_PATHS)
        target = next(t for t in base if t.startswith("OUT"))
        name = path.replace("OUTNAME", target)
        return "out", path, [name if t == target else t for t in base], extra, expect
    if (kind == "unit" and "--unit" in base) or (kind == "unit" and command in ("design-config", "study")):
        text, expect = rng.choice(UNIT_FILES)
        body = {"BINARY": "\x00\x01\x02binary", "EMPTY": "", "NESTED": "x = " + "[" * 1000 + "]" * 1000}.get(text)
        if command == "export" and text == "solid = true":
            expect = "either"  # exported as a solid body: not judged here (see BENCHMARKS.md)
        extra["unit.toml"] = body if body is not None else UNIT + text + "\n"
        if text == "element_size = 3.0\nwall = 1e9":
            extra["unit.toml"] = "[unit]\n" + text + "\n"
        return "unit", text, base, extra, expect
    if kind == "scan" and command in ("correlate", "identify"):
        text, expect = rng.choice(SCANS)
        extra["trace.csv"] = {"EMPTY": "", "BINARY": "\x00\xff" * 100}.get(text, text)
        return "scan", text[:40], base, extra, expect
    if kind == "photo" and command == "correlate":
        what, expect = rng.choice(PHOTOS)
        extra["bad.png"] = {"not an image": "hello", "EMPTY": ""}.get(what, "")
        if what in ("HUGE_PNG", "TRUNCATED_PNG", "photo.png"):
            extra["bad.png"] = "BYTES:" + {"HUGE_PNG": _png(60000, 60000, b"\x00" * 64),
                                            "TRUNCATED_PNG": _png(64, 48)[:60],
                                            "photo.png": _png(64, 48)}[what].hex()
        return "photo", what, [*base, "--photo", "bad.png"], extra, expect
    if kind == "curve" and command == "design-config":
        curve, expect = rng.choice(CURVES)
        extra["run.toml"] = RUN_TOML.replace('objective = "sin"', f'objective = "curve"\ncurve = {curve}')
        return "curve", curve, base, extra, expect
    if kind == "config" and command in ("design-config", "study"):
        table, key, value, expect = rng.choice(CONFIG_KEYS)
        if command == "study" and key in ("tolerance", "robust", "robust_samples"):
            expect = "either"  # the study may refuse or ignore design-only keys: it must end cleanly
        text = RUN_TOML
        if table == "model" and key == "increments":
            text = text.replace("increments = 3\n", "")
        if table == "design" and key == "units":
            text = text.replace("units = 3\n", "")
        text = text.replace(f"[{table}]\n", f"[{table}]\n{key} = {value}\n", 1)
        extra["run.toml"] = text
        return "config", f"[{table}] {key} = {value}", base, extra, expect
    if kind == "ignored" and command in IGNORED:
        options = rng.choice(IGNORED[command])
        return "ignored", " ".join(options), [*base, *options], extra, "refuse"
    if kind == "repeat":
        options = [t for t in base if t.startswith("--") and (command, t) not in MULTIPLE]
        if options:
            opt = rng.choice(options)
            i = base.index(opt)
            value = base[i + 1] if i + 1 < len(base) and not base[i + 1].startswith("-") else None
            again = [opt, value] if value is not None else [opt]
            if value is None:
                return None  # a repeated flag is harmless
            return "repeat", opt, [*base, *again], extra, "refuse"
    if kind == "huge" and command in HUGE:
        option, value = rng.choice(HUGE[command])
        if option == "0110":
            return "huge", value[:20], [value if t == "0110" else t for t in base], extra, "refuse"
        changed = _set(base, option, value)
        if changed is None:
            changed = [*base, option, value]
        return "huge", f"{option} {value[:20]}", changed, extra, "refuse"
    if kind == "valid":
        return "valid", "", base, extra, "run"
    return None


def case(command: str, mutation: str, value: str, argv: list[str], extra: dict[str, str], expect: str) -> Case:
    """One case written by hand (a finding kept as a regression case)."""
    return Case(-1, command, mutation, value, argv, extra, expect)


def cases(count: int, seed: int = 0) -> list[Case]:
    """``count`` cases, drawn by a seeded generator over every command in turn."""
    rng = random.Random(seed)
    found: list[Case] = []
    commands = sorted(BASE)
    seen: set[tuple[str, ...]] = set()
    tries = 0
    while len(found) < count and tries < count * 50:
        tries += 1
        command = commands[len(found) % len(commands)] if rng.random() < 0.7 else rng.choice(commands)
        drawn = _mutations(rng, command)
        if drawn is None:
            continue
        name, value, argv, extra, expect = drawn
        key = (command, name, value, *argv, *sorted(extra.items()))  # type: ignore[arg-type]
        if key in seen and name != "valid":
            continue
        seen.add(key)
        found.append(Case(len(found), command, name, value, argv, extra, expect))
    return found


# -- running a case ---------------------------------------------------------------------------


@dataclass
class Outcome:
    case: int
    command: str
    mutation: str
    value: str
    expect: str
    code: int
    seconds: float
    verdict: str  # "ok", "refused", "3d", or the finding
    stderr_tail: list[str] = field(default_factory=list)
    argv: list[str] = field(default_factory=list)


def _listing(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*") if not str(p.relative_to(root)).startswith("xdg")}


def run_case(case: Case, python: str = sys.executable) -> Outcome:
    """Run one case in a fresh folder; judge how it ended."""
    folder = Path(tempfile.mkdtemp(prefix=f"fuzz-{case.number:04d}-"))
    try:
        for name, content in {**{k: v.decode("latin-1") for k, v in files().items()}, **case.files}.items():
            if content.startswith("BYTES:"):
                (folder / name).write_bytes(bytes.fromhex(content[6:]))
            else:
                codec = "utf-8" if name in case.files else "latin-1"
                (folder / name).write_bytes(content.encode(codec))
        (folder / "proc-link").symlink_to("/proc")
        (folder / "launch.py").write_text(LAUNCHER, encoding="utf-8")
        before = _listing(folder)
        env = {**case_env(folder), "PYTHONHASHSEED": "0"}
        t0 = time.perf_counter()
        try:
            done = subprocess.run([python, "launch.py", *case.argv], cwd=folder, env=env, capture_output=True,
                                  text=True, timeout=TIMEOUT, errors="replace")
            code, err, out = done.returncode, done.stderr, done.stdout
        except subprocess.TimeoutExpired as exc:
            code, err, out = -1, str(exc.stderr or ""), ""
        seconds = time.perf_counter() - t0
        lines = [line for line in err.splitlines() if line.strip()]
        left = {p for p in _listing(folder) - before if not p.startswith("xdg") and not p.endswith(".sqlite")}
        verdict = _judge(case, code, lines, out, left)
        return Outcome(case.number, case.command, case.mutation, case.value, case.expect, code, round(seconds, 2),
                       verdict, lines[-3:], case.argv)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _judge(case: Case, code: int, lines: list[str], out: str, left: set[str]) -> str:
    text = "\n".join(lines) + out
    if code == -1:
        return f"timeout after {TIMEOUT:.0f} s"
    if "Traceback" in text or "internal error" in text:
        return "internal error"
    if code == 99:
        return "3d" if case.expect != "refuse" else "accepted (reached a 3D solve)"
    if code == 0:
        return "ok" if case.expect != "refuse" else "accepted (exit 0)"
    if code == 2:
        if case.expect == "run":
            return "refused a valid case"
        if len(lines) != 1 or not lines[0].startswith("error: "):
            return f"exit 2 with {len(lines)} lines on stderr"
        if left:
            return f"left {sorted(left)[:3]}"
        return "refused"
    return f"exit {code}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=400)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    todo = cases(args.cases, args.seed)
    t0 = time.perf_counter()
    with ThreadPoolExecutor(args.jobs) as pool:
        outcomes = list(pool.map(run_case, todo))
    wall = time.perf_counter() - t0
    good = ("ok", "refused", "3d")
    findings = [o for o in outcomes if o.verdict not in good]
    by_command: dict[str, dict[str, int]] = {}
    for o in outcomes:
        counts = by_command.setdefault(o.command, {})
        counts[o.verdict if o.verdict in good else "finding"] = counts.get(o.verdict if o.verdict in good
                                                                           else "finding", 0) + 1
    print(f"{len(outcomes)} cases (seed {args.seed}) in {wall:.0f} s wall on {args.jobs} jobs; "
          f"slowest {max(o.seconds for o in outcomes):.1f} s; {len(findings)} findings")
    for command, counts in sorted(by_command.items()):
        print(f"  {command:<14} " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    for o in findings:
        print(f"FINDING #{o.case} {o.command} {o.mutation} {o.value!r}: {o.verdict} (exit {o.code}); "
              f"{' | '.join(o.stderr_tail)[:300]}")
    if args.json:
        args.json.write_text(json.dumps({"wall_s": wall, "outcomes": [asdict(o) for o in outcomes]}, indent=1))
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
