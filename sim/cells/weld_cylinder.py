"""``weld_cylinder``: the 5R welding cell of seed 001 (large cylindrical part coaxial with J1).

Seed 001 welds large cylindrical parts "whose axis of symmetry coincides with the first axis of
rotation of the robot", the robot mounted on the floor or upside-down; phase I (Table 1, eq. 4)
brings the torch to the start of the seam at ``q = (-15.2, 116.82, -1.3, 1.4, -0.206) deg``.

**The part is derived from that pose.** The tcp of the phase-I end pose is computed with the
closed-form FK (seed 000 eq. 5) with the attached torch (``l3 = J4->flange + torch length``):
with the default ``mig_torch_long`` (300 mm) and the 5R robot's dimensions the point lies at
radius ``R`` = 0.703 m from the J1 axis and ``D`` = 1.349 m *below* frame 0 (the pose folds the
arm down: q2 = 116.8 deg), with the torch 26.9 deg from the downward vertical, leaning out. So:

* the part is a vertical cylindrical shell (outer radius ``R + 25 mm``, wall 25 mm) closed at
  the top by a flat annular head set flush into it (inner radius ``R - 0.15`` m, 30 mm thick);
  its top face is at ``z = part height`` (0.8 m, on the floor);
* the **seam** is the circumferential groove weld on the top face where head and shell meet
  (radius ``R``), welded in the flat position with the torch tilted ``w`` = 26.9 deg outward
  from the surface normal (work angle) and no travel angle (a 5R's torch axis is its J5 axis,
  always in the vertical plane through J1: on a circle about J1 it is perpendicular to the
  travel direction). The tcp approaches from above the head during phase I and never has to
  pass through the part;
* moving J1 alone traces the seam (it is a circle about the J1 axis): the seam arc starts at the
  phase-I end (q1 = -15.2 deg) and runs towards increasing q1 up to 5 deg short of J1's upper
  limit (+160 deg on the 5R robot: 170.2 deg of arc, 2.09 m); the rest of the circumference
  would need a part positioner.

**Mounts.** ``floor``: the robot stands on a column through the hollow part, its base plane at
``part height + D - h0`` (h0 = 0.6 m, floor -> J2), so that J2 is ``D`` above the seam and the
seed's phase-I end pose puts the torch tip exactly on the seam start. ``ceiling``: the same part
on the floor; the robot hangs upside-down (turned 180 deg about the world x axis) from a gantry
beam with its base plane at ``part height + D + h0``, J2 again ``D`` above the seam. Hanging,
the seed's phase-I joint values would fold the arm *up* towards the beam, so they cannot end on
the seam; the cell's ``start_q`` is then the analytic IK (seed 000 eq. 13-17,
:func:`sim.robots.kinematics.ik.solve_ik`) of the seam start with the same torch posture. The seam is
laid out in frame 0 exactly as on the floor (start at q1 = -15.2 deg, running towards
increasing q1); in world it therefore starts at +15.2 deg azimuth and runs clockwise.
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
from sim.errors import CellsimError
from sim.robots.kinematics.closed_form import fk_5r
from sim.robots.kinematics.ik import solve_ik
from sim.robots.kinematics.model import joint_limits

#: Seed 001 Table 1 / eq. (4): end of phase I, deg.
PHASE1_END_DEG = (-15.2, 116.82, -1.3, 1.4, -0.206)
PART_HEIGHT = 0.8  #: top face of the part above the floor, m
SHELL_WALL = 0.025  #: shell wall thickness outside the seam radius, m
HEAD_WIDTH = 0.15  #: radial width of the annular head inside the seam radius, m
HEAD_THICKNESS = 0.03  #: m
COLUMN_RADIUS = 0.2  #: robot column (floor mount), m
J1_MARGIN_DEG = 5.0  #: the seam ends this far short of J1's upper limit


def phase1_end_q() -> np.ndarray:
    """Seed 001 phase-I end configuration (Table 1, eq. 4), rad, (5,)."""
    return np.deg2rad(np.array(PHASE1_END_DEG))


def seam_start_frame0(rig: RobotRig) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form tcp position (3,) and torch axis (3,) at the phase-I end, in frame 0.

    Seed 000 eq. (5) with the rig's kinematics (``l3 = J4 -> flange + tool length``).
    """
    R, p = fk_5r(phase1_end_q(), rig.kinematics().family.dims)
    return p, R[:, 0]


def build(rig: RobotRig, mount: str) -> Layout:
    """Build the cell (see the module docstring)."""
    p0, a0 = seam_start_frame0(rig)
    R = float(np.hypot(p0[0], p0[1]))
    phi0 = float(np.arctan2(p0[1], p0[0]))
    D = float(-p0[2])
    if D <= 0.1 or R <= HEAD_WIDTH + COLUMN_RADIUS:
        raise CellsimError(f"weld_cylinder: the phase-I end pose puts the torch {D:.3f} m below "
                           f"frame 0 at radius {R:.3f} m; the cell needs it well below J2 and "
                           "outside the robot column")
    # torch posture: work angle from the top face's normal, leaning radially outwards
    rho0 = np.array([np.cos(phi0), np.sin(phi0), 0.0])
    work = float(np.degrees(np.arctan2(-(a0 @ rho0), -a0[2])))
    h0 = rig.frame0_height
    zs = PART_HEIGHT
    base_h = zs + D - h0 if mount == "floor" else zs + D + h0
    world = new_world(f"weld_cylinder_{rig.spec.name}_{mount}", center=(0.0, 0.0, zs),
                      extent=2.0 * (R + 1.5))
    T0 = attach_robot(world, rig, mount, base_h)
    T0_inv = np.linalg.inv(T0)

    # seam: circle about J1 at radius R in the plane z = zs, from q1 = phi0 up to the J1 limit
    lim = joint_limits(rig.spec)
    q1_max = float(lim[1][0]) if lim is not None and np.isfinite(lim[1][0]) else np.pi
    phi_end = min(q1_max - np.deg2rad(J1_MARGIN_DEG), phi0 + 2 * np.pi - 1e-3)
    z0 = (T0_inv @ np.array([0.0, 0.0, zs, 1.0]))[2]  # seam plane in frame 0
    ang = np.array([phi0, 0.5 * (phi0 + phi_end), phi_end])
    pts0 = np.column_stack([R * np.cos(ang), R * np.sin(ang), np.full(3, z0)])
    pts = pts0 @ T0[:3, :3].T + T0[:3, 3]
    normal = T0[:3, :3] @ np.array([0.0, 0.0, 1.0])  # +q1 travel: right-handed about J1
    # torch body leans radially out; travel is +q1: left of travel (seen from above) is the
    # J1-axis side for the floor mount (normal up), the outer side when hanging (normal down)
    side = -1 if normal[2] > 0 else 1
    seam = Seam(name="circumferential", kind="arc", points=pts, normal=normal,
                torch_work_angle_deg=work, torch_travel_angle_deg=0.0,
                surface_normal=np.array([0.0, 0.0, 1.0]), torch_side=side, tool_axis=0,
                world_from_frame0=T0,
                description=("circumferential groove weld, flat position, on the top face of "
                             "the cylinder where the head meets the shell"))

    # start configuration: seed 001 phase-I end on the floor; analytic IK when hanging
    if mount == "floor":
        start_q = phase1_end_q()
    else:
        km = rig.kinematics()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sols = [s for s in solve_ik(km, T0_inv @ seam.pose(0.0), np.zeros(5))
                    if s.within_limits]
        if not sols:
            raise CellsimError("weld_cylinder: the seam start is out of reach when hanging")
        start_q = sols[0].q

    # part: shell (outside the seam radius) + flush annular head (inside)
    wb = world.worldbody
    shell = add_ring(wb, "shell", R, R + SHELL_WALL, 0.0, zs, "steel", n=96)
    head = add_ring(wb, "head", R - HEAD_WIDTH, R, zs - HEAD_THICKNESS, zs, "dark_steel", n=96)
    # seam line (visual): 4 mm wide, 0.5 mm proud, over the welded arc
    # seam line (visual): 4 mm wide, 0.5 mm proud, over the welded arc (counter-clockwise in
    # world from the start on the floor; hanging, the world azimuth runs the other way)
    ring_from = pts[0] if normal[2] > 0 else pts[2]
    ring_phi0 = float(np.arctan2(ring_from[1], ring_from[0]))
    add_ring(wb, "seam", R - 0.002, R + 0.002, zs, zs + 0.0005, "seam", n=64, phi0=ring_phi0,
             phi1=ring_phi0 + (phi_end - phi0), contact=False)
    if mount == "floor":
        col_h = base_h - 0.03
        wb.add("geom", name="column", type="cylinder", pos=[0, 0, col_h / 2],
               size=[COLUMN_RADIUS, col_h / 2], material="concrete", contype=2, conaffinity=2)
        add_box(wb, "column_plate", [0, 0, base_h - 0.015], [0.34, 0.34, 0.015], "dark_steel")
    else:
        span = R + 1.2
        add_box(wb, "beam", [0, 0, base_h + 0.1], [0.2, span, 0.1], "fixture")
        add_box(wb, "beam_plate", [0, 0, base_h + 0.01], [0.34, 0.34, 0.01], "dark_steel")
        for sgn in (-1, 1):
            add_box(wb, f"post{'ab'[sgn > 0]}", [0, sgn * span, (base_h + 0.2) / 2],
                    [0.15, 0.15, (base_h + 0.2) / 2], "fixture")
    start_w = pts[0]
    az = np.arctan2(start_w[1], start_w[0])
    cam_az = az - np.deg2rad(35.0)
    tool_cam = [(R + 1.0) * np.cos(cam_az), (R + 1.0) * np.sin(cam_az), zs + 0.45]
    ov_pos = [3.2 + R, -(2.6 + R), zs + 2.2]
    if mount == "floor":
        # the arm reaches down behind its column to the far side of the ring: look down at
        # 55 deg so that it stays in view all round (the video frames the distance itself)
        horizontal = float(np.hypot(ov_pos[0], ov_pos[1]))
        ov_pos[2] = zs + 0.3 + horizontal * np.tan(np.deg2rad(55.0))
    cameras = add_cameras(world, rig, ov_pos, [0.0, 0.0, zs + 0.3], tool_cam, tool_fovy=35.0)
    dims = {
        "seam_radius": R, "seam_height": zs, "shell_outer_radius": R + SHELL_WALL,
        "head_inner_radius": R - HEAD_WIDTH, "part_height": zs, "drop_j2_to_seam": D,
        "robot_base_height": base_h, "torch_work_angle_deg": work,
        "seam_sweep_deg": float(np.degrees(phi_end - phi0)),
    }
    return Layout(world=world, world_from_frame0=T0, seams={seam.name: seam}, cameras=cameras,
                  start_q=start_q, home_q=np.zeros(rig.spec.n_joints), dims=dims,
                  objects={"shell": shell, "head": head},
                  seam_objects={seam.name: ("shell", "head")})

