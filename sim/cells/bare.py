"""The bare scene (``cell=None``): the robot alone with floor, lights and cameras.

``floor``: base plane on the floor (z = 0). ``ceiling``: hanging from a ceiling plate with its
base plane at ``h0 + reach + 0.2`` m (h0 = base -> J2, reach = sum of the link lengths to the
tcp), so the fully stretched arm clears the floor.
"""

from __future__ import annotations

from sim.cells.compose import (
    Layout,
    RobotRig,
    add_box,
    add_cameras,
    attach_robot,
    new_world,
)


def build(rig: RobotRig, mount: str) -> Layout:
    """Build the bare scene for ``rig``."""
    h0 = rig.frame0_height
    reach = rig.max_distance_from_frame0()
    height = 0.0 if mount == "floor" else h0 + reach + 0.2
    j2 = h0 if mount == "floor" else height - h0
    world = new_world(f"bare_{rig.spec.name}_{mount}", center=(0.0, 0.0, j2),
                      extent=2.5 * reach)
    T0 = attach_robot(world, rig, mount, height)
    if mount == "ceiling":
        add_box(world.worldbody, "ceiling_plate", [0, 0, height + 0.02],
                [0.6 * reach, 0.6 * reach, 0.02], "concrete")
    d = 2.2 * reach
    cameras = add_cameras(world, rig, overview_pos=[d, -0.9 * d, j2 + 0.6 * reach],
                          overview_target=[0.3 * reach, 0.0, j2 - 0.2 * reach],
                          tool_pos=[0.9 * d, -0.5 * d, j2], tool_fovy=30.0)
    dims = {"robot_base_height": height, "j2_height": j2}
    return Layout(world=world, world_from_frame0=T0, cameras=cameras,
                  home_q=rig.home_q.copy(), dims=dims)
