"""Outputs a person wants to look at (issue 17): progress per stage, the report's order, charts
scaled to their data.

* ``cellsim run`` without a terminal prints one line per stage to standard error and closes
  with the total wall time and each stage's; ``summary.json`` keeps them (``timings_s``).
* ``report.html`` opens with a summary table (verdict, per joint the hardest check and its
  margin), rounds numbers to what they mean, folds the checks per joint, and fits a phone.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from sim.cli import main
from sim.pipeline.stages import STAGES


def test_run_reports_every_stage_and_its_wall_time(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "bugnar_5r_phase1", "--out", str(out), "--no-video"]) == 0
    cap = capsys.readouterr()
    lines = [line for line in cap.err.splitlines() if line.startswith("cellsim: ")]
    names = [line.split()[1] for line in lines]
    assert names == [s for s in STAGES if s != "video"], cap.err
    assert all(re.fullmatch(r"cellsim: \w+ \d+\.\d\d s", line) for line in lines)
    summary = json.loads((out / "summary.json").read_text())
    assert list(summary["timings_s"]) == names
    assert summary["total_wall_s"] >= sum(summary["timings_s"].values()) - 1e-6
    closing = [line for line in cap.out.splitlines() if line.strip().startswith("wall ")]
    assert closing and all(f"{n} " in closing[0] for n in names), cap.out


def test_quiet_run_prints_no_stage_lines(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "bugnar_5r_phase1", "--out", str(out), "--no-video", "--no-plots",
                 "--quiet"]) == 0
    assert "cellsim: simulate" not in capsys.readouterr().err


def test_report_opens_with_the_summary_and_folds_the_checks(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", "lrmate200ic_pick_place", "--out", str(out), "--no-video",
                 "--no-plots", "--quiet"]) == 0
    text = (out / "report.html").read_text()
    assert 'name="viewport"' in text
    headings = re.findall(r"<h2>([^<]+)</h2>", text)
    assert headings[0] == "Summary", headings
    first = text.split("<h2>Summary</h2>", 1)[1].split("<h2>", 1)[0]
    for j in ("j1", "j2", "j3", "j4", "j5", "j6"):
        assert f"<td>{j}</td>" in first
    assert "hardest check" in first and "margin %" in first
    assert text.count("<details") >= 6  # the checks folded per joint
    # no raw floats: every number in a table cell has at most 4 significant digits
    cells = re.findall(r"<td>(-?\d+\.\d+)</td>", text)
    assert cells and all(len(c.replace("-", "").replace(".", "").lstrip("0")) <= 4
                         for c in cells), [c for c in cells if len(c) > 8][:5]


SHIPPED = sorted(__import__("sim.core.resources", fromlist=["x"]).shipped_scenarios())


#: The fast share's ten minutes (issue 29): the frames of the scenarios with mechanisms, a
#: second robot or a ceiling mount (the costliest framings, 15-30 s of CPU each) are checked in
#: the slow share; the fast share keeps the default weld cycle, pick and place and seed 000's
#: sequence.
FRAMES_SLOW = {"two_robot_tee_weld", "positioner_cylinder_downhand", "track_beam_weld",
               "bugnar_5r_weld_cycle_ceiling", "lrmate200ic_tp_weld_plate",
               "lrmate200ic_weld_plate"}


@pytest.mark.render
@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow)
                                  if n in FRAMES_SLOW else n for n in SHIPPED])
def test_overview_frames_show_the_whole_robot(name, scenario_run):
    """The first and middle frames of the overview: no pixel of the robot (or its tool) on
    the image border, and the robot is in the picture."""
    from sim.render.frames import FrameRenderer

    run_dir, _ = scenario_run(name)
    with FrameRenderer(run_dir, cameras=("overview",), width=320, height=240,
                       overlay=False, caption=False) as fr:
        model = fr.model
        robot = np.array([model.body(int(b)).name.startswith("robot/")
                          for b in model.geom_bodyid])
        for time in (fr.record.t0, fr.record.t0 + 0.5 * fr.record.duration):
            seg = fr.segment(time)
            mask = np.zeros(seg.shape, bool)
            hit = seg >= 0
            mask[hit] = robot[seg[hit]]
            assert mask.sum() > 200, (name, time)  # the robot is in the picture
            border = np.concatenate([mask[0], mask[-1], mask[:, 0], mask[:, -1]])
            assert not border.any(), (name, time, int(border.sum()))


@pytest.mark.render
@pytest.mark.parametrize("name", ["bugnar_5r_weld_cycle", "lrmate200ic_weld_plate"])
def test_tool_camera_follows_the_torch(name, scenario_run):
    """The tool camera keeps the torch's tip in the middle of its image all along the cycle."""
    from sim.render.frames import FrameRenderer

    run_dir, _ = scenario_run(name)
    with FrameRenderer(run_dir, cameras=("tool",), width=320, height=240, overlay=False,
                       caption=False) as fr:
        model = fr.model
        tool = np.array([model.body(int(b)).name.startswith("robot/tool/")
                         for b in model.geom_bodyid])
        for frac in (0.0, 0.3, 0.6, 0.9):
            seg = fr.segment(fr.record.t0 + frac * fr.record.duration)
            centre = seg[100:140, 140:180]
            hit = centre >= 0
            assert hit.any() and tool[centre[hit]].any(), (name, frac)
