"""A video's frame rate takes a range, 1-1000 fps (:data:`sim.core.tomlschema.FPS`), in
``[video] fps``, ``cellsim run --fps`` and ``cellsim render --fps``: ``render --fps 1e-9`` was
taken and failed inside ffmpeg ("Unable to parse framerate ... '0'", found by a new-user
trial). Specification, on generated rates: one outside the range is refused naming the key or
the flag and the range; the range's ends are taken."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sim.cli import main
from sim.errors import ScenarioError
from sim.scenario import parse_scenario

BASE = (Path(__file__).resolve().parents[2] / "scenarios" / "kacso_lrmate100ib_sequence1.toml"
        ).read_text()
_outside = st.one_of(st.floats(-1e308, 1.0, exclude_max=True),
                     st.floats(1000.0, 1e308, exclude_min=True))


def _with_fps(value: float) -> str:
    return BASE.replace("[expect]", f"[video]\nfps = {value!r}\n\n[expect]", 1)


@settings(max_examples=30, deadline=None)
@given(fps=_outside)
def test_a_scenarios_rate_outside_the_range_is_refused(fps: float) -> None:
    with pytest.raises(ScenarioError, match=r"video\.fps: must be between 1 and 1000 fps"):
        parse_scenario(_with_fps(fps), source="v.toml")


@pytest.mark.parametrize("fps", [1.0, 24.0, 1000.0])
def test_the_ranges_ends_are_taken(fps: float) -> None:
    assert parse_scenario(_with_fps(fps), source="v.toml").video.fps == fps


@pytest.mark.parametrize("command", ["run", "render"])
@pytest.mark.parametrize("fps", ["1e-9", "0", "-3", "1001", "nan", "inf"])
def test_a_flags_rate_outside_the_range_is_refused_before_anything_runs(
        command: str, fps: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = "kacso_lrmate100ib_sequence1" if command == "run" else str(tmp_path / "no_run")
    with pytest.raises(SystemExit) as exc:
        main([command, target, "--fps", fps, "--out", str(tmp_path / "o")])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "argument --fps:" in err and not (tmp_path / "o").exists()
