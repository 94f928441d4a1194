"""The run as a 3D replay in the browser, linked to its charts (a section of ``report.html``).

The cell's geoms and meshes, the robots, tools and held parts move with the recorded ``qpos``
(body poses from ``mj_kinematics`` at the display rate; no OpenGL needed), the tool path is
drawn with the arc-on part as a bead, collision intervals and the closest clearance points
are highlighted at their times, and the charts of joint torque, speed and tracking error
(uPlot) follow the time slider; a click on a chart moves the replay there. One file, offline:
three.js and uPlot are shipped in ``vendor/`` (MIT, licences alongside) and inlined.

* :mod:`~sim.analysis.replay.scene`: geoms, meshes, cameras, body poses, clearance points;
* :mod:`~sim.analysis.replay.series`: chart and path decimation;
* :mod:`~sim.analysis.replay.payload`: the page's JSON data;
* :mod:`~sim.analysis.replay.page`: the HTML section (``app.js`` is the page's own script).

Test hooks on the page: ``window.cellsimReplay`` (``time()``, ``setTime(t)``,
``frameTimes()``, ``camera()`` (projection and view matrices, canvas size), ``solo(bodies)``,
``setView(name)``, ``chart(id)`` (its plotting area and x range)).

May import: :mod:`sim.simulation.runfolder` and mujoco.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sim.analysis.replay.page import replay_section
from sim.analysis.replay.payload import build_payload


def replay_html(model_xml: str | Path, arrays: Mapping[str, Any],
                summary: Mapping[str, Any]) -> str:
    """The replay section of ``report.html`` for a run: its ``model.xml`` and recorded arrays
    (``t``, ``qpos``; charts and paths from what else is there) and its summary."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(model_xml))
    joints = summary.get("joints")
    names = [str(j) for j in joints] if isinstance(joints, list) else []
    return replay_section(build_payload(model, arrays, summary, names))


def replay_of_folder(run_dir: str | Path) -> str:
    """The replay section for a finished run folder (read with ``load_run``)."""
    from sim.errors import RunFolderError
    from sim.simulation.runfolder import load_run

    record = load_run(run_dir)
    assert record.model_path is not None
    summary = dict(record.summary)
    summary.setdefault("joints", list(record.joints))
    try:
        return replay_html(record.model_path, record.arrays, summary)
    except ValueError as exc:  # the recorded poses do not fit the model
        raise RunFolderError(f"{record.where}: trajectory.npz: {exc}") from exc


__all__ = ["build_payload", "replay_html", "replay_of_folder", "replay_section"]
