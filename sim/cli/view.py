"""``cellsim view RUN_DIR``: write the run's 3D replay into its ``report.html`` (and open it).

Reads ``RUN_DIR/model.xml``, ``trajectory.npz`` and ``summary.json``, builds the replay
(:mod:`sim.analysis.replay`: body poses by ``mj_kinematics``, no OpenGL needed) and puts it
into ``RUN_DIR/report.html`` in place of its replay section (a page of its own when the run has
no report). ``--open`` opens it in the browser when there is a display; otherwise (a headless
server) the path is printed, to copy the one offline file to a machine that has a browser.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from sim.simulation.runfolder import REPORT_HTML


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "view",
        help="write (or refresh) the 3D replay in RUN_DIR/report.html and optionally open it",
        description="Write the run's 3D replay (cell, robots, tools and parts moving with the "
                    "recorded poses; tool path and bead; collisions and clearance points; "
                    "torque, speed and tracking-error charts linked to the time slider) into "
                    "RUN_DIR/report.html: one self-contained file that opens offline.",
    )
    p.add_argument("run_dir", metavar="RUN_DIR", help="folder written by `cellsim run`")
    p.add_argument("--open", action="store_true", dest="open_it",
                   help="open the report in a web browser (when a display exists)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sim.analysis.replay import replay_of_folder
    from sim.analysis.replay.page import with_replay
    from sim.core.files import write_atomic

    folder = Path(args.run_dir)
    section = replay_of_folder(folder)  # one-line error (exit 2) for a missing/invalid folder
    path = folder / REPORT_HTML
    old = path.read_text("utf-8") if path.is_file() else None
    write_atomic(path, with_replay(old, section, f"cellsim replay: {folder.name}"))
    size_mb = path.stat().st_size / 1e6
    if args.open_it and (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
                         or sys.platform in ("darwin", "win32")):
        import webbrowser

        if webbrowser.open(path.resolve().as_uri()):
            print(f"opened {path} ({size_mb:.1f} MB)")
            return 0
    print(f"{path} ({size_mb:.1f} MB): open it in a web browser (works offline)")
    return 0
