"""``weld_table``: a welding table for the LR Mate 100iB (5 axes) and 200iC/5L (6 axes).

Everything is laid out in the robot's frame 0 (J1 axis, J2 height; frame 0's x axis points at
the table) and the robot stands upright on a 0.6 m riser; world = frame 0 shifted up by
``0.6 + h0`` (h0 = floor-of-robot to J2: 0.35 m for the 100iB, 0.33 m for the 200iC). Sizes in m:

* a table and a 10 mm steel base plate whose top is ``PLATE_TOP`` = 0.15 m below J2, spanning
  x 0.24..0.62, y -0.36..0.46;
* **line** seam: a flat-position (1F) fillet in the root of a 90 deg V formed by two 6 mm plates
  (60 mm wide) at +-45 deg resting on a V-block. The root is a *radial* line at azimuth -32 deg
  from r = 0.38 to 0.51 (0.13 m), 0.06 m above the base plate; welded outwards with the torch
  in the vertical plane through the root (work angle 45 deg to either plate) and a 10 deg push
  travel angle;
* **arc** seam: a horizontal fillet (2F) at the foot of a curved 8 mm wall (a cylindrical
  segment of radius 0.50 about the J1 axis, 70 mm high) standing on the base plate, on the
  robot side of the wall: centre on the J1 axis, radius 0.50, from azimuth -5 to +45 deg
  (counter-clockwise, 0.436 m), work angle 45 deg from the plate normal with the torch leaning
  back towards the robot, travel angle 0.

Why this geometry: a 5-axis arm (100iB) can only put its torch axis in the vertical plane
through J1 and the tool point (``R = Rz(q1) Ry(q2+q3+q4) Rx(q5)``, seed 000 eq. 6; q5 only rolls
the torch about itself). A radial seam lies in that plane, so the torch may push or drag along
it but must be symmetric across it: hence the V (1F) rather than a wall fillet. On an arc about
J1 the plane is perpendicular to the travel direction at every point, so any work angle is
available but the travel angle is 0. Both seams are therefore weldable with 5 DOF at constant
work/travel angles (``Seam.plane_deviation_deg`` = 0), and by the 6-axis 200iC too. The heights
keep the 200iC's wrist away from its ``theta5 = 0`` singularity (|theta5| >= 29 deg along both
seams with the analytic IK), which a lower table would not.
"""

from __future__ import annotations

import warnings

import numpy as np

from sim.cells.compose import (
    Layout,
    RobotRig,
    add_box,
    add_cameras,
    add_ring,
    attach_robot,
    new_world,
)
from sim.cells.seam import Seam
from sim.robots.kinematics.ik import solve_ik

RISER = 0.6  #: robot riser height, m
PLATE_TOP = -0.15  #: base plate top in frame 0, m
PLATE_T = 0.010
PLATE_X = (0.24, 0.62)
PLATE_Y = (-0.36, 0.46)
TABLE_T = 0.04
LINE_AZIMUTH_DEG = -32.0
LINE_R = (0.38, 0.51)
LINE_ROOT_ABOVE_PLATE = 0.06
V_PLATE_W, V_PLATE_T = 0.060, 0.006
LINE_TRAVEL_DEG = 10.0
ARC_R = 0.50
ARC_DEG = (-5.0, 45.0)
WALL_T, WALL_H = 0.008, 0.07


def _rot_cols(x, y, z) -> np.ndarray:
    return np.column_stack([x, y, z])


def build(rig: RobotRig, mount: str) -> Layout:
    """Build the welding table for ``rig`` (floor mount only)."""
    h0 = rig.frame0_height
    world = new_world(f"weld_table_{rig.spec.name}", center=(0.35, 0.0, RISER + h0),
                      extent=2.5)
    T0 = attach_robot(world, rig, mount, RISER)
    wb = world.worldbody
    up = np.array([0.0, 0.0, 1.0])
    tool_axis = rig.spec.family.approach_column

    def w(p) -> np.ndarray:  # frame 0 -> world
        return T0[:3, :3] @ np.asarray(p, float) + T0[:3, 3]

    # riser, table, base plate
    add_box(wb, "riser", [0, 0, RISER / 2], [0.16, 0.16, RISER / 2], "concrete")
    cx, cy = sum(PLATE_X) / 2, sum(PLATE_Y) / 2
    hx, hy = (PLATE_X[1] - PLATE_X[0]) / 2, (PLATE_Y[1] - PLATE_Y[0]) / 2
    plate_c = w([cx, cy, PLATE_TOP - PLATE_T / 2])
    add_box(wb, "base_plate", plate_c, [hx, hy, PLATE_T / 2], "steel")
    top_w = plate_c[2] - PLATE_T / 2
    add_box(wb, "table_top", [plate_c[0], plate_c[1], top_w - TABLE_T / 2],
            [hx + 0.03, hy + 0.03, TABLE_T / 2], "table")
    for sx in (-1, 1):
        for sy in (-1, 1):
            leg_h = top_w - TABLE_T
            add_box(wb, f"table_leg{'ab'[sx > 0]}{'ab'[sy > 0]}",
                    [plate_c[0] + sx * hx, plate_c[1] + sy * hy, leg_h / 2],
                    [0.025, 0.025, leg_h / 2], "dark_steel")

    # line seam: root of a 90 deg V, radial at LINE_AZIMUTH_DEG
    phi = np.deg2rad(LINE_AZIMUTH_DEG)
    t = np.array([np.cos(phi), np.sin(phi), 0.0])
    left = np.cross(up, t)
    z_root = PLATE_TOP + LINE_ROOT_ABOVE_PLATE
    r0, r1 = LINE_R
    p_start, p_end = r0 * t + [0, 0, z_root], r1 * t + [0, 0, z_root]
    mid = 0.5 * (p_start + p_end)
    half_len = 0.5 * (r1 - r0) + 0.01
    c45 = np.sqrt(0.5)
    for name, side in (("v_plate_left", 1.0), ("v_plate_right", -1.0)):
        u = c45 * (side * left + up)  # from the root up along the plate's inner face
        n_out = c45 * (side * left - up)  # the plate's outer normal (away from the V)
        centre = mid + 0.5 * V_PLATE_W * u + 0.5 * V_PLATE_T * n_out
        R = _rot_cols(t, u, np.cross(t, u))
        add_box(wb, name, w(centre), [half_len, V_PLATE_W / 2, V_PLATE_T / 2], "dark_steel", R=R)
    # V-block: a square bar turned 45 deg under the V, its upper faces under the plates
    a = 0.03
    root_out = mid - V_PLATE_T * np.sqrt(2.0) * up
    vb = root_out - a * np.sqrt(2.0) * up
    add_box(wb, "v_block", w(vb), [half_len, a, a], "fixture",
            R=_rot_cols(t, c45 * (left + up), c45 * (-left + up)))
    add_box(wb, "line_mark", w(mid + 0.0008 * up), [0.5 * (r1 - r0), 0.0015, 0.0008], "seam",
            R=_rot_cols(t, left, up), contact=False)
    n_ref = c45 * (-left + up)  # inner normal of the left plate (reference surface)
    line0 = Seam(name="line", kind="line", points=np.array([p_start, p_end]), normal=None,
                 torch_work_angle_deg=45.0, torch_travel_angle_deg=LINE_TRAVEL_DEG,
                 surface_normal=n_ref, torch_side=1, tool_axis=tool_axis,
                 description="1F fillet in the root of a 90 deg V (two 6 mm plates), radial")

    # arc seam: fillet at the foot of a curved wall about the J1 axis (robot side)
    a0, a1 = np.deg2rad(ARC_DEG)
    ang = np.array([a0, 0.5 * (a0 + a1), a1])
    pts = np.column_stack([ARC_R * np.cos(ang), ARC_R * np.sin(ang), np.full(3, PLATE_TOP)])
    arc0 = Seam(name="arc", kind="arc", points=pts, normal=up, torch_work_angle_deg=45.0,
                torch_travel_angle_deg=0.0, surface_normal=up, torch_side=1, tool_axis=tool_axis,
                description="2F fillet at the foot of a curved wall (R 0.50 m about J1)")
    axis_w = T0[:2, 3]  # J1 axis (x, y) in world
    z_plate_w = w([0, 0, PLATE_TOP])[2]
    wall = add_ring(wb, "wall", ARC_R, ARC_R + WALL_T, z_plate_w, z_plate_w + WALL_H, "steel", n=24,
             phi0=a0 - np.deg2rad(7.0), phi1=a1 + np.deg2rad(7.0), center=axis_w)
    add_ring(wb, "arc_mark", ARC_R - 0.003, ARC_R, z_plate_w, z_plate_w + 0.0008, "seam", n=24,
             phi0=a0, phi1=a1, center=axis_w, contact=False)

    seams = {s.name: s.transformed(T0) for s in (line0, arc0)}
    km = rig.kinematics()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sols = [s for s in solve_ik(km, line0.pose(0.0), rig.home_q) if s.within_limits]
    start_q = sols[0].q if sols else None

    j2 = T0[2, 3]
    cameras = add_cameras(world, rig, overview_pos=[1.35, -1.15, j2 + 0.5],
                          overview_target=[0.35, 0.0, z_plate_w],
                          # the tool camera looks from the torch side (inside the arc, over
                          # the V-block), so both seams and their beads are in view
                          tool_pos=w([0.12, -0.62, PLATE_TOP + 0.45]).tolist(), tool_fovy=40.0)
    dims = {"riser_height": RISER, "plate_top_height": z_plate_w,
            "plate_top_below_j2": -PLATE_TOP, "line_root_height": w(p_start)[2],
            "line_length": r1 - r0, "arc_radius": ARC_R, "arc_sweep_deg": ARC_DEG[1] - ARC_DEG[0],
            "wall_height": WALL_H}
    return Layout(world=world, world_from_frame0=T0, seams=seams, cameras=cameras,
                  start_q=start_q, home_q=rig.home_q.copy(), dims=dims,
                  objects={"wall": wall},
                  seam_objects={"line": ("v_plate_left", "v_plate_right"),
                                "arc": ("wall", "base_plate")})

