"""Robot comparison: one weld move, several arms of the welding-robot library side by side.

The same Cartesian job (a joint move onto a 300 mm line seam 1 m in front of the robot, the
torch straight down, the line welded at 20 mm/s, the torch lifted) is written as a scenario in
code for each robot, evaluated in memory, and the arms are compared on their verdict, the
busiest joint's sizing margin and the shoulder's (J2) peak and RMS torque.

    python examples/robot_comparison.py [ROBOT ...]
"""

import sys

import sim
from sim.scenario import parse_scenario

JOB = """
name = "compare_{robot}"
description = "{robot}: a 300 mm line weld at 20 mm/s, torch down"
robot = "{robot}"
tool = "mig_torch"

[[phases]]
name = "approach"
planner = "434"
durations_s = [2.0]
to_mm = [900.0, -150.0, 300.0]
euler_zyx_deg = [0.0, 0.0, 180.0]

[[phases]]
name = "weld"
kind = "linear"
to_mm = [900.0, 150.0, 300.0]
speed_mm_s = 20.0

[[phases]]
name = "lift"
kind = "linear"
to_mm = [900.0, 150.0, 400.0]
speed_mm_s = 100.0
"""


def main(robots: list[str]) -> list[sim.RunResult]:
    results = []
    print(f"{'robot':<12} {'verdict':<8} {'hardest':<8} {'margin %':>9} "
          f"{'J2 peak N m':>12} {'J2 RMS N m':>11}")
    for robot in robots:
        result = sim.evaluate(parse_scenario(JOB.format(robot=robot)))
        hardest = min(result.sizing.values(), key=lambda j: j.margin_pct)
        j2 = result.sizing[result.joints[1]]
        print(f"{robot:<12} {result.verdict:<8} {hardest.joint:<8} {hardest.margin_pct:>9.1f} "
              f"{j2.peak_torque_nm:>12.1f} {j2.rms_torque_nm:>11.1f}")
        results.append(result)
    return results


if __name__ == "__main__":
    main(sys.argv[1:] or ["m10ia", "irb1600", "kr10r1420"])
