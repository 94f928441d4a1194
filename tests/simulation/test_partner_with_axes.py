"""A cell's second robot beside a positioner or on a track's cell: a new user's first such cell
(a D500 turning a pipe, a second LR Mate beside it, idle) crashed as soon as the positioner
moved (exit 3: the first robot's plan took the second robot's joints for its own).

Specification, on generated coordinated welds (a positioner's, :mod:`support.axes_welds`;
a track's, :mod:`support.axes_tracks`) with a second LR Mate added to the cell file, idle or
making a joint move of its own:

* the first robot's plan (its joints and the cell's axes, sampled over its cycle) is the same,
  bit for bit, as the same cell's without the second robot (the second robot's presence
  changes nothing of it);
* the second robot's lane holds its home all cycle, or ends at its own move's target;
* ``cellsim check`` of the cell with the second robot answers (exit 0 or 1, never a traceback).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.axes_cells import HOME_DEG
from support.axes_tracks import TrackCase, track_cases
from support.axes_welds import WeldCase, weld_cases

from sim.cli import main
from sim.scenario import load_scenario
from sim.simulation.compile import build
from sim.simulation.motion import build_motion

R2_TARGET_DEG = (25.0, 10.0, -15.0, 0.0, -80.0, 30.0)


def _with_partner(case: WeldCase | TrackCase, folder: Path, moves: bool,
                  fault: bool = False) -> tuple[Path, Path]:
    """The case's scenario alone and with a second robot ``r2`` in its cell (900 mm to the
    side of the work, facing it), idle or with a 2 s joint move from its home. ``fault``: a
    planted fault, the first robot's weld 1 % faster in the cell with the second robot."""
    alone = case.write(folder / "alone")
    both = (dataclasses.replace(case, speed=case.speed * 1.01) if fault else case).write(
        folder / "both")
    y = -900.0 if isinstance(case, TrackCase) else 900.0
    cell = both.parent / "cell.toml"
    cell.write_text(cell.read_text() + (
        "\n[[robots]]\nname = \"r2\"\nmodel = \"lrmate200ic5l\"\n"
        f"base_pos_mm = [600.0, {y}, 0.0]\nbase_euler_zyx_deg = [{-90 if y > 0 else 90}, 0, 0]\n"))
    if moves:
        both.write_text(both.read_text() + (
            "\n[[robots.r2.phases]]\nname = \"r2_move\"\nplanner = \"434\"\n"
            "time_s = [0.0, 2.0]\n"
            f"joints_deg = [{list(HOME_DEG)}, {list(R2_TARGET_DEG)}]\n"))
    return alone, both


def _plan(path: Path):
    sc = load_scenario(path)
    return build_motion(sc, build(sc).context)


def _judge(case: WeldCase | TrackCase, folder: Path, moves: bool, fault: bool = False) -> None:
    alone_path, both_path = _with_partner(case, folder, moves, fault)
    alone, both = _plan(alone_path), _plan(both_path)
    assert both.n_lead == alone.n_joints and len(both.lanes) == 1
    assert both.lanes[0][0] == "r2"
    t = np.linspace(alone.t0, alone.phases[-1].t1, 400)
    q_alone, q_both = alone.at(t).q, both.at(t).q
    assert np.array_equal(q_both[:, :alone.n_joints], q_alone), str(case)
    r2 = q_both[:, alone.n_joints:]
    assert r2.shape[1] == 6
    if moves:
        end = both.lanes[0][1].at(np.array([both.lanes[0][1].t1])).q[0]
        assert np.allclose(np.degrees(end), R2_TARGET_DEG, atol=1e-9), str(case)
    else:
        assert np.all(r2 == r2[0]), str(case)
        assert np.allclose(np.degrees(r2[0]), HOME_DEG, atol=1e-9)
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(["check", str(both_path)])
    assert code in (0, 1), err.getvalue()
    assert "Traceback" not in err.getvalue()


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow],
          derandomize=True)
@given(case=weld_cases(), moves=st.booleans())
def test_a_second_robot_beside_a_positioner_leaves_the_first_robots_plan_as_it_was(case, moves):
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        _judge(case, Path(tmp), moves)


@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.too_slow],
          derandomize=True)
@given(case=track_cases(), moves=st.booleans())
def test_a_second_robot_in_a_track_cell_leaves_the_first_robots_plan_as_it_was(case, moves):
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        _judge(case, Path(tmp), moves)


def test_planted_fault_a_weld_1_percent_faster_beside_the_second_robot_is_caught(tmp_path):
    case = WeldCase(pos=(600.0, 0.0), yaw=0.0, kind="line", size=(120.0, 60.0),
                    offset=(0.0, 0.0), start_deg=0.0, sweep=80.0, work=45.0, travel=0.0,
                    speed=12.0)
    _judge(case, tmp_path / "ok", moves=False)
    with pytest.raises(AssertionError):
        _judge(case, tmp_path / "fault", moves=False, fault=True)


@pytest.mark.slow
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(case=weld_cases(), moves=st.booleans())
def test_more_positioner_cells_with_a_second_robot(case, moves):
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        _judge(case, Path(tmp), moves)
