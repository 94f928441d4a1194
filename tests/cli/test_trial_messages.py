"""Small messages a new-user trial found wrong: an unreachable pose typed as 1e308 mm printed
a 300-digit distance; ``cellsim plan /tmp`` said "no such scenario file" of a folder;
``summary.json``'s ``record_hz`` read 999.9999999999991 for a 1 ms record."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sim.cli import main
from sim.core.text import mm_text
from sim.simulation.runfolder.writing import sample_rate


@given(x=st.floats(-1e305, 1e305))
def test_a_length_reads_short_whatever_its_size(x: float) -> None:
    text = mm_text(x)
    assert len(text) <= 16 and float(text) == pytest.approx(1e3 * x, rel=1e-3, abs=0.05)


@pytest.mark.parametrize("robot", ["lrmate200ic5l", "robot_5r", "lrmate100ib"])
def test_an_unreachable_typo_is_one_short_line(robot: str, capsys: pytest.CaptureFixture[str]
                                               ) -> None:
    assert main(["ik", robot, "1e308", "0", "300"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and len(err[0]) < 300 and "outside the arm's reach" in err[0], err


def test_a_folder_is_not_a_scenario_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                         ) -> None:
    assert main(["plan", str(tmp_path)]) == 2
    assert capsys.readouterr().err.strip() == \
        f"cellsim: error: {tmp_path}: a folder, not a scenario file"


@given(dt=st.sampled_from([1e-3, 2e-3, 5e-4, 1.0 / 60.0]), n=st.integers(3, 5000))
def test_a_records_rate_is_its_rate(dt: float, n: int) -> None:
    t = np.arange(n) * dt
    assert sample_rate(t) == float(f"{1.0 / dt:.9g}")
    assert sample_rate(np.arange(82593) * 1e-3) == 1000.0


def test_the_run_line_gives_the_steps_time_in_significant_digits(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A short run printed "0.624 s simulated in 0.00 s": the MuJoCo steps' time now has 3
    significant digits and says what it is (summary.json's wall_s)."""
    import json
    import re

    out = tmp_path / "run"
    main(["run", "kacso_lrmate100ib_sequence1", "--out", str(out), "--no-video", "--no-plots"])
    line = next(ln for ln in capsys.readouterr().out.splitlines() if "simulated in" in ln)
    got = re.search(r"simulated in (\S+) s of MuJoCo steps", line)
    assert got, line
    wall = json.loads((out / "summary.json").read_text())["wall_s"]
    assert float(got.group(1)) == float(f"{wall:.3g}") > 0.0
