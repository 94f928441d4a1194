"""Collisions of a simulated motion decided from its plan's reference scan: what a metrics-only
sweep variant checks (:func:`collisions_from_reference`).

Variants of one plan (a sweep's payloads at one speed scale) follow the same reference motion;
each simulated motion deviates from it by its tracking error. The reference is scanned once
per plan in a process (:func:`reference_scan`: the coarse scan of :func:`~sim.simulation.
collisions.find_collisions` at the same samples, and every pair of checked geoms closer than
:data:`NEAR_RANGE_M`), kept in a bounded cache keyed by the values it depends on (the check
model's geometry, the reference's positions at the coarse samples and the samples' times and
phases; never an object's identity).

A variant is then checked as :func:`~sim.simulation.collisions.find_collisions` would check it,
without its own coarse scan: a robot geom is at most ``dev = sum_j |q_j - q_ref_j| R_j`` away
from where it is in the reference (``R_j``: :meth:`CollisionModel.reach_from_joint`), so a pair
is at least its reference distance less ``2 dev`` apart in the variant. Every coarse interval in
which the variant's own scan could find a risky pair is then also found from the reference's
distances less ``2 dev`` (:func:`~sim.simulation.collisions._intervals_to_check`, with the
variant's own motion bounds and allowed contacts), so the samples scanned here include every
sample the full check scans. No contact that is not allowed at any of them: the full check
finds no collision either, and ``collisions`` is ``[]``. Any contact left (a collision, or one
the bounds cannot rule out): the full check runs, so what is reported is always exactly what
:func:`~sim.simulation.collisions.check_motion` reports.

Clearance is not computed here (a warning, it changes no verdict and no sweep row); a summary
checked this way has no ``"clearance"``. Cells with parts, mechanisms or several robots
(:func:`reusable`) are checked in full.

Owns the reuse; the search is :mod:`sim.simulation.collisions`'.
May import: the check model, the samples, the search.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sim.simulation import collisions as _col
from sim.simulation.allowed_contacts import allowed_contacts, allowed_mask
from sim.simulation.collision_model import (
    CLEARANCE_RANGE_M,
    DETECTION_MARGIN_M,
    PENETRATION_TOLERANCE_M,
    AllowedContact,
    CollisionModel,
    Contacts,
    MotionSamples,
    coarse_scan,
    mujoco_module,
)
from sim.simulation.compile import BuiltCell

#: Pairs of checked geoms (a robot's links and tool among themselves too) measured in the
#: reference up to this distance, m: the check model's own margin.
NEAR_RANGE_M = DETECTION_MARGIN_M
#: Numerical slack on every distance compared, m (GJK and the contact distances are exact to
#: far better).
SLACK_M = 5e-5
#: Reference scans kept per process.
KEPT = 4

_CACHE: OrderedDict[str, ReferenceScan] = OrderedDict()
#: Reference scans made and found in the cache by this process, and variants whose
#: collisions were checked in full after all (a contact not ruled out, or a cell not reusable).
STATS = {"scans": 0, "hits": 0, "full": 0}


@dataclass(frozen=True)
class ReferenceScan:
    """The reference's pairs at the coarse samples: a lower bound of each listed pair's distance
    (``rows``; pairs not listed: at least :data:`NEAR_RANGE_M` for a robot's own geoms, at least
    :data:`CLEARANCE_RANGE_M` with the cell), and the reference's positions there."""

    rows: Contacts
    qpos: NDArray[np.float64]


def reusable(built: BuiltCell) -> bool:
    """One robot without parts, mechanisms or external axes: every degree of freedom is one of
    its joints (what :func:`collisions_from_reference` bounds)."""
    cell = built.cell
    return (not cell.partners and not built.part_qpos and not cell.mechanisms
            and len(built.joint_ids) == cell.robot.n_joints
            and built.model.nq == len(built.robot_qpos))


def geometry_key(cm: CollisionModel) -> bytes:
    """Everything of the check models that places and measures the checked geoms: their
    geoms' rows (a geom no check collides with, contype and conaffinity 0 there, counts by
    those two only: a payload's mass and its marker do not change the key), the bodies, joints,
    meshes, exclusions and collision options; no masses."""
    h = hashlib.sha256()
    checked = np.array(sorted(cm.geoms), dtype=int)
    for m in (cm.model, cm.range_model):
        h.update(np.ascontiguousarray(m.geom_contype).tobytes())
        h.update(np.ascontiguousarray(m.geom_conaffinity).tobytes())
        h.update(repr((m.nq, m.nbody, m.ngeom, m.nmesh, int(m.opt.disableflags),
                       int(m.opt.enableflags), m.opt.ccd_iterations, m.opt.ccd_tolerance)
                      ).encode())
        for name in sorted(dir(m)):
            if not name.startswith(("geom_", "body_", "jnt_", "mesh_", "bvh_", "exclude_",
                                     "pair_", "hfield_", "qpos0", "key_qpos")) or any(
                    w in name for w in ("mass", "inertia", "ipos", "iquat", "invweight",
                                        "gravcomp", "rgba", "matid", "user", "friction",
                                        "solref", "solimp", "priority", "solmix")):
                continue
            value = getattr(m, name)
            if isinstance(value, np.ndarray) and name.startswith("geom_") \
                    and value.shape[:1] == (m.ngeom,):
                value = value[checked]
            if isinstance(value, np.ndarray):
                h.update(name.encode())
                h.update(np.ascontiguousarray(value).tobytes())
    for arr in (cm.role, cm.is_work, cm.is_base, cm.robot_of):
        h.update(np.ascontiguousarray(arr).tobytes())
    h.update(repr(sorted((g, cg.name, cg.owner) for g, cg in cm.geoms.items())).encode())
    return h.digest()


def reference_key(cm: CollisionModel, samples: MotionSamples, coarse: NDArray[np.int64],
                  q_ref: NDArray[np.float64]) -> str:
    """The cache key of a reference scan: the geometry, the coarse samples (indices, times,
    phases) and the reference's joint positions there, bit for bit."""
    h = hashlib.sha256(geometry_key(cm))
    for arr in (coarse, samples.t[coarse], samples.phase[coarse], q_ref):
        h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()


def _near_scan(model: Any, qpos: NDArray[np.float64], samples: NDArray[np.int64]) -> Contacts:
    """Every pair ``model`` reports at the given samples with its contact distance."""
    mujoco = mujoco_module()
    data = mujoco.MjData(model)
    out_s, out_g1, out_g2, out_d = [], [], [], []
    for i in samples:
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        n = data.ncon
        if n:
            geom = data.contact.geom[:n]
            out_s.append(np.full(n, i))
            out_g1.append(np.minimum(geom[:, 0], geom[:, 1]))
            out_g2.append(np.maximum(geom[:, 0], geom[:, 1]))
            out_d.append(data.contact.dist[:n].copy())
    if not out_s:
        return Contacts()
    return Contacts(np.concatenate(out_s), np.concatenate(out_g1), np.concatenate(out_g2),
                    np.concatenate(out_d))


def reference_scan(cm: CollisionModel, samples: MotionSamples, coarse: NDArray[np.int64],
                   q_ref: NDArray[np.float64], *, make: bool = True) -> ReferenceScan | None:
    """The reference's scan (module docstring), from the cache when the same reference was
    scanned on the same geometry in this process; None when it was not and not ``make``.
    ``q_ref``: the robot's joint positions of the reference at the coarse samples,
    (len(coarse), n)."""
    key = reference_key(cm, samples, coarse, q_ref)
    hit = _CACHE.get(key)
    if hit is not None:
        _CACHE.move_to_end(key)
        STATS["hits"] += 1
        return hit
    if not make:
        return None
    STATS["scans"] += 1
    qpos = np.tile(cm.built.model.qpos0, (samples.t.size, 1))
    qpos[np.ix_(coarse, np.asarray(cm.built.robot_qpos))] = q_ref
    std = coarse_scan(cm, qpos, coarse)
    # a distance of 0 is a pair touching within the tolerance: at least -tolerance apart
    std.dist[std.dist == 0.0] = -PENETRATION_TOLERANCE_M
    near = _near_scan(cm.model, qpos, coarse)  # every checked pair, margin NEAR_RANGE_M
    # a negative contact distance with a margin is no measure of the depth: the pair
    # penetrates no deeper than the tolerance unless the coarse scan measured it deeper
    near.dist[near.dist < 0.0] = -PENETRATION_TOLERANCE_M
    rows = Contacts.concat([std, near])
    scan = ReferenceScan(rows, qpos[coarse])
    _CACHE[key] = scan
    while len(_CACHE) > KEPT:
        _CACHE.popitem(last=False)
    return scan


def deviation(cm: CollisionModel, qpos: NDArray[np.float64], q_ref: NDArray[np.float64]
              ) -> NDArray[np.float64]:
    """How far any robot geom is from where it is in the reference, m, per row of ``qpos``
    ((M, nq), the variant's positions at the coarse samples) and ``q_ref`` ((M, n))."""
    mujoco = mujoco_module()
    m = cm.built.model
    out = np.zeros(qpos.shape[0])
    for k, (j, adr) in enumerate(zip(cm.built.joint_ids, cm.built.robot_qpos, strict=True)):
        slide = m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE
        out += np.abs(qpos[:, adr] - q_ref[:, k]) * (1.0 if slide else cm.reach_from_joint(int(j)))
    return out


def collisions_from_reference(built: BuiltCell, samples: MotionSamples,
                              phase_names: Sequence[str], phase_seams: Sequence[str | None],
                              weaves: Sequence[float], q_ref: NDArray[np.float64],
                              cm: CollisionModel | None = None, *, scan: bool = True
                              ) -> tuple[list[dict[str, Any]], list[str]]:
    """The collisions :func:`~sim.simulation.collisions.check_motion` reports for ``samples``
    (the variant's simulated motion) and the allowed contacts' reasons, using the reference's
    scan (module docstring). ``q_ref``: the reference's joint positions at
    ``coarse_samples(samples)``; ``scan``: scan the reference when it is not in the cache
    (else check in full: a scan pays off from the second variant of a plan)."""
    cm = cm or CollisionModel(built)
    allowed = allowed_contacts(cm, samples, phase_seams, weaves)
    reasons = sorted({a.reason for a in allowed})
    coarse = _col.coarse_samples(samples)
    if len(coarse) < 2 or not reusable(built):
        return _full(cm, samples, phase_names, allowed), reasons
    ref = reference_scan(cm, samples, coarse, q_ref, make=scan)
    if ref is None or ref.qpos.shape[0] != coarse.size:
        return _full(cm, samples, phase_names, allowed), reasons
    # against the positions the scan was made at (whatever the cache gave back)
    scanned_q = ref.qpos[:, np.asarray(built.robot_qpos)]
    dev = 2.0 * deviation(cm, samples.qpos[coarse], scanned_q) + SLACK_M
    bounds = _col.motion_bound(cm, samples, coarse)
    move = 2.0 * bounds["link"]
    # a pair missing from the reference's rows: its own geoms at NEAR_RANGE_M at least, the
    # cell at CLEARANCE_RANGE_M; unless the deviation bounds both, check it all in full
    if np.any(dev >= NEAR_RANGE_M - PENETRATION_TOLERANCE_M) or np.any(
            move + np.maximum(dev[:-1], dev[1:]) >= CLEARANCE_RANGE_M - PENETRATION_TOLERANCE_M):
        return _full(cm, samples, phase_names, allowed), reasons
    rows = ref.rows
    k = np.searchsorted(coarse, rows.s)
    lower = rows.dist - dev[k]
    keep = lower - 2.0 * float(np.max(move, initial=0.0)) < -PENETRATION_TOLERANCE_M
    shifted = Contacts(rows.s[keep], rows.g1[keep], rows.g2[keep], lower[keep])
    intervals = _col._intervals_to_check(cm, samples, coarse, shifted, allowed)
    fine = np.unique(np.concatenate([np.arange(a, b + 1) for a, b in intervals]
                                    or [np.zeros(0, int)])).astype(int)
    c = cm.scan(samples.qpos, fine)
    if c.select(~allowed_mask(c, allowed)).s.size:  # a collision, or one not ruled out
        return _full(cm, samples, phase_names, allowed), reasons
    return [], reasons


def clear_cache() -> None:
    """Forget every reference scan of this process (and zero :data:`STATS`)."""
    _CACHE.clear()
    STATS.update(scans=0, hits=0, full=0)


def _full(cm: CollisionModel, samples: MotionSamples, phase_names: Sequence[str],
          allowed: list[AllowedContact]) -> list[dict[str, Any]]:
    STATS["full"] += 1
    return _col.find_collisions(cm, samples, phase_names, allowed)


__all__ = ["KEPT", "NEAR_RANGE_M", "SLACK_M", "STATS", "ReferenceScan", "clear_cache",
           "collisions_from_reference", "deviation", "geometry_key", "reference_key",
           "reference_scan", "reusable"]
