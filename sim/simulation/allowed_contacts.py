"""The contacts a motion may make, declared rather than guessed (:func:`allowed_contacts`): the
welding wire in the seam's workpieces while the arc is on (up to its radius, the phase's weave
reach and :data:`WIRE_ARC_DEPTH_M`), the torch's touch sensing, the suction cup with the part
it picks, parts resting, lifted off and set down; see :mod:`sim.simulation.collisions` for the
full rules.

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
    PART,
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
    out: list[AllowedContact] = []
    work = frozenset(g for g, cg in cm.geoms.items() if cg.work)
    torch = cell.tool is not None and cell.tool.kind == "torch"
    if work and torch and cell.seam_objects:
        all_work = frozenset().union(*(cm.ids(CELL, obj) for objs in cell.seam_objects.values()
                                       for obj in objs))
        radius = max(float(built.model.geom_size[g, 0]) for g in work)
        # the wire in the joint of the seam it welds, weaving included, while the arc is on
        for k, seam in enumerate(phase_seams):
            when = samples.arc_on & (samples.phase == k)
            if not when.any():
                continue
            objs = cell.seam_objects.get(seam, ()) if seam is not None else ()
            pieces = (frozenset().union(*(cm.ids(CELL, o) for o in objs)) if objs else all_work)
            reach = 0.0 if weaves is None else float(weaves[k])
            depth = radius + reach + WIRE_ARC_DEPTH_M
            weaving = f" + weave {reach * 1e3:.1f} mm" if reach > 0 else ""
            out.append(AllowedContact(
                work, pieces, when, f"wire in the joint of seam {seam!r}, arc on (up to "
                f"{depth * 1e3:.1f} mm: radius{weaving} + {WIRE_ARC_DEPTH_M * 1e3:g} mm)",
                max_depth_m=depth))
        # the wire tip set on a workpiece, arc off included (touch sensing, the tip on the
        # root at a seam's start or end); deeper is a collision
        touch = cell.tool.touch_depth_m
        out.append(AllowedContact(work, all_work, np.ones(n, bool),
                                  f"wire touching a workpiece (up to {(radius + touch) * 1e3:.1f} "
                                  f"mm: radius + touch depth {touch * 1e3:g} mm)",
                                  max_depth_m=radius + touch))
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
