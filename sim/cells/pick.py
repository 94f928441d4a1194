"""``pick``: a pick-and-place cell for the LR Mate 200iC/5L with the vacuum gripper.

Laid out in the robot's frame 0 (robot upright on a 0.6 m riser; world = frame 0 shifted up by
0.6 + 0.33 m). Sizes in m:

* **infeed table** (top 0.18 below J2, x 0.14..0.50, y 0.30..0.46) carrying four **parts**: free
  boxes 60 x 40 x 30 mm, 0.25 kg each (a density of 3470 kg/m^3: a hollow aluminium
  casting), friction 0.8, long side along x, centres at x = 0.20, 0.28, 0.36, 0.44, y = 0.38,
  resting on the table (body names ``part0`` .. ``part3``);
* **outfeed tray** (floor top 0.18 below J2; 30 mm rim around x 0.20..0.44, y -0.48..-0.28) with
  four marked **slots** in a 2 x 2 grid at x = 0.27, 0.37 and y = -0.34, -0.42. ``Cell.slots``
  holds where each part's centre is once placed: on the tray floor, 15 mm up.

Every pick and place pose has the gripper pointing straight down (tcp z axis = -z) at the top
face of a part (0.15 below J2, 0.43..0.58 m from the J1 axis): the analytic IK reaches all of
them inside the joint ranges with |theta5| >= 22 deg (clear of the wrist singularity). The
parts rest on the table by contact alone (MuJoCo soft contacts; they settle by ~0.1 mm).
"""

from __future__ import annotations

import numpy as np

from sim.cells.compose import (
    Layout,
    RobotRig,
    add_box,
    add_cameras,
    attach_robot,
    new_world,
)
from sim.cells.tools import CONTACT_PART_AFFINITY, CONTACT_PART_TYPE

RISER = 0.6
INFEED_TOP = -0.18  #: infeed table top in frame 0, m
INFEED_X, INFEED_Y = (0.14, 0.50), (0.30, 0.46)
PART_HALF = (0.030, 0.020, 0.015)  #: part half sizes, m (60 x 40 x 30 mm)
PART_MASS = 0.25  #: kg
PART_FRICTION = (0.8, 0.005, 0.0001)
PART_X = (0.20, 0.28, 0.36, 0.44)
PART_Y = 0.38
TRAY_FLOOR = -0.18  #: tray floor top in frame 0, m
TRAY_X, TRAY_Y = (0.20, 0.44), (-0.48, -0.28)
TRAY_RIM_H, TRAY_RIM_T, TRAY_BASE_T = 0.03, 0.005, 0.008
SLOT_X, SLOT_Y = (0.27, 0.37), (-0.34, -0.42)


def build(rig: RobotRig, mount: str) -> Layout:
    """Build the pick cell for ``rig`` (floor mount)."""
    h0 = rig.frame0_height
    world = new_world(f"pick_{rig.spec.name}", center=(0.3, 0.0, RISER + h0), extent=2.0)
    T0 = attach_robot(world, rig, mount, RISER)
    wb = world.worldbody

    def w(p) -> np.ndarray:
        return T0[:3, :3] @ np.asarray(p, float) + T0[:3, 3]

    add_box(wb, "riser", [0, 0, RISER / 2], [0.16, 0.16, RISER / 2], "concrete")
    # infeed table: 40 mm top on a frame
    top = w([0, 0, INFEED_TOP])[2]
    c = w([sum(INFEED_X) / 2, sum(INFEED_Y) / 2, INFEED_TOP])
    hx, hy = (INFEED_X[1] - INFEED_X[0]) / 2, (INFEED_Y[1] - INFEED_Y[0]) / 2
    add_box(wb, "infeed_top", [c[0], c[1], top - 0.02], [hx, hy, 0.02], "table")
    add_box(wb, "infeed_stand", [c[0], c[1], (top - 0.04) / 2], [0.05, 0.05, (top - 0.04) / 2],
            "dark_steel")
    # outfeed tray on a stand
    floor_top = w([0, 0, TRAY_FLOOR])[2]
    tc = w([sum(TRAY_X) / 2, sum(TRAY_Y) / 2, TRAY_FLOOR])
    thx, thy = (TRAY_X[1] - TRAY_X[0]) / 2, (TRAY_Y[1] - TRAY_Y[0]) / 2
    add_box(wb, "tray_floor", [tc[0], tc[1], floor_top - TRAY_BASE_T / 2],
            [thx, thy, TRAY_BASE_T / 2], "fixture")
    zr = floor_top + TRAY_RIM_H / 2
    for name, cx, cy, sx, sy in (
            ("tray_rim_xm", tc[0] - thx - TRAY_RIM_T / 2, tc[1], TRAY_RIM_T / 2, thy + TRAY_RIM_T),
            ("tray_rim_xp", tc[0] + thx + TRAY_RIM_T / 2, tc[1], TRAY_RIM_T / 2, thy + TRAY_RIM_T),
            ("tray_rim_ym", tc[0], tc[1] - thy - TRAY_RIM_T / 2, thx, TRAY_RIM_T / 2),
            ("tray_rim_yp", tc[0], tc[1] + thy + TRAY_RIM_T / 2, thx, TRAY_RIM_T / 2)):
        add_box(wb, name, [cx, cy, zr], [sx, sy, TRAY_RIM_H / 2], "fixture")
    stand_h = floor_top - TRAY_BASE_T
    add_box(wb, "tray_stand", [tc[0], tc[1], stand_h / 2], [0.05, 0.05, stand_h / 2], "dark_steel")
    slots = []
    for i, (sx, sy) in enumerate([(x, y) for y in SLOT_Y for x in SLOT_X]):
        p = w([sx, sy, TRAY_FLOOR])
        add_box(wb, f"slot{i}", [p[0], p[1], floor_top + 0.0002],
                [PART_HALF[0] + 0.003, PART_HALF[1] + 0.003, 0.0002], "slot", contact=False)
        slots.append([p[0], p[1], floor_top + PART_HALF[2]])
    # parts: free boxes resting on the infeed table
    parts = []
    for i, x in enumerate(PART_X):
        p = w([x, PART_Y, INFEED_TOP])
        body = wb.add("body", name=f"part{i}", pos=[p[0], p[1], top + PART_HALF[2]])
        body.add("freejoint", name=f"part{i}")
        body.add("geom", name=f"part{i}", type="box", size=PART_HALF, mass=PART_MASS,
                 material="part", friction=PART_FRICTION, contype=CONTACT_PART_TYPE,
                 conaffinity=CONTACT_PART_AFFINITY, condim=4)
        parts.append(f"part{i}")
    j2 = T0[2, 3]
    cameras = add_cameras(world, rig, overview_pos=[1.35, -1.05, j2 + 0.55],
                          overview_target=[0.3, 0.0, top + 0.1],
                          tool_pos=w([0.85, -0.15, 0.25]).tolist(), tool_fovy=35.0)
    dims = {"riser_height": RISER, "infeed_top_height": top, "tray_floor_height": floor_top,
            "part_mass": PART_MASS, "part_size_x": 2 * PART_HALF[0],
            "part_size_y": 2 * PART_HALF[1], "part_size_z": 2 * PART_HALF[2]}
    return Layout(world=world, world_from_frame0=T0, parts=parts, slots=np.array(slots),
                  cameras=cameras, home_q=rig.home_q.copy(), dims=dims)
