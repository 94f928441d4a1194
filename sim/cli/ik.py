"""``cellsim ik ROBOT X Y Z [--euler-zyx-deg A B G] [--tool NAME] [--all] [--json]``: analytic inverse
kinematics.

Position in mm in the robot's ``frame0``; orientation of its ``tcp`` frame as Z-Y-X Euler
angles in degrees, ``R = Rz(A) Ry(B) Rx(G)`` (seed 000 eq. 6); default: the tcp orientation in
the zero pose (q = 0). Solutions are printed best first (inside the joint ranges,
then closest to the zero pose; see :mod:`sim.robots.kinematics.ik`), in degrees, only the best unless
``--all``. For the 5-axis robots A is implied by the position: a disagreeing A is replaced
(one note on stderr). A pose with no solution is one line on stderr and exit code 2, for every
kind of robot (shipped, a robot folder, an arm as data with a closed form or the numeric
solver). ``--json`` prints::

    {"robot": str, "tool": str or null,
     "solutions": [{"joints_deg": [..], "within_limits": bool}]}
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from typing import NoReturn

import numpy as np

from sim.core.rotations import euler_zyx_to_matrix, make_transform
from sim.core.text import mm_text
from sim.errors import KinematicsError, UnreachableError
from sim.robots.kinematics.ik import listed, solve_ik
from sim.robots.kinematics.model import kinematic_model
from sim.robots.registry import resolve_robot


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ik", help="inverse kinematics of a tcp pose",
        description="Analytic inverse kinematics: joint values (deg) that put the robot's tcp "
                    "at X Y Z (mm, frame0) with orientation R = Rz(A) Ry(B) Rx(G) (deg). "
                    "Solutions are listed best first: inside the joint ranges, then closest "
                    "to the zero pose, every joint at 0 (joint distance weighted by 1/max "
                    "speed).")
    p.add_argument("robot", metavar="ROBOT",
                   help="robot name (see `cellsim list`), or an arm as data: a URDF file, a "
                        "robot.toml or its folder (closed form when ortho-parallel with a "
                        "spherical wrist, numeric otherwise)")
    for axis in "XYZ":
        p.add_argument(axis.lower(), metavar=axis, type=float,
                       help=f"tcp {axis.lower()} in frame0, mm")
    p.add_argument("--euler-zyx-deg", metavar=("A", "B", "G"), nargs=3, type=float, default=None,
                   help="tcp orientation, Z-Y-X Euler angles in degrees (default: the tcp's "
                        "orientation in the zero pose, every joint at 0, not a cell's home "
                        "pose); for 5-axis robots A is implied by the position")
    p.add_argument("--tool", metavar="NAME", default=None,
                   help="the tcp is this tool's tip: a shipped tool (see `cellsim list`) or a "
                        "tool file (docs/cell-format.md); default: the model's own tcp, the "
                        "flange centre (the seeds' lrmate100ib and robot_5r have their torch "
                        "built in: their tcp is its tip, 145 and 300 mm past the flange)")
    p.add_argument("--maker", action="store_true",
                   help="also print the joint values in the maker's convention (FANUC: J3 from "
                        "the horizontal, FANUC's signs), as the controller shows them; a robot "
                        "without a [maker] table (not a FANUC) prints its own values")
    p.add_argument("--all", action="store_true", help="print every solution, not only the best")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def _check_finite(label: str, values: list[float]) -> None:
    for name, v in zip(label.split(), values):
        if not math.isfinite(v):
            raise KinematicsError(f"{name} must be a finite number, got {v}")


def _print_solutions(sols, shown, show_all: bool, maker=None) -> None:
    """One line per solution shown (joint values in deg, limits, branch), the maker's joint
    values under each when ``maker`` (q -> text) is given."""
    for i, s in enumerate(shown, 1):
        joints = " ".join(f"{v:9.3f}" for v in np.rad2deg(s.q))
        flag = "within limits" if s.within_limits else "OUTSIDE joint limits"
        print(f"  {i:2d}: {joints}   {flag}  [{s.branch}]")
        if maker is not None:
            print(f"      {maker(s.q)}")
    if not show_all and len(sols) > 1:
        print(f"  ({len(sols) - 1} more with --all)")


def _no_solution(name: str, args: argparse.Namespace, how: str) -> NoReturn:
    """An IK that found no solution is an unreachable pose for every kind of robot: one line,
    exit 2 (the closed forms of the shipped robots raise the same error with the distance)."""
    raise UnreachableError(f"{name}: pose unreachable: no inverse-kinematics solution for "
                           f"X Y Z = {args.x:g} {args.y:g} {args.z:g} mm ({how})", 0.0)


def _run_arm(args: argparse.Namespace) -> int:
    """``cellsim ik`` of an arm given as data (:mod:`sim.robots.arm`): the flange pose in the
    arm's base frame (a DH table's frame 0, a URDF's root link)."""
    from sim.robots.arm import load_arm

    if args.tool not in (None, "none") or args.maker:
        raise KinematicsError("--tool and --maker are for the shipped robots; an arm given as "
                              "data solves for its flange in its own joint values")
    arm = load_arm(args.robot)
    p = np.asarray([args.x, args.y, args.z], dtype=float) / 1000.0
    if args.euler_zyx_deg is None:
        R = arm.fk(np.zeros(arm.chain.n))[:3, :3]
    else:
        R = euler_zyx_to_matrix(*np.deg2rad(args.euler_zyx_deg))
    sols = arm.ik(make_transform(R, p))
    how = {"opw": "closed form (OPW)", "offset_wrist": "closed form (offset wrist, UR-type)",
           "five_r": "closed form (seed 000's 5R)"}.get(
        arm.solver, f"numeric ({arm.why_numeric})")
    if not sols:
        why = "numeric solver: none found in the joint ranges" if arm.solver == "numeric" \
            else f"{arm.solver} solver"
        if arm.opw is not None:
            from sim.robots.kinematics.opw import reach_gap

            gap, inner, outer = reach_gap(arm.opw, make_transform(R, p))
            if gap > 1e-9:
                why += (f"; the wrist centre is {mm_text(gap)} mm outside the arm's reach, J2 "
                        f"to wrist centre between {mm_text(inner)} and {mm_text(outer)} mm")
        _no_solution(arm.name, args, why)
    shown = sols if args.all else sols[:1]
    if args.json:
        print(json.dumps({"robot": arm.name, "solver": arm.solver, "tool": None,
                          "solutions": [{"joints_deg": [float(v) for v in np.rad2deg(s.q)],
                                         "within_limits": bool(s.within_limits),
                                         "branch": s.branch} for s in shown]}))
        return 0
    print(f"{arm.name} ({arm.source}): {len(sols)} solution(s), {how}; joints "
          f"{' '.join(arm.chain.joint_names)} in deg")
    _print_solutions(sols, shown, args.all)
    return 0


def run(args: argparse.Namespace) -> int:
    from sim.robots.arm import is_arm_path

    position = [args.x, args.y, args.z]
    _check_finite("X Y Z", position)
    if args.euler_zyx_deg is not None:
        _check_finite("A B G", args.euler_zyx_deg)
    if is_arm_path(args.robot):
        return _run_arm(args)
    spec = resolve_robot(args.robot)
    if args.tool is None or args.tool == "none":
        model = kinematic_model(spec)
    else:
        from sim.cells import tool_from_ref
        from sim.cells.compose import prepare_robot

        model = prepare_robot(spec, tool_from_ref(args.tool, None)).kinematics()
    p = np.asarray(position, dtype=float) / 1000.0
    if args.euler_zyx_deg is None:
        R = model.family.default_orientation(model.fk(np.zeros(model.n_joints))[:3, :3], p)
    else:
        a, b, g = np.deg2rad(args.euler_zyx_deg)
        a_new = model.family.reachable_alpha(p, float(a), float(b))
        if a_new != a:
            print(f"cellsim: note: {spec.name} has {spec.n_joints} axes: A is implied by the "
                  f"position (A = {np.rad2deg(a_new):.3f} deg, not {args.euler_zyx_deg[0]:g})",
                  file=sys.stderr)
            a = a_new
        R = euler_zyx_to_matrix(a, b, g)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sols = listed(solve_ik(model, make_transform(R, p)))
    for w in caught:
        print(f"cellsim: warning: {w.message}", file=sys.stderr)
    if not sols:
        _no_solution(spec.name, args, "closed form")
    shown = sols if args.all else sols[:1]
    from sim.robots.maker import maker_joint_names, to_maker

    if args.json:
        doc = {"robot": spec.name, "tool": args.tool,
               "solutions": [{"joints_deg": [float(v) for v in np.rad2deg(s.q)],
                              "within_limits": bool(s.within_limits)} for s in shown]}
        if args.maker:
            doc["maker_joints"] = list(maker_joint_names(spec))
            for d, s in zip(doc["solutions"], shown, strict=True):
                d["joints_maker_deg"] = [float(v) for v in np.rad2deg(to_maker(spec, s.q))]
        print(json.dumps(doc))
        return 0

    with_tool = f" with tool {args.tool}" if args.tool not in (None, "none") else ""
    print(f"{spec.title} ({spec.name}){with_tool}: {len(sols)} solution(s), best first; "
          f"joints {' '.join(spec.joints)} in deg")
    maker = None
    if args.maker:
        names = " ".join(maker_joint_names(spec))
        maker = lambda q: (f"{' '.join(f'{v:9.3f}' for v in np.rad2deg(to_maker(spec, q)))}"  # noqa: E731
                           f"   maker's {names}")
    _print_solutions(sols, shown, args.all, maker)
    return 0
