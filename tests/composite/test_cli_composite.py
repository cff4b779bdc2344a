"""``pneumorph composite transition|coupon``: output, files and exit codes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from pneumorph.composite.coupon import CouponResult, CouponSpec, simulate_coupon
from tests.cli import run


def test_transition_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "composite", "transition", "--crimp-ratio", "0.3", "--amplitude", "1.5",
                       "--length", "176.25")
    assert code == 0
    assert "53.99 %" in out and "34.7500" in out and "56.20 %" in out


def test_transition_json_with_wavelength(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "composite", "transition", "--wavelength", "6", "--json")
    data = json.loads(out)
    assert code == 0
    assert data["crimp_ratio"] == 0.25
    assert data["transition_strain"] == pytest.approx(0.3901, abs=1e-4)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--crimp-ratio", "0"], "--crimp-ratio must be a finite number > 0"),
        (["--crimp-ratio", "0.3", "--amplitude", "-1"], "amplitude"),
        (["--crimp-ratio", "0.2", "--length", "5"], "longer than the coupon"),
        (["--crimp-ratio", "0.2", "--wavelength", "7.5"], "exactly one"),
        ([], "exactly one"),
    ],
)
def test_impossible_crimp_is_a_one_line_error(capsys: pytest.CaptureFixture[str], argv: list[str],
                                               message: str) -> None:
    code, out, err = run(capsys, "composite", "transition", *argv)
    assert code == 2 and out == ""
    assert err.startswith("error: ") and message in err and err.count("\n") == 1


def test_coupon_json_and_files(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, out, _ = run(capsys, "composite", "coupon", "--crimp-ratio", "0.3", "--length", "20", "--per-flute", "1",
                       "--rows", "1", "--levels", "24", "--strain-max", "0.9", "--gauges", "20", "--seed", "3",
                       "--out", str(tmp_path), "--json")
    assert code == 0
    data = json.loads(out)
    assert data["transition_engineering"] == pytest.approx(data["analytical_limit_transition"], abs=0.01)
    assert data["gauges"]["count"] == 20 and data["gauges"]["seed"] == 3
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["coupon-cr0_3-deformed.png", "coupon-cr0_3-load.png", "coupon-cr0_3-surface-strain.png",
                     "coupon-cr0_3.csv", "coupon-cr0_3.json"]
    rows = (tmp_path / "coupon-cr0_3.csv").read_text().splitlines()
    assert rows[0] == "engineering_strain,surface_strain,force_N_per_mm" and len(rows) == 26


def test_coupon_text(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "composite", "coupon", "-c", "0.25", "--length", "24", "--per-flute", "1",
                       "--rows", "1", "--levels", "24", "--strain-max", "0.7", "--gauges", "0")
    assert code == 0
    assert "transition, engineering strain" in out and "virtual strain gauges" not in out


def test_coupon_rejects_a_crimp_too_high_for_the_coupon(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "composite", "coupon", "-c", "0.3", "--thickness", "2.5")
    assert code == 2 and "thickness" in err


@pytest.fixture(scope="module")
def tiny_coupon() -> CouponResult:
    """A real coupon small enough to stand in for the solve (27 nodes, about a second)."""
    return simulate_coupon(CouponSpec.from_ratio(0.3, length=20.0, per_flute=1, rows=1), strain_max=0.9, levels=24)


@pytest.fixture()
def stubbed_solve(monkeypatch: pytest.MonkeyPatch, tiny_coupon: CouponResult) -> None:
    """The coupon's solve replaced by a stub that reports each level 3 s after the last (on the reporter's clock)
    and returns ``tiny_coupon``; a quiet machine (no load), so that the plan's estimate is the model's own."""
    import click

    import pneumorph.cli.progress as progress
    import pneumorph.composite.coupon as coupon
    from pneumorph.io.progress import Progress

    now = [0.0]

    def solve(spec: CouponSpec, strain_max: float | None = None, levels: int = 100, snapshots: tuple = (),
              on_level: Any = None) -> CouponResult:
        for k in range(levels):
            now[0] += 3.0
            on_level(k, 0.5 * (k + 1) / levels, 10.0 * k)
        return tiny_coupon

    monkeypatch.setattr(coupon, "simulate_coupon", solve)
    def reporter(quiet: bool = False) -> Progress:  # the command's reporter on the stub's clock; -q: silent
        return Progress((lambda line: None) if quiet else (lambda line: click.echo(line, err=True)), heartbeat=0,
                        clock=lambda: now[0])

    monkeypatch.setattr(progress, "reporter", reporter)
    monkeypatch.setattr("pneumorph.io.progress.os.getloadavg", lambda: (0.0, 0.0, 0.0))


@pytest.mark.usefixtures("stubbed_solve")
def test_coupon_says_its_plan_then_counts_its_levels(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """The default coupon of CR 0.25 (2,133 nodes, pulled to 2 s / lambda - 1 + 10 % = 51.4 %) is planned at
    LEVEL_SECONDS x 2,133 = 0.16 s a level, 16 s for its 100 levels (measured: 15.5 s of CPU); then every level
    is counted against the 100, and the files are announced."""
    from pneumorph.composite.coupon import LEVEL_SECONDS

    assert len(CouponSpec.from_ratio(0.25).mesh().points) == 2133
    assert 100 * LEVEL_SECONDS * 2133 == pytest.approx(16.0, abs=0.01)
    code, out, err = run(capsys, "composite", "coupon", "-c", "0.25", "--gauges", "0", "--out", str(tmp_path / "c"))
    assert code == 0 and "transition, engineering strain" in out
    lines = err.splitlines()
    assert lines[0] == (f"coupon of CR 0.25 (2,133 nodes) pulled to 51.4 % strain: 100 levels, estimated 16 s "
                        f"(0.2 s each, 1 worker) -> {tmp_path / 'c'}")
    assert lines[1] == "  coupon: 1/100 after 3.0 s, 3.0 s each, about 5 min left; 0.5 % strain, 0 N/mm"
    assert [line.split()[1] for line in lines[1:101]] == [f"{k}/100" for k in range(1, 101)]
    assert lines[100] == "  coupon: 100/100 after 5 min, 3.0 s each; 50.0 % strain, 990 N/mm"
    assert lines[101].startswith("writing the coupon's CSV, JSON and figures") and len(lines) == 102


@pytest.mark.usefixtures("stubbed_solve")
@pytest.mark.parametrize("more", [[], ["--json"]])
def test_a_quiet_coupon_says_nothing_on_stderr(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                               more: list[str]) -> None:
    code, out, err = run(capsys, "composite", "coupon", "-c", "0.3", "--levels", "24", "--gauges", "0", "-q",
                         "--out", str(tmp_path), *more)
    assert code == 0 and err == ""
    assert ("transition_engineering" if more else "transition, engineering strain") in out
    assert len(list(tmp_path.iterdir())) == 5


def test_a_coupon_run_meshes_its_coupon_once(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch,
                                             tmp_path: Path) -> None:
    """The plan's title (its nodes), its estimate (LEVEL_SECONDS per node) and the solve share one mesh: the
    builder runs once in a coupon run (the ramp replaced by a uniform stretch to the pulled end at each level)."""
    import pneumorph.composite.coupon as coupon
    from pneumorph.fem.stepping import RampStatistics

    builds = []

    def counted(*args: Any) -> Any:
        builds.append(args)
        return build(*args)

    def pulled_only(items: Any, fields: Any, apply: Any, dof1: Any, dof0: Any, settings: Any, on_level: Any,
                    **kwargs: Any) -> RampStatistics:
        u, x = fields[0].values, fields[0].region.mesh.points[:, 0]
        for k in range(settings.increments):
            apply((k + 1) / settings.increments)
            u[:, 0] = u[:, 0].max() * x / x.max()  # a uniform stretch up to the pulled end
            on_level(k, (k + 1) / settings.increments)
        return RampStatistics()

    build = coupon.coupon_mesh
    monkeypatch.setattr(coupon, "coupon_mesh", counted)
    monkeypatch.setattr(coupon, "ramp", pulled_only)
    # a thickness no other test meshes, so that no mesh of these parameters was built before
    code, _, err = run(capsys, "composite", "coupon", "-c", "0.3", "--length", "20", "--thickness", "4.75",
                       "--per-flute", "1", "--rows", "1", "--levels", "20", "--gauges", "0", "-q")
    assert code == 0, err
    assert len(builds) == 1, builds
