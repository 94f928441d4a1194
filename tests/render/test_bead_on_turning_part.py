"""The weld bead of a seam a positioner turns is laid on the part, not in the air: while the
part turns under a torch that stays put, the bead must wind round the part with it (a new
user's video showed it as a point at the torch: drawn in the world frame)."""

from __future__ import annotations

import numpy as np

SCENARIO = "positioner_cylinder_downhand"


def test_the_bead_rides_on_the_turning_part(scenario_run):
    import mujoco

    from sim.render.overlay import PathOverlay
    from sim.simulation.runfolder.reading import load_run

    run_dir, summary = scenario_run(SCENARIO)
    record = load_run(run_dir)
    model = mujoco.MjModel.from_xml_path(str(run_dir / "model.xml"))
    overlay = PathOverlay(record, model=model)
    (weld,) = summary["weld"]
    assert weld["carried_by"] == "positioner"
    carried = [(run, body) for run, body in zip(overlay.bead_runs, overlay.bead_body,
                                                 strict=True) if body is not None]
    assert len(carried) == 1
    (pts, _, _, _), body = carried[0]
    assert body == model.body("positioner_mount").id
    # on the part: in the faceplate's frame the tool point runs a circle about the rotate axis
    # (the faceplate's z) at one height, round the whole seam (359 deg)
    radius = np.hypot(pts[:, 0], pts[:, 1])
    assert np.ptp(radius) < 1e-4 and np.ptp(pts[:, 2]) < 1e-4
    angles = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    assert np.degrees(np.ptp(angles)) > 350.0
    # the planted fault: drawn in the world (no model to pose the part), the bead collapses
    # to where the torch stands
    flat = PathOverlay(record)
    world = [p for (p, _, _, _), b in zip(flat.bead_runs, flat.bead_body, strict=True)]
    assert np.ptp(world[0], axis=0).max() < 0.05
