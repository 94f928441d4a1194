"""A robot given as data, for tests that need one of their own: :data:`DH_ROBOT`, a robot
folder's ``robot.toml`` from a DH table (an OPW arm, with drives and a mass), and
:data:`DH_SCENARIO`, a joint move and a straight line of it from ``robots/dh_arm``.
"""

from __future__ import annotations

#: Six ``[[drives]]`` tables (gear ratio, rotor inertia, rated and peak torque per joint).
DRIVES_6 = "".join(f"""
[[drives]]
gear_ratio = {r}
efficiency = 0.75
rotor_inertia_kg_m2 = {i}
rated_torque_nm = {t}
peak_torque_nm = {p}
max_speed_rpm = 6000
""" for r, i, t, p in [(120, 2e-5, 0.65, 2.4), (120, 4.5e-5, 1.3, 4.5), (120, 2e-5, 0.65, 2.4),
                       (75, 5e-6, 0.32, 1.0), (75, 5e-6, 0.32, 1.0), (48, 3e-6, 0.25, 0.8)])

DH_ROBOT = """name = "dh_arm"
description = "an OPW arm from its DH table"
[kinematics]
convention = "dh"
dh = [[75, -90, 330, 0], [300, 0, 0, -90], [75, -90, 0, 0], [0, 90, 320, 0], [0, -90, 0, 0],
      [0, 0, 80, 0]]
[joints]
range_deg = [[-170, 170], [-100, 140], [-150, 150], [-190, 190], [-120, 120], [-360, 360]]
max_speed_deg_s = [270, 270, 270, 450, 450, 720]
[mass]
total_kg = 25
payload_kg = 2
""" + DRIVES_6

DH_SCENARIO = """name = "dh_moves"
description = "a robot from a DH table: a joint move and a straight line"
robot = "robots/dh_arm"
[[phases]]
name = "move"
planner = "434"
time_s = [0.0, 1.0, 2.0]
joints_deg = [[0, 0, 0, 0, 30, 0], [20, 10, -20, 10, 40, 20], [30, 20, -30, 0, 60, 0]]
[[phases]]
name = "line"
kind = "linear"
to_mm = [450, 150, 300]
speed_mm_s = 100
"""
