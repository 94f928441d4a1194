"""``cellsim workspace ROBOT [--out FILE.png]``: workspace section picture and reach.

Draws seed 004's (theta2, theta3) map with the singular curves of eq. (24)-(25) and the x-z
section of the reachable wrist centre (5-axis robots: the equivalent map and the x-z section of
wrist point and tcp), and prints the reach as defined in :mod:`sim.robots.kinematics.workspace`:
the largest distance from the J1 axis of the wrist centre, and of the tcp, within the ranges.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from sim.errors import CellsimError
from sim.robots.kinematics.model import kinematic_model
from sim.robots.kinematics.workspace import plot_workspace, written_by_workspace
from sim.robots.registry import get_robot


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "workspace", help="draw the workspace section and print the reach",
        description="Write a PNG of the robot's reachable section (joint-space map with the "
                    "singular curves, x-z section) and print its reach: the largest distance "
                    "from the J1 axis of the wrist centre and of the tcp within the joint ranges.")
    p.add_argument("robot", metavar="ROBOT", help="robot name (see `cellsim list`): one of the "
                   "seeds' families (lrmate100ib, lrmate200ic5l, robot_5r), whose singular "
                   "curves the map draws; another robot is refused in one line")
    p.add_argument("--out", metavar="FILE.png", default=None,
                   help="PNG to write (default: workspace_<robot>.png in the current folder); an "
                        "existing file is replaced only if cellsim workspace wrote it there")
    p.set_defaults(func=run)


def _deg(q: np.ndarray) -> str:
    return np.array2string(np.rad2deg(q), precision=1, suppress_small=True)


def run(args: argparse.Namespace) -> int:
    spec = get_robot(args.robot)
    out = Path(args.out or f"workspace_{spec.name}.png")
    if out.suffix.lower() != ".png":
        raise CellsimError(f"--out must name a .png file, got {str(out)!r}")
    if not out.parent.is_dir():
        raise CellsimError(f"--out: folder {str(out.parent)!r} does not exist")
    if out.is_dir() or out.is_symlink():
        raise CellsimError(f"--out: {str(out)!r} is a folder or a symbolic link; name a new "
                           ".png file")
    if out.exists() and not written_by_workspace(out):
        raise CellsimError(f"--out: {str(out)!r} exists and cellsim workspace did not write it; "
                           "name a new .png file (or remove it)")
    model = kinematic_model(spec)
    reach = plot_workspace(model, out, title=f"{spec.title} ({spec.name}) workspace")
    ranges = "joint ranges from the model" if model.lower is not None else \
        "no joint ranges known: +-180 deg assumed"
    print(f"{spec.title} ({spec.name}), {ranges}")
    print(f"  reach of the wrist centre (max distance from the J1 axis): {1e3 * reach.wrist:.1f} mm"
          f" at q = {_deg(reach.q_wrist)} deg")
    print(f"  reach of the tcp (max distance from the J1 axis):          {1e3 * reach.tcp:.1f} mm"
          f" at q = {_deg(reach.q_tcp)} deg")
    print(f"  wrote {out}")
    return 0
