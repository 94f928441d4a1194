"""``cellsim check`` of one weld cell on the LR Mate 200iC/5L and on a UR5-like DH arm.

Issue 29's acceptance: ``cellsim check`` of a cell with a UR-type DH arm (three parallel axes
and an offset wrist, given by a ``robot.toml`` DH table) takes at most 2x the time of the same
cell with the LR Mate. Both cells hold the same box on the floor with the same three fillet
seams (two straight, one arc) in world; each robot stands at the world origin, turned so that
the seams lie in its own working region (the UR5's home faces its base's -x axis: it is turned
180 deg). Each scenario goes home -> to each seam (joint move, ``approach_mm``), plunges,
welds, retracts, and goes home.

Prints, per arm, the wall and CPU time of ``check_scenario`` (in-process, after a warm-up
build that loads the modules) and its findings, then the ratio UR5 / LR Mate (target <= 2.0).
CPU time (``time.process_time``) is the figure to compare on a shared machine.

Run: ``python benchmarks/bench_check.py [--profile ur5|lrmate] [--repeat N]``.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import sys
import tempfile
import time
from pathlib import Path

UR5_DH = ((0.0, 90.0, 89.159, 0.0), (-425.0, 0.0, 0.0, 0.0), (-392.25, 0.0, 0.0, 0.0),
          (0.0, 90.0, 109.15, 0.0), (0.0, -90.0, 94.65, 0.0), (0.0, 0.0, 82.3, 0.0))
UR5_DRIVES = ((101, 2.0e-5, 0.8, 3.0), (101, 4.5e-5, 1.6, 5.0), (101, 2.0e-5, 0.8, 3.0),
              (101, 5.0e-6, 0.3, 1.0), (101, 5.0e-6, 0.3, 1.0), (101, 5.0e-6, 0.3, 1.0))
UR5_TOML = (
    'name = "ur5_dh"\ndescription = "a UR5-like arm from its DH table"'
    '\n[kinematics]\nconvention = "dh"\ndh = [\n'
    + ",\n".join(f"  [{a!r}, {al!r}, {d!r}, {o!r}]" for a, al, d, o in UR5_DH)
    + "\n]\n[joints]\nrange_deg = [[-360, 360], [-360, 360], [-180, 180], [-360, 360], "
    "[-360, 360], [-360, 360]]\nmax_speed_deg_s = [180, 180, 180, 180, 180, 180]\n"
    "[mass]\ntotal_kg = 18\npayload_kg = 5\n"
    + "".join(f"[[drives]]\ngear_ratio = {r}\nefficiency = 0.75\nrotor_inertia_kg_m2 = {i}\n"
              f"rated_torque_nm = {t}\npeak_torque_nm = {p}\nmax_speed_rpm = 6000\n"
              for r, i, t, p in UR5_DRIVES))

#: robot reference, base yaw (deg), home (deg)
ARMS = {
    "lrmate": ("lrmate200ic5l", 0.0, (0.0, 0.0, 0.0, 0.0, -90.0, 0.0)),
    "ur5": ("robots/ur5_dh", 180.0, (0.0, -90.0, 90.0, -90.0, -90.0, 0.0)),
}

#: seams on the box's top face (object frame, mm): name, kind, points
SEAMS = (
    ("s1", "line", ((-50.0, -70.0, 40.0), (50.0, -70.0, 40.0))),
    ("s2", "line", ((-60.0, 0.0, 40.0), (40.0, 60.0, 40.0))),
    ("s3", "arc", ((28.10, -43.58, 40.0), (30.0, 0.0, 40.0), (28.10, 43.58, 40.0))),
)


def cell_toml(base_yaw: float, home: tuple[float, ...]) -> str:
    seams = "".join(
        f'[[seams]]\nname = "{n}"\nobject = "part"\nkind = "{k}"\n'
        f"points_mm = {[list(p) for p in pts]!r}\nnormal = [0.0, 0.0, 1.0]\n"
        f'work_angle_deg = 45.0\ntravel_angle_deg = 10.0\nlean = "left"\n\n'
        for n, k, pts in SEAMS)
    return (f'name = "bench_cell"\ntool = "mig_torch"\n\n[robot]\nbase_pos_mm = [0.0, 0.0, 0.0]\n'
            f"base_euler_zyx_deg = [{base_yaw!r}, 0.0, 0.0]\nhome_deg = {list(home)!r}\n\n"
            '[[objects]]\nname = "part"\nshape = "box"\nsize_mm = [260.0, 240.0, 80.0]\n'
            'role = "workpiece"\npos_mm = [470.0, 0.0, 40.0]\neuler_zyx_deg = [0.0, 0.0, 0.0]'
            f"\n\n{seams}")


def scenario_toml(robot: str, home: tuple[float, ...]) -> str:
    h = list(home)
    out = (f'name = "bench_check"\ndescription = "bench"\nrobot = "{robot}"\n'
           f'cell = "cells/cell.toml"\n\n'
           f'[[phases]]\nname = "home"\nplanner = "434"\ntime_s = [0.0, 0.25, 0.5]\n'
           f"joints_deg = {[h, h, h]!r}\n\n")
    for n, k, _ in SEAMS:
        kind = "circular" if k == "arc" else "linear"
        out += (f'[[phases]]\nname = "to_{n}"\nplanner = "434"\ndurations_s = [2.0]\n'
                f'to_seam = "{n}"\napproach_mm = 80\n\n'
                f'[[phases]]\nname = "plunge_{n}"\nkind = "linear"\nto_seam = "{n}"\n'
                f'orientation = "seam"\nspeed_mm_s = 40.0\n\n'
                f'[[phases]]\nname = "weld_{n}"\nkind = "{kind}"\nseam = "{n}"\n'
                f'orientation = "seam"\nspeed_mm_s = 20.0\n\n'
                f'[[phases]]\nname = "retract_{n}"\nkind = "linear"\nto_seam = "{n}"\n'
                f'retract_mm = 80\norientation = "seam"\nspeed_mm_s = 40.0\n\n')
    out += (f'[[phases]]\nname = "back"\nplanner = "434"\ndurations_s = [4.0]\n'
            f"joints_deg = [{h!r}]\n")
    return out


def write(root: Path, key: str) -> Path:
    robot, yaw, home = ARMS[key]
    (root / "cells").mkdir(parents=True, exist_ok=True)
    (root / "cells" / "cell.toml").write_text(cell_toml(yaw, home))
    if key == "ur5":
        (root / "robots" / "ur5_dh").mkdir(parents=True, exist_ok=True)
        (root / "robots" / "ur5_dh" / "robot.toml").write_text(UR5_TOML)
    path = root / "scenario.toml"
    path.write_text(scenario_toml(robot, home))
    return path


def check(path: Path, profile: bool = False) -> tuple[float, float, list[str], dict]:
    from sim.pipeline.check import check_scenario
    from sim.scenario import load_scenario

    cwd = os.getcwd()
    os.chdir(path.parent)  # the robot folder reference is relative
    try:
        prof = cProfile.Profile() if profile else None
        w0, c0 = time.perf_counter(), time.process_time()
        if prof is not None:
            prof.enable()
        res = check_scenario(load_scenario(str(path)))
        if prof is not None:
            prof.disable()
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    finally:
        os.chdir(cwd)
    if prof is not None:
        pstats.Stats(prof).sort_stats("cumulative").print_stats(35)
        print("findings:", *[f"{f.kind}: {f.line}" for f in res.findings], sep="\n  ")
    return wall, cpu, [f"{f.kind}: {f.line}" for f in res.findings], res.timings


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", choices=tuple(ARMS), help="cProfile this arm's check")
    ap.add_argument("--only", choices=tuple(ARMS), help="check this arm only (no ratio)")
    ap.add_argument("--repeat", type=int, default=1, help="checks per arm (best CPU kept)")
    args = ap.parse_args(argv)
    print(f"load: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} (1, 5 min)")
    with tempfile.TemporaryDirectory() as tmp:
        paths = {k: write(Path(tmp) / k, k) for k in ARMS}
        if args.profile:
            check(paths[args.profile], profile=True)
            return 0
        check(paths["lrmate"])  # warm-up: module imports, the shipped robot's first build
        best: dict[str, tuple[float, float]] = {}
        for key, path in paths.items():
            if args.only and key != args.only:
                continue
            for _ in range(max(1, args.repeat)):
                wall, cpu, findings, timings = check(path)
                if key not in best or cpu < best[key][1]:
                    best[key] = (wall, cpu)
            print(f"{key:7s} wall {best[key][0]:7.2f} s  cpu {best[key][1]:7.2f} s  "
                  + "  ".join(f"{k} {v:.2f}" for k, v in timings.items())
                  + f"  findings {len(findings)}")
            for f in findings:
                print(f"    {f}")
    if args.only:
        return 0
    r_wall = best["ur5"][0] / best["lrmate"][0]
    r_cpu = best["ur5"][1] / best["lrmate"][1]
    print(f"ratio ur5 / lrmate: wall {r_wall:.2f}  cpu {r_cpu:.2f}  (target <= 2.0)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
