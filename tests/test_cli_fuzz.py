"""Bad input on every command and option: exit 2, one line, no traceback, nothing written.

Each case starts from a command line that would run (a "baseline") and spoils one option,
argument or config key. The FE solvers, the coupon and the evaluators are replaced by
tripwires, so a value that gets past the checks fails the test at once instead of
computing: every refusal must come before any solve.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from pneumorph.cli import main
from tests.benchmark import load

# -- the tripwires ------------------------------------------------------------------------


class _Reached(Exception):
    pass


def _trip(*args: object, **kwargs: object) -> None:
    raise _Reached("a solve was reached: the bad value was not refused up front")


@pytest.fixture()
def sandbox(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    import pneumorph.bimodal.model as bimodal
    import pneumorph.composite.coupon as coupon
    import pneumorph.execution as execution
    import pneumorph.execution.evaluators as evaluators
    import pneumorph.models.fe as fe

    monkeypatch.setattr(fe.FEModel, "solve", _trip)
    monkeypatch.setattr(fe.FEModel, "evaluate", _trip)
    monkeypatch.setattr(bimodal.BimodalModel, "solve", _trip)
    monkeypatch.setattr(coupon, "simulate_coupon", _trip)
    import uvicorn

    monkeypatch.setattr(uvicorn, "run", _trip)  # the bench's server never starts on a bad value
    monkeypatch.setattr(execution, "make_evaluator", lambda *a, **k: evaluators.SerialEvaluator())
    monkeypatch.setattr(evaluators, "make_evaluator", lambda *a, **k: evaluators.SerialEvaluator())
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.delenv("PNEUMORPH_CACHE", raising=False)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "binary.bin").write_bytes(bytes(range(256)) * 4)
    (tmp_path / "a-file").write_text("not a folder\n", encoding="utf-8")
    (tmp_path / "terms.json").write_text(  # a chain table of far-field terms (format 3) without its terms' keys
        '{"format": 3, "kind": "pneumorph chain table", "window": 3, "pressures_mpa": [0.045], "terms": {"window": 2}}',
        encoding="utf-8")
    (tmp_path / "folder").mkdir()
    os.mkfifo(tmp_path / "pipe")  # opened, it would block: refused by its kind before
    with (tmp_path / "huge.bin").open("wb") as fh:  # 1 GB that takes no disk (sparse)
        fh.truncate(2**30)
    (tmp_path / "latin1.toml").write_bytes("[unit]\nname = 'caf\u00e9'\n".encode("latin-1"))
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    (tmp_path / "many.csv").write_text("1 2\n" * 1_000_000, encoding="utf-8")  # 4 MB, a million points: 2.5 GB parsed
    for name, text in BASELINES.FILES.items():  # what the baselines name: unit.toml, run.toml, the data files
        (tmp_path / name).write_text(text, encoding="utf-8")
    (tmp_path / "trace.csv").write_text("x,y\n" + "".join(f"{i},{(i % 3)}\n" for i in range(160)),
                                         encoding="utf-8")
    return tmp_path


def _listing(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")} - {"xdg"}


def _refused(root: Path, capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    before = _listing(root)
    code = main(argv)
    out, err = capsys.readouterr()
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err + out, err
    assert code == 2, f"exit {code} for {argv}: {err or out}"
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    left = {p for p in _listing(root) - before if not p.startswith("xdg")}
    assert not left, f"{argv} left {sorted(left)}"
    return lines[0]


# -- the commands and their options -------------------------------------------------------

BASELINES = load("fuzz_baselines")
#: the command line each case starts from, by the command's path (benchmarks/fuzz_baselines.py)
BASE = BASELINES.BASE
spoil = BASELINES.spoil


REAL = ["nan", "inf", "-inf", "1e999", "abc", ""]  # never a number
POSITIVE = ["0", "-1", *REAL]
NONNEG = ["-1", *REAL]
COUNT = ["1.5", "true", "abc", "", "-1"]
POS_COUNT = ["0", *COUNT]
HUGE = ["100000", "1000000000"]

OPTIONS: dict[str, dict[str, list[str]]] = {
    "design": {
        "--pressure": [*POSITIVE, "1e9"], "--amplitude": POSITIVE, "--periods": POSITIVE, "--margin": POSITIVE,
        "--epsilon": [*NONNEG, "1e9"], "--refine": [*POSITIVE, "3", "4", "0.01", "1e9"],  # 3, 4: no finer than 3 mm
        "--units": POS_COUNT + HUGE, "--pop": ["1", *POS_COUNT, *HUGE], "--gen": [*COUNT, *HUGE],
        "--seed": COUNT, "--verify": POS_COUNT, "--workers": POS_COUNT, "--tolerance": [*NONNEG, "2"],
        "--max-open": [*POS_COUNT, "5000000", "1000000000", "1000000001"],  # past the memory budget, past the cap
        "--robust-samples": POS_COUNT + HUGE, "--target": ["", "   ", "y = 1/0",
        "y = x**", "y = nan", "r = 1/0", "y = exp(1000)", "y = __import__('os')", "path:", "path:missing.csv",
        "path:binary.bin", "path:folder", "path:a-file", "path:/dev/zero", "path:pipe", "path:huge.bin",
        "path:many.csv", "letter-q"],
        "--scheduler": ["not a url", ""],
        "--unit": ["binary.bin", "folder", "missing.toml", ""], "--cache": ["folder", "a-file/x.sqlite", ""],
        "--out": ["a-file", "a-file/sub", ""],
        "--chain-table": ["binary.bin", "folder", "missing.json", "", "terms.json"],
        "--library": ["binary.bin", "folder", "missing.toml", "", "a-file"],
        "--stage": ["", "abc", "18", "18:", "x:sin", "nan:sin", "18:reach", "18:reach 1", "18:max-x", "20:sin",
                    "18:r = 20 + theta", "18:y = 1/0"],
        "--model-file": ["binary.bin", "folder", "missing.toml", ""],
        "--clear": ["", "abc", "27:x", "nan", "27:inf", "27:1:2", "27:-1", "-5", "27", "0", "1e999", "27:1e999", "27:",
                    ":1", "1e9", "27:0"],
    },
    "simulate": {
        "--pressure": [*POSITIVE, "1e9"], "--increments": POS_COUNT + HUGE, "--orientation": ["", "0120", "abc"],
        "--volume-change": [*POSITIVE, "1e3", "1e-300", "25"],  # 25 V0 in the baseline's 3 increments: 8.3 a step
        "--unit": ["binary.bin", "folder", ""], "--out": ["a-file", "a-file/sub", ""],
        "--library": ["binary.bin", "folder", "missing.toml", "", "a-file"],
        "--model-file": ["binary.bin", "folder", "missing.toml", ""],
        "--obstacle": ["", "plane", "cube:centre=1,2", "plane:point=1,2", "plane:point=0,0;normal=0,0",
                       "cylinder:centre=60,20;radius=0", "sphere:centre=60,20;radius=-1",
                       "sphere:centre=nan,20;radius=2", "sphere:centre=60,20;radius=2;friction=-1",
                       "sphere:centre=60,20;radius=inf",
                       "plane:point=10,5;normal=0,1", "sphere:centre=10,6;radius=2", "plane:point=a,b;normal=1,0",
                       "sphere:centre=60,20;radius=2;on=side", "cylinder:centre=60,20;radius=2;axis=0,0,1",
                       "sphere:centre=60,20;radius=2;friction=nan", "sphere:centre=60,20;radius=2;kind=plane",
                       "cylinder:centre=60,20;radius=1e300", "plane:point=0,-30;normal=1e-320,1e-320",
                       "sphere:centre=60,20;radius=2;radius=3", "sphere:centre=60,20,5;radius=2",
                       ";", "sphere:", "sphere:centre=1e999,20;radius=2",
                       "sphere:centre=60,20;radius=2;friction=1e9", "plane:point=150,0;normal=-1,0;friction=10.5"],
    },
    "study": {
        "--populations": ["", "0", "1", "20,,40", "abc", "1.5", "-20"], "--seeds": POS_COUNT + HUGE,
        "--gen": COUNT + HUGE, "--units": POS_COUNT + HUGE, "--pressure": POSITIVE, "--target": ["", "y = 1/0"],
        "--cache": ["folder", ""], "--out": ["a-file", "a-file/sub", ""],
    },
    "calibrate": {
        "--units": POS_COUNT + HUGE, "--pressures": ["", "0", "-5", "nan", "5,,10", "abc", "inf"],
        "--runs": POS_COUNT + HUGE, "--seed": COUNT, "--validate": COUNT + HUGE, "--unit": ["binary.bin", ""],
        "--cache": ["folder", ""], "--out": ["a-file", "a-file/sub", ""],
    },
    "chain build": {
        "--pressure": POSITIVE, "--units": POS_COUNT + HUGE, "--window": [*POS_COUNT, "50"],
        "--tolerance": POSITIVE, "--heldout": COUNT + HUGE, "--workers": POS_COUNT, "--unit": ["binary.bin", ""],
        "--cache": ["folder", ""], "--out": ["folder", "a-file/t.json", ""],
        "--library": ["binary.bin", "folder", "missing.toml", "", "a-file"],
        "--quadrature": ["", "gauss", "27", "Full", "nan"],
    },
    "bimodal": {
        "--pmax": [*POSITIVE, "1e9"], "--step": [*POSITIVE, "100"], "--voids": POS_COUNT + HUGE + ["10000", "101"],
        "--element-size": [*POSITIVE, "1e-4", "0.3"], "--end-cap": [*NONNEG, "1e9", "10001"],
        "--bilinear-nu": ["0.5", "-1.5", *REAL],
        "--control": ["", "arc-length"], "--composite": ["", "rebar"],
        "--volume-change": [*POSITIVE, "1e3", "1e-300", "30"],  # 30 V0 in the default 12 steps: 2.5 a step
        "--paper": ["", "crimped", "Measured"], "--gravity": ["", "sideways", "horizontal", "Hanging"],
        "--max-cutbacks": COUNT + HUGE, "--max-iterations": POS_COUNT + HUGE, "--out": ["a-file", "a-file/sub", ""],
    },
    "composite coupon": {
        "--crimp-ratio": POSITIVE, "--amplitude": POSITIVE, "--length": POSITIVE, "--thickness": POSITIVE,
        "--per-flute": POS_COUNT + HUGE, "--rows": POS_COUNT + HUGE, "--levels": POS_COUNT + HUGE,
        "--strain-max": POSITIVE, "--bulk-modulus": POSITIVE, "--gauges": COUNT + HUGE, "--seed": COUNT,
        "--snapshot": NONNEG, "--out": ["a-file", "a-file/sub", ""],
    },
    "composite transition": {"--crimp-ratio": POSITIVE, "--amplitude": POSITIVE, "--length": POSITIVE},
    "materials fit": {
        "--min-stretch": POSITIVE, "--max-stretch": POSITIVE, "--starts": POS_COUNT + HUGE, "--seed": COUNT,
        "--delimiter": ["", "ab"], "--columns": ["", "stress", "stress,stress", "foo,bar"],
        "--stress-unit": ["", "furlongs"], "--plot": ["folder", "a-file/x.png", ""], "--model": ["", "nope"],
    },
    "materials characterise bilinear": {"--primary-limit": POSITIVE, "--secondary-points": ["0", "1", *COUNT, *HUGE]},
    "materials characterise poisson": {"--strain-range": ["nan", "abc", ""]},
    "materials show": {"--library": ["binary.bin", "folder", "missing.toml", ""]},
    "materials list": {"--library": ["binary.bin", "folder", ""]},
    "export": {"--stl": ["a-file", "a-file/sub", ""], "--inp": ["folder", "a-file/x.inp", "x.txt", ""],
               "--pressure": [*POSITIVE, "1e9"], "--clearance": ["-1", "10", *REAL], "--draft": ["-1", "45", *REAL],
               "--unit": ["binary.bin", "folder", ""], "--model-file": ["binary.bin", "folder", "missing.toml", ""],
               "--library": ["binary.bin", "folder", "missing.toml", "", "a-file"]},
    "serve": {"--host": ["", "   ", "nosuchhost.invalid"], "--port": [*POS_COUNT, "65536", "100000"],
              "--state": ["a-file", "a-file/sub", ""], "--cache": ["folder", "a-file/x.sqlite", ""],
              "--workers": POS_COUNT, "--allow-host": ["", "   ", "x" * 300],
              "--jobs-per-session": [*POS_COUNT, "101"], "--max-jobs": [*POS_COUNT, "1001"],
              "--job-days": [*POSITIVE, "4000"], "--state-quota": ["0", "0.5", *REAL, "1e9"],
              "--model-file": ["binary.bin", "folder", "missing.toml", ""]},
    **{f"sensitivity {study}": {"--design": ["", "0120", "abc"], "--units": POS_COUNT + HUGE,
                                "--pressure": [*POSITIVE, "1e9"],
               "--unit": ["binary.bin", "folder", ""], "--workers": POS_COUNT,
               "--cache": ["folder", "a-file/x.sqlite", ""],
               "--out": ["a-file", "a-file/sub", ""],
               "--model-file": ["binary.bin", "folder", "missing.toml", ""], **extra}
       for study, extra in (
           ("simplifications", {"--passage": [*POSITIVE, "5"], "--base-length": POSITIVE, "--change": [*REAL, "101"]}),
           ("tolerances", {"--tolerance": [*POSITIVE, "2"], "--samples": COUNT + HUGE, "--seed": COUNT}),
           ("bulk-modulus", {"--factor": POSITIVE}),
           ("calibration", {"--reach": ["0.5", "11", *REAL]}),
           ("temperature", {"--change": [*REAL, "-101"]}),
       )},
    "unit optimise": {"--var": ["", "height=1:2", "wall=2:1", "wall", "wall=a:b", "end_wall=2:6", "pitch=5:12"],
                 "--strain-limit": POSITIVE, "--pressure": [*POSITIVE, "1e9"], "--units": ["2", *POS_COUNT, *HUGE],
                 "--pop": ["3", *POS_COUNT, *HUGE], "--gen": POS_COUNT + HUGE, "--seed": COUNT,
                 "--resolution": ["-1", "11", *REAL], "--element-size": [*POSITIVE, "1e-4"],
                 "--unit": ["binary.bin", "folder", "missing.toml", ""], "--workers": POS_COUNT,
                 "--cache": ["folder", "a-file/x.sqlite", ""], "--out": ["a-file", "a-file/sub", ""]},
    "sensitivity mesh": {"--design": ["", "0120", "abc"], "--units": POS_COUNT + HUGE,
                         "--size": [*POSITIVE, "0.01", "1e9"],
             "--pressure": [*POSITIVE, "1e9"], "--unit": ["binary.bin", "folder", ""], "--model": ["", "4d"],
             "--target": ["", "y = 1/0", "max-q"], "--amplitude": REAL, "--order": [*POSITIVE, "13"],
             "--cache": ["folder", "a-file/x.sqlite", ""], "--out": ["a-file", "a-file/sub", ""],
             "--model-file": ["binary.bin", "folder", "missing.toml", ""]},
    "correlate": {"--design": ["", "0120", "abc"], "--pressure": [*POSITIVE, "1e9"], "--unit": ["binary.bin", ""],
                  "--scale": POSITIVE, "--scan-unit": ["cm", "furlongs", ""],
                  "--photo": ["folder", "missing.png", ""], "--out": ["a-file", "a-file/sub", ""],
                  "--model-file": ["binary.bin", "folder", "missing.toml", ""],
                  "--library": ["binary.bin", "folder", "missing.toml", "", "a-file"]},
    "identify": {"--design": ["", "0120", "abc"], "--pressure": [*POSITIVE, "1e9"],
                 "--manifest": ["binary.bin", "folder", "missing.toml", ""], "--unit": ["binary.bin", "folder", ""],
                 "--scale": POSITIVE, "--scan-unit": ["cm", "furlongs", ""], "--fit": ["", "abc", "wall,abc"],
                 "--tolerance": [*POSITIVE, "5"],
                 "--seed": COUNT, "--cache": ["folder", "a-file/x.sqlite", ""], "--out": ["a-file", "a-file/sub", ""]},
    "scan synth": {"--out": ["folder", "a-file/x.csv", "x.txt", "x.xyz", ""], "--pressure": [*POSITIVE, "1e9"],
              "--set": ["", "wall", "wall=abc", "walls=1", "wall=-1", "wall=nan", "wall=inf", "body_bulk_scale=10000",
                        "element_size=0.1", "=1"],
              "--points": ["9", *POS_COUNT, "1000000"], "--noise": ["-1", "11", *REAL], "--seed": COUNT,
              "--unit": ["binary.bin", "folder", ""], "--model-file": ["binary.bin", "folder", "missing.toml", ""]},
}

# the one execution option set of every command that solves many designs (pneumorph.cli.options.execution)
for _command in ("design", "study", "calibrate", "chain build", "unit optimise", "identify",
                 *(f"sensitivity {study}" for study in ("simplifications", "tolerances", "bulk-modulus", "calibration",
                                                        "temperature", "mesh"))):
    OPTIONS[_command]["--workers"] = [*OPTIONS[_command].get("--workers", POS_COUNT), "1024"]  # past the cores
    OPTIONS[_command].setdefault("--scheduler", ["not a url", ""])

# every option that reads a file: a device, a named pipe, a file of 1 GB, text in another encoding, JSON nested
# 100,000 deep (pneumorph.io.reading); each refused by its kind or size before it is read
HOSTILE_FILES = ["/dev/zero", "/dev/urandom", "pipe", "huge.bin", "latin1.toml", "deep.json"]
for _options in OPTIONS.values():
    for _option in ("--unit", "--library", "--chain-table", "--model-file", "--manifest", "--photo"):
        if _option in _options:
            _options[_option] = [*_options[_option], *HOSTILE_FILES]
OPTIONS["identify"]["--pressure"] += ["1e-300", "0.5"]  # below MIN_SCAN_PRESSURE_KPA: no deformation to fit
OPTIONS["sensitivity mesh"]["--size"] += ["1.0"]  # one size: no convergence to estimate

CASES = [(cmd, opt, bad) for cmd, options in OPTIONS.items() for opt, values in options.items() for bad in values]


@pytest.mark.parametrize(("cmd", "option", "bad"), CASES, ids=[f"{c}{o}={b!r}" for c, o, b in CASES])
def test_bad_option_value(sandbox: Path, capsys: pytest.CaptureFixture[str], cmd: str, option: str, bad: str) -> None:
    argv = spoil(BASE[cmd], option, bad)
    if option == "--strain-range":
        argv += ["10"]  # the range's second number
    line = _refused(sandbox, capsys, argv)
    assert option in line or "orientation" in line or "crimp" in line.lower(), line


@pytest.mark.parametrize("cmd", ["materials characterise poisson", "materials characterise thermal",
                                 "materials characterise bilinear", "materials fit"])
@pytest.mark.parametrize("data", ["binary.bin", "folder", "missing.csv", "", "deep.json", "pipe", "huge.bin",
                                  "/dev/zero", "latin1.toml", "many.csv"])
def test_bad_data_file(sandbox: Path, capsys: pytest.CaptureFixture[str], cmd: str, data: str) -> None:
    """deep.json is one line past the csv module's limit; many.csv a million rows (2 GB and a minute parsed)."""
    argv = [data if a.endswith(".csv") else a for a in BASE[cmd]]
    _refused(sandbox, capsys, argv)


# -- config files -------------------------------------------------------------------------

CONFIG_KEYS: list[tuple[str, str, str]] = [
    (table, key, value)
    for table, key, values in [
        ("design", "units", ['"four"', "true", "1.5", "0", "-1", "100000"]),
        ("design", "objective", ['""', "1", '"y = 1/0"', '"y = nan"', '"nope"']),
        ("design", "amplitude", ["nan", "inf", '"ten"', "true", "0"]),
        ("design", "periods", ["nan", "-1", '"x"']),
        ("design", "seed", ["1.5", "-1", '"0"', "true"]),
        ("design", "search", ["1", '"fast"']),
        ("design", "certify", ['"yes"', "1"]),
        ("design", "verify", ["0", "1.5", "true"]),
        ("design", "max_open", ["0", "1.5", "true", '"9"', "2000000000"]),
        ("ga", "elitism", ["-1", "100", "1.5"]),
        ("ga", "budget", ["1", "0", "1.5"]),
        ("design", "margin", ["0", "nan", '"1"']),
        ("design", "point", ["[1]", '"1,2"', "[nan, 0]"]),
        ("design", "path", ['"abc"', "[1, 2]", "[[0, 0]]", '[[0, "a"], [1, 2]]']),
        ("design", "anchored", ["1"]),
        ("design", "chain_table", ["1", '""']),
        ("design", "clear", ["1", '"x"', "{pressure_kpa = nan}", "{pressure_kpa = 27, clearance_mm = -1}", "{}",
                             "{clearance_mm = 1}", '{pressure_kpa = "27"}', "{pressure_kpa = true}",
                             "{pressure_kpa = 27, margin = 1}", "{pressure_kpa = inf}", "{pressure_kpa = 1e9}",
                             "{pressure_kpa = 0}", "[27, 1]", "{pressure_kpa = 27, clearance_mm = nan}",
                             '{pressure_kpa = 27, clearance_mm = "1"}', "{pressure_kpa = 27, clearance_mm = 1e999}"]),
        ("ga", "population", ["1", "1.5", "true", '"100"', "100000000"]),
        ("ga", "generations", ["1.5", "-1", "true", "100000000"]),
        ("ga", "cxpb", ["nan", "2", '"x"']),
        ("ga", "hall_of_fame", ["0", "1.5"]),
        ("execution", "executor", ["1", '"gpu"']),
        ("execution", "workers", ["0", "1.5", "true"]),
        ("execution", "scheduler", ["1", '"not a url"']),
        ("execution", "cache", ["1", '""']),
        ("model", "fidelity", ['"4d"', "2"]),
        ("model", "pressure_kpa", ["nan", "inf", "0", "-5", '"45"', "true", "1e9"]),
        ("model", "increments", ["0", "1.5", "true", "1000000000"]),
        ("model", "substeps", ["0", "1.5", "1000000"]),
        ("model", "gravity", ['"sideways"', "1"]),
        ("model", "unit_file", ['"binary.bin"', '"missing.toml"', "1"]),
        ("model", "quadrature", ['"gauss"', "27", "true", '""', '"Full"', "[1]"]),
        ("model", "volume_change", ["nan", "inf", "0", "-1", '"1"', "true", "1e3", "[1]", "1e-9", "25"]),
        ("model", "obstacle", ["1", '"sphere"', "[1]", "[{}]", '[{kind = "cube"}]', '[{kind = "sphere"}]',
                               '[{kind = "sphere", centre = [60, 20], radius = -1}]',
                               '[{kind = "sphere", centre = [60, 20], radius = 2, colour = "red"}]',
                               '[{kind = "sphere", centre = [60, "a"], radius = 2}]',
                               '[{kind = "sphere", centre = [60, 20], radius = nan}]',
                               '[{kind = "sphere", centre = [60, 20], radius = 2, friction = -1}]',
                               '[{kind = "sphere", centre = [60, 20], radius = 2, friction = 1e9}]',
                               '[{kind = "plane", point = [0, 0], normal = [0, 0]}]',
                               '{kind = "sphere", centre = [60, 20], radius = 2}']),
        ("model.unit", "pitch", ["nan", "0", '"ten"', "true"]),
        ("model.unit", "element_size", ["1e-4", "0", "nan"]),
    ]
    for value in values
]


@pytest.mark.parametrize(("table", "key", "value"), CONFIG_KEYS, ids=[f"[{t}]{k}={v}" for t, k, v in CONFIG_KEYS])
@pytest.mark.parametrize("cmd", ["design", "study"])
def test_bad_config_key(sandbox: Path, capsys: pytest.CaptureFixture[str], cmd: str, table: str, key: str,
                        value: str) -> None:
    if cmd == "study" and table == "execution":
        pytest.skip("the study takes its executor from its options")
    config = sandbox / "config.toml"
    config.write_text(f"[{table}]\n{key} = {value}\n", encoding="utf-8")
    line = _refused(sandbox, capsys, [cmd, str(config), "--out", "run"])
    assert key in line, line


@pytest.mark.parametrize("content", [bytes(range(256)), b"[design\nunits = 3", b"[unknown]\nx = 1\n", b"units = 3\n",
                                     b"design = 3\n", b"ga = [1]\n", b"[design]\nverify = 3\nsearch = 'ga'\n",
                                     b"[design]\nmargin = 2.0\nsearch = 'exhaustive'\nunits = 4\n"])
@pytest.mark.parametrize("cmd", ["design", "study"])
def test_bad_config_file(sandbox: Path, capsys: pytest.CaptureFixture[str], cmd: str, content: bytes) -> None:
    config = sandbox / "config.toml"
    config.write_bytes(content)
    _refused(sandbox, capsys, [cmd, str(config), "--out", "run"])


@pytest.mark.parametrize("content", [bytes(range(256)), b"[unit]\npitch = 'ten'\n", b"[unit]\nelement_size = 1e-4\n",
                                     b"[unit]\npitch = nan\n", b"pitch = 10\n"])
def test_bad_unit_file(sandbox: Path, capsys: pytest.CaptureFixture[str], content: bytes) -> None:
    unit = sandbox / "unit.toml"
    unit.write_bytes(content)
    for argv in (BASE["simulate"], BASE["design"], BASE["chain build"]):
        _refused(sandbox, capsys, spoil(argv, "--unit", str(unit)))


@pytest.mark.parametrize("friction", ["1e9", "10.5", "inf"])
def test_a_friction_past_its_bound_in_a_model_file_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str],
                                                              friction: str) -> None:
    """``[[model.obstacle]]`` of ``--model-file`` has the bound of ``--obstacle`` and the config (MAX_FRICTION)."""
    model = sandbox / "model.toml"
    model.write_text(f"[[model.obstacle]]\nkind = 'plane'\npoint = [150, 0]\nnormal = [-1, 0]\nfriction = {friction}\n",
                     encoding="utf-8")
    line = _refused(sandbox, capsys, [*BASE["simulate"], "--model-file", str(model)])
    assert "friction" in line and ("MAX_FRICTION" in line or friction == "inf"), line


@pytest.mark.parametrize(("argv", "names", "least"), [
    (["simulate", "-o", "0110", "--volume-change", "100", "--increments", "1", "--out", "run"],
     ("--volume-change 100 over --increments 1 is 100 V0 per step", "--increments"), 50),
    (["bimodal", "-c", "0.2", "--volume-change", "8", "--pmax", "10", "--step", "5", "--out", "run"],
     ("--volume-change 8 over --pmax/--step 2 is 4 V0 per step", "--step 2.5 kPa or smaller"), 4),
])
def test_a_volume_step_past_its_largest_is_refused_alike(sandbox: Path, capsys: pytest.CaptureFixture[str],
                                                         argv: list[str], names: tuple[str, str], least: int) -> None:
    """One rule for simulate and bimodal (MAX_VOLUME_STEP, 2 V0 a step from rest), said in each command's options
    with the fewest steps that keep to it, before any solve."""
    line = _refused(sandbox, capsys, argv)
    assert names[0] in line and "more than the 2 V0 a step can take from rest (MAX_VOLUME_STEP" in line
    assert names[1] in line and f"{least}" in line.split("from rest")[1]


def test_target_and_objective_together(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line = _refused(sandbox, capsys, [*BASE["design"], "--target", "sin", "--objective", "max-y"])
    assert "--target" in line and "--objective" in line


def test_reach_needs_a_point(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line = _refused(sandbox, capsys, [*BASE["design"], "--objective", "reach"])
    assert "--point" in line


def test_far_field_terms_on_too_short_a_training_model(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--window 1 --far-terms`` makes a table of +-2, whose training designs need 5 units: 4 are refused."""
    line = _refused(sandbox, capsys, [*spoil(BASE["chain build"], "--window", "1"), "--far-terms"])
    assert "far-field terms of window +-1" in line and "at least 5 units" in line


def test_split_terms_without_far_field_terms(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line = _refused(sandbox, capsys, [*BASE["chain build"], "--split-terms", "--no-far-terms"])
    assert "--split-terms" in line and "--no-far-terms" in line


def test_unknown_command_and_option(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _refused(sandbox, capsys, ["nope"])
    _refused(sandbox, capsys, ["design", "--nope"])
    _refused(sandbox, capsys, ["simulate"])  # a required option missing


def test_overflowing_stress_data_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rows = "".join(f"{1 + 0.1 * i},{1e300 * i}\n" for i in range(20))
    (sandbox / "huge.csv").write_text("stretch,stress\n" + rows, encoding="utf-8")
    line = _refused(sandbox, capsys, ["materials", "fit", "huge.csv", "-m", "neo-hooke"])
    assert "stress unit" in line


@pytest.mark.parametrize("extra", [["--verify", "2", "--search", "ga"], ["--margin", "2", "--search", "exhaustive"],
                                   ["--certify", "--search", "ga"], ["--max-open", "100", "--search", "ga"],
                                   ["--no-build", "--search", "exhaustive"]])
def test_options_of_another_search_are_refused_not_ignored(sandbox: Path, capsys: pytest.CaptureFixture[str],
                                                           extra: list[str]) -> None:
    search = extra.index("--search")
    argv = [*spoil(BASE["design"], "--search", extra[search + 1]), *extra[:search], *extra[search + 2:]]
    line = _refused(sandbox, capsys, argv)
    assert "only appl" in line and extra[0] in line


def test_exhaustive_search_beyond_its_limit_is_refused_before_anything_is_said(
        sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line = _refused(sandbox, capsys, spoil(spoil(BASE["design"], "--search", "exhaustive"), "--units", "30"))
    assert "at most 20 units" in line and "1,073,741,824" in line


def test_overwrite_without_a_folder_to_overwrite_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = [a for a in BASE["identify"] if a not in ("--out", "run")]
    line = _refused(sandbox, capsys, [*argv, "--overwrite"])
    assert "--overwrite" in line and "--out" in line


def test_snapshot_beyond_the_final_strain_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    line = _refused(sandbox, capsys, [*BASE["composite coupon"], "--snapshot", "5"])
    assert "--snapshot" in line and "final strain" in line


# -- every option of every command is covered ---------------------------------------------

def _commands() -> dict[str, object]:
    import click

    from pneumorph.cli import cli

    found: dict[str, object] = {}

    def walk(group: click.Group, path: tuple[str, ...]) -> None:
        ctx = click.Context(group)
        for name in group.list_commands(ctx):
            command = group.get_command(ctx, name)
            assert command is not None, name
            if isinstance(command, click.Group):
                walk(command, (*path, name))
            else:
                found[" ".join((*path, name))] = command

    walk(cli, ())
    return found


# options whose every value is valid or whose bad values are tried elsewhere in this file
COVERED_ELSEWHERE = {
    "--json", "--quiet", "--overwrite", "--certify", "--references-only", "--stable", "--markdown", "--help",
    "--objective",  # a choice; with --target: test_target_and_objective_together; reach: test_reach_needs_a_point
    "--point",  # test_reach_needs_a_point and the two-number type
    "--wavelength",  # test_impossible_crimp_is_a_one_line_error (tests/composite)
}


def test_every_command_has_a_baseline_and_every_option_is_fuzzed() -> None:
    import click

    for path, command in _commands().items():
        assert path in BASE, f"no baseline for pneumorph {path}"
        for param in command.params:  # type: ignore[attr-defined]
            if not isinstance(param, click.Option) or param.is_flag:
                continue
            name = max(param.opts, key=len)
            fuzzed = name in OPTIONS.get(path, {}) or isinstance(param.type, click.Choice) \
                or name in COVERED_ELSEWHERE
            assert fuzzed, f"pneumorph {path} {name} is not in the fuzz table"


CHOICES = [(path, max(p.opts, key=len)) for path, command in _commands().items()
           for p in command.params if isinstance(p, __import__("click").Option)  # type: ignore[attr-defined]
           and isinstance(p.type, __import__("click").Choice)]


@pytest.mark.parametrize(("path", "option"), CHOICES, ids=[f"{p} {o}" for p, o in CHOICES])
def test_a_value_outside_a_choice_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str], path: str,
                                             option: str) -> None:
    argv = list(BASE[path])
    if option in argv:
        argv[argv.index(option) + 1] = "nope"
    elif option == "--crimp-ratio":
        argv[argv.index("-c") + 1] = "nope"
    else:
        argv += [option, "nope"]
    line = _refused(sandbox, capsys, argv)
    assert "nope" in line and option in line


@pytest.mark.parametrize(("content", "name", "extra"), [
    (b"", "scan.stl", []), (b"solid x\nnot a facet\n" * 3, "scan.stl", []), (bytes(range(256)), "scan.csv", []),
    (b"x,y\n1,2\n", "scan.csv", []), (b"u,v\n" + b"1,2\n" * 20, "scan.csv", []), (b"1 2 3\n", "scan.dat", []),
    (None, "trace.csv", ["--scan-unit", "m"]),  # a trace in mm read as metres: 1000 times too large
    (None, "folder", []), (None, "pipe", []), (None, "huge.bin", []), (None, "/dev/urandom", []),
    (None, "/dev/null", []),  # refused by their kind or size, not as "no such file"
    ("x,y\n" + "".join(f"{0.1 * i},{0.05 * i}\n" for i in range(500)), "line.csv", []),  # on a line: 60 s of FE
    ("x,y\n" + "1" * 200_000 + ",2\n", "long.csv", []),  # a field past the csv module's limit: csv.Error
    ("ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty float y\nproperty float z\n"
     "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
     + "".join(f"{i} {i * i % 7} {i % 3}\n" for i in range(12)) + "3 0 1 99\n", "faces.ply", []),
])
def test_bad_scans_are_refused_before_the_model_is_solved(sandbox: Path, capsys: pytest.CaptureFixture[str],
                                                         content: bytes | str | None, name: str,
                                                         extra: list[str]) -> None:
    if content is not None:
        (sandbox / name).write_bytes(content.encode() if isinstance(content, str) else content)
    argv = ["correlate", name, "--design", "0110", "--model", "2d", *extra]
    if not extra:
        argv += ["--scale", "0.2"]
    line = _refused(sandbox, capsys, argv)
    assert name in line


@pytest.mark.parametrize("design", ["", "012", "abc", "0" * 101])
def test_a_bad_design_to_export_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str], design: str) -> None:
    _refused(sandbox, capsys, ["export", design, "--stl", "run"])


@pytest.mark.parametrize("argv", [["export", "0110"], ["export", "0110", "--stl", "run", "--draft", "1"],
                                  ["export", "0110", "--inp", "d.inp", "--mould"],
                                  ["export", "0110", "--stl", "run", "--pressure", "30"]])
def test_export_options_that_do_not_apply_are_refused(sandbox: Path, capsys: pytest.CaptureFixture[str],
                                                      argv: list[str]) -> None:
    _refused(sandbox, capsys, argv)


def test_a_port_in_use_is_refused_before_the_bench_starts(sandbox: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        line = _refused(sandbox, capsys, ["serve", "--port", str(port), "--state", "run"])
    assert f"127.0.0.1:{port} is in use" in line


@pytest.mark.parametrize("cmd", sorted(BASE))
def test_an_option_given_twice_is_refused(sandbox: Path, capsys: pytest.CaptureFixture[str], cmd: str) -> None:
    """click keeps the last value of a repeated option and never checks the first: refused instead."""
    argv = list(BASE[cmd])
    repeatable = ("--mould", "--json", *BASELINES.REPEATABLE.get(cmd, ()))
    option = next((a for a in argv if a.startswith("--") and a not in repeatable), None)
    if option is None:
        pytest.skip("no option with a value in the baseline")
    value = argv[argv.index(option) + 1]
    line = _refused(sandbox, capsys, [*argv, option, value])
    assert f"{option} is given 2 times" in line, line
