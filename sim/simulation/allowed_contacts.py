"""The contacts a motion may make, declared rather than guessed (:func:`allowed_contacts`): the
welding wire in the seam's workpieces while the arc is on (up to its radius, the phase's weave
reach and :data:`WIRE_ARC_DEPTH_M`), the torch's touch sensing, the suction cup with the part
it picks, parts resting, lifted off and set down; see :mod:`sim.simulation.collisions` for the
full rules. In a cell with several robots each robot's wire and tool mount are declared for
itself (its own phases, seams and arc: :meth:`MotionSamples.lane`; only the first robot picks);
nothing is ever allowed between two robots.

Owns the declarations and the mask of the contacts they allow (:func:`allowed_mask`).
May import: :mod:`sim.core` and the check model.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.core.intervals import true_runs
from sim.simulation.collision_model import (
    CELL,
    LEAD,
    LINK,
    PART,
    PENETRATION_TOLERANCE_M,
    TOOL,
    AllowedContact,
    CollisionModel,
    Contacts,
    MotionSamples,
    mujoco_module,
)

#: Depth the welding wire may reach beyond its radius (and the phase's weave reach) in the seam's
#: workpiece while the arc is on (the tip in the weld pool, tracking included), m; the contact
#: tip and nozzle never touch.
WIRE_ARC_DEPTH_M = 1e-3
#: Depth a part may sink into what it rests on, is lifted off or set down on, or into the cup's
#: lip, m: the soft contacts of the simulation sink by a fraction of this.
PART_CONTACT_DEPTH_M = 1e-3
#: Suction picks the part whose bounding sphere holds the tool point, with this to spare, m.
PICK_REACH_M = 0.005
#: Step of the sweep of the tool's own joint that finds the tool's geoms overlapping the link
#: before it at every angle (:func:`mount_overlaps`), deg.
MOUNT_SWEEP_STEP_DEG = 0.5


def weave_reach(weave: Any) -> float:
    """How far a weave (:class:`planners.weave.Weave`, or None) takes the tool point from its
    path, m: the largest ``|(lateral, longitudinal)|`` offset of its pattern over a cycle (its
    fade envelope is at most 1): the amplitude ``A`` for a sine, zigzag or circle,
    ``sqrt(5) / 2 A`` for the triangle (``A`` across, ``A / 2`` behind); 0 without a weave."""
    if weave is None:
        return 0.0
    lateral, longitudinal = weave.shape(np.linspace(0.0, 1.0, 401))  # the extremes at 1/4, 3/4
    return float(np.max(np.hypot(lateral, longitudinal)))


def allowed_contacts(cm: CollisionModel, samples: MotionSamples,
                     phase_seams: Sequence[str | None],
                     weaves: Sequence[float] | None = None) -> list[AllowedContact]:
    """The contacts the work makes on purpose (module docstring), as declarations.

    Args:
        cm: The check model.
        samples: The sampled motion.
        phase_seams: The seam each phase follows (None when it follows none), by phase index.
        weaves: Each phase's weave reach, m (:func:`phase_weaves`); None: no phase weaves.
    """
    built = cm.built
    cell = built.cell
    n = samples.t.size
    out: list[AllowedContact] = [
        AllowedContact(frozenset({a}), frozenset({b}), np.ones(n, bool), reason)
        for a, b, reason in mount_overlaps(cm)]
    # each robot's wire: the first robot's phases and arc, then each other robot's
    robots = [(LEAD, cell.tool, samples.arc_on, samples.phase, phase_seams, weaves, "")]
    for cr in cell.partners:
        lane = samples.lane(cr.name)
        robots.append((cr.name, cr.tool, lane.arc_on, lane.phase, lane.phase_seams, lane.weaves,
                       f"{cr.name}: "))
    lead_work: frozenset[int] = frozenset()
    for name, tool, arc_on, phase, seams, phase_weaves, label in robots:
        work = frozenset(g for g, cg in cm.geoms.items() if cg.work and cg.robot == name)
        if name == LEAD:
            lead_work = work
        if tool is None or tool.kind != "torch" or not (work and cell.seam_objects):
            continue
        all_work = frozenset().union(*(cm.ids(CELL, obj) for objs in cell.seam_objects.values()
                                       for obj in objs))
        radius = max(float(built.model.geom_size[g, 0]) for g in work)
        # the wire in the joint of the seam it welds, weaving included, while the arc is on
        for k, seam in enumerate(seams):
            when = arc_on & (phase == k)
            if not when.any():
                continue
            objs = cell.seam_objects.get(seam, ()) if seam is not None else ()
            pieces = (frozenset().union(*(cm.ids(CELL, o) for o in objs)) if objs else all_work)
            reach = 0.0 if phase_weaves is None else float(phase_weaves[k])
            depth = radius + reach + WIRE_ARC_DEPTH_M
            weaving = f" + weave {reach * 1e3:.1f} mm" if reach > 0 else ""
            out.append(AllowedContact(
                work, pieces, when, f"{label}wire in the joint of seam {seam!r}, arc on (up to "
                f"{depth * 1e3:.1f} mm: radius{weaving} + {WIRE_ARC_DEPTH_M * 1e3:g} mm)",
                max_depth_m=depth))
        # the wire tip set on a workpiece, arc off included (touch sensing, the tip on the
        # root at a seam's start or end); deeper is a collision
        touch = tool.touch_depth_m
        out.append(AllowedContact(work, all_work, np.ones(n, bool),
                                  f"{label}wire touching a workpiece (up to "
                                  f"{(radius + touch) * 1e3:.1f} mm: radius + touch depth "
                                  f"{touch * 1e3:g} mm)", max_depth_m=radius + touch))
    work = lead_work  # the first robot picks (the others carry no suction gripper)
    # parts: at rest, lifted off, set down; the cup lip with the part it picks
    part_ids = {p: cm.ids(PART, p) for p in cell.parts}
    if not part_ids:
        return out
    cell_ids = cm.ids(CELL)
    depth = PART_CONTACT_DEPTH_M
    held = {p: np.zeros(n, bool) for p in part_ids}
    for i_on, stop in true_runs(samples.suction):
        p = _picked_part(cm, samples, i_on)
        if p is None:
            continue
        held[p][i_on:stop] = True
        k_on, k_off = int(samples.phase[i_on]), int(samples.phase[stop - 1])
        if stop < n:
            k_off = int(samples.phase[stop])
        window = (samples.phase >= k_on - 1) & (samples.phase <= k_off + 1)
        if work:
            out.append(AllowedContact(work, part_ids[p], window,
                                      f"cup lip on {p}, picking it", max_depth_m=depth))
        settle = held[p] & np.isin(samples.phase, (k_on, k_on + 1, k_off - 1, k_off))
        rest = frozenset().union(*(ids for q, ids in part_ids.items() if q != p))
        out.append(AllowedContact(part_ids[p], cell_ids | rest, settle,
                                  f"{p} lifted off or set down", max_depth_m=depth))
    names = list(part_ids)
    for i, p in enumerate(names):
        out.append(AllowedContact(part_ids[p], cell_ids, ~held[p], f"{p} at rest",
                                  max_depth_m=depth))
        for q in names[i + 1:]:
            out.append(AllowedContact(part_ids[p], part_ids[q], ~held[p] & ~held[q],
                                      f"{p} and {q} at rest", max_depth_m=depth))
    return out


def _picked_part(cm: CollisionModel, samples: MotionSamples, i: int) -> str | None:
    """The part the cup's lip is on when suction comes on at sample ``i``: the nearest part
    whose bounding sphere holds the tool point (with :data:`PICK_REACH_M` to spare); None when
    suction comes on with no part at the cup."""
    mujoco = mujoco_module()
    built = cm.built
    m, d = cm.model, cm._data
    d.qpos[:] = samples.qpos[i]
    mujoco.mj_kinematics(m, d)
    tcp = d.site_xpos[built.tcp_site]
    best, best_d = None, np.inf
    for p in built.cell.parts:
        body = m.body(p).id
        geoms = np.flatnonzero(m.geom_bodyid == body)
        reach = float(np.max(np.linalg.norm(m.geom_pos[geoms], axis=1) + m.geom_rbound[geoms]))
        dist = float(np.linalg.norm(d.xpos[body] - tcp))
        if dist <= reach + PICK_REACH_M and dist < best_d:
            best, best_d = p, dist
    return best


def allowed_mask(c: Contacts, allowed: Sequence[AllowedContact]) -> NDArray[np.bool_]:
    ok = np.zeros(c.s.size, bool)
    for rule in allowed:
        if c.s.size:
            ok |= rule.mask(c.s, c.g1, c.g2, c.dist)
    return ok


def mount_overlaps(cm: CollisionModel) -> list[tuple[int, int, str]]:
    """The tool's geoms that overlap a geom of the link before the one the tool is mounted on at
    every angle of the joint between them: ``(tool geom, link geom, reason)``.

    The tool is welded to the last link, so its pose relative to the link before depends on
    that one joint only; a pair that overlaps at every angle of its range (swept every
    :data:`MOUNT_SWEEP_STEP_DEG`, deeper than the collision tolerance each time) is the model's
    shapes meeting at the mount (a link capsule's cap reaching past the flange face into the
    tool's adapter), no place a motion can reach or avoid: MoveIt's "always in collision" pair.
    A pair that overlaps at some angles only stays a collision. Computed once per check model.
    """
    cached = getattr(cm, "_mount_overlaps", None)
    if cached is not None:
        return list(cached)
    found: list[tuple[int, int, str]] = []
    for robot in cm.robots:
        found += _mount_overlaps(cm, robot)
    cm._mount_overlaps = tuple(found)  # type: ignore[attr-defined]
    return found


def _mount_overlaps(cm: CollisionModel, robot: str) -> list[tuple[int, int, str]]:
    """:func:`mount_overlaps` of one robot's tool."""
    mujoco = mujoco_module()
    m = cm.model
    tool = sorted(g for g, cg in cm.geoms.items() if cg.role == TOOL and cg.robot == robot)
    found: list[tuple[int, int, str]] = []
    if tool:
        body = int(m.geom_bodyid[tool[0]])
        while body != 0 and m.body_jntnum[body] == 0:  # up to the link the tool is welded to
            body = int(m.body_parentid[body])
        before = int(m.body_parentid[body])
        link = sorted(g for g, cg in cm.geoms.items()
                      if cg.role == LINK and cg.robot == robot
                      and int(m.geom_bodyid[g]) == before)
        if body != 0 and m.body_jntnum[body] == 1 and link:
            joint = int(m.body_jntadr[body])
            lo, hi = ((float(m.jnt_range[joint, 0]), float(m.jnt_range[joint, 1]))
                      if m.jnt_limited[joint] else (-np.pi, np.pi))
            hi = min(hi, lo + 2 * np.pi)  # the pose repeats after a turn
            angles = np.linspace(lo, hi, max(2, int(np.ceil(
                np.degrees(hi - lo) / MOUNT_SWEEP_STEP_DEG)) + 1))
            d = mujoco.MjData(m)
            adr = int(m.jnt_qposadr[joint])
            worst = {(a, b): -np.inf for a in tool for b in link}
            fromto = np.zeros(6)
            for angle in angles:
                d.qpos[:] = m.qpos0
                d.qpos[adr] = angle
                mujoco.mj_kinematics(m, d)
                for (a, b), w in worst.items():
                    if w > -PENETRATION_TOLERANCE_M:
                        continue  # already clear at some angle
                    dist = mujoco.mj_geomDistance(m, d, a, b, 1.0, fromto)
                    worst[(a, b)] = max(w, float(dist))
            joint_name = m.joint(joint).name.removeprefix(f"{robot}/")
            for (a, b), w in worst.items():
                if w <= -PENETRATION_TOLERANCE_M:
                    found.append((a, b, f"{cm.geoms[a].name} overlaps {cm.geoms[b].name} at "
                                  f"every angle of {joint_name} (at least {-w * 1e3:.1f} mm): "
                                  "the model's shapes meeting at the tool mount"))
    return found
