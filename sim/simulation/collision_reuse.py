"""Collisions of a simulated motion decided from its plan's reference scan: what a metrics-only
sweep variant checks (:func:`collisions_from_reference`).

Variants of one plan (a sweep's payloads at one speed scale) follow the same reference motion;
each simulated motion deviates from it by its tracking error. The reference is scanned once
per plan in a process (:func:`reference_scan`), kept in a bounded cache keyed by the values it
depends on (the check model's geometry, the reference's positions at the coarse samples of
:func:`~sim.simulation.collisions.find_collisions` and the samples' times and phases; never an
object's identity). The scan is two passes, both cheaper than a run's coarse scan:

* the *near pass*, at every coarse sample: every pair of checked geoms (a robot's links and
  tool among themselves too) closer than :data:`NEAR_RANGE_M` (one ``mj_collision`` of the
  check model, whose margin that is), with a lower bound of its distance: the least of its
  contact distances and its ``mj_geomDistance``, a penetration as deep as ``mj_geomDistance``
  measures it and at least the tolerance (a contact distance with a margin is no measure of a
  depth); a pair not listed is at least :data:`NEAR_RANGE_M` apart;
* the *ranged pass*, at the *anchor* samples only (:func:`anchor_samples`: the first coarse
  sample, then each one at which some robot geom is more than :data:`ANCHOR_GAP_M` from where
  it is at the anchor before): every pair with the cell closer than
  :data:`CLEARANCE_RANGE_M` (the clearance model), each with its distance (the near pass's
  bound where that is lower); a pair not listed is at least :data:`CLEARANCE_RANGE_M` apart.

A robot geom moves by at most ``sum_j |qa_j - qb_j| R_j`` from joint positions ``qa`` to
``qb`` (``R_j``: :meth:`CollisionModel.reach_from_joint`; :func:`joint_gap`), so a pair's
distance at a coarse sample of the reference is at least its distance at the sample's anchor
less twice the gap between the two, and in the variant at least that less twice the
variant's deviation from the reference there (``dev2``). :func:`lower_bounds` gives each pair
at each coarse sample the near pass's bound where it lists the pair, else the larger of
:data:`NEAR_RANGE_M` and the anchor's bound, less ``dev2``; and a bound for every pair listed
nowhere. Every coarse interval in which the full check could find a risky pair (a pair its
own scan lists at an end, closer than the tolerance once the interval's motion bound is
taken off) is then found from these bounds too: by
:func:`~sim.simulation.collisions._intervals_to_check` (the variant's own motion bounds and
allowed contacts) for the listed pairs, and directly for the pairs listed nowhere. A
robot's pair with itself is listed by the full check's scan only where it touches; one the
near pass does not list cannot touch in the variant unless ``dev2`` reaches
:data:`NEAR_RANGE_M` less the tolerance: then the full check runs. So the samples scanned
here include every sample the full check scans. No contact that is not allowed at any of
them: the full check finds no collision either, and ``collisions`` is ``[]``. Any contact left
(a collision, or one the bounds cannot rule out): the full check runs, so what is reported is
always exactly what :func:`~sim.simulation.collisions.check_motion` reports.

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
    mujoco_module,
)
from sim.simulation.compile import BuiltCell

#: Pairs of checked geoms (a robot's links and tool among themselves too) measured in the
#: reference at every coarse sample up to this distance, m: the check model's own margin.
NEAR_RANGE_M = DETECTION_MARGIN_M
#: How far a robot geom may be, in the reference, from where it is at the anchor sample its
#: coarse sample is bounded from, m (:func:`anchor_samples`). Larger: fewer anchors, looser
#: bounds. The weld plate's 8271 coarse samples: 2407 anchors at 1 mm, 957 at 5, 642 at 10;
#: a scan and check of 0.47 s CPU at 1 mm, 0.28 s at 8 mm and 0.27 s at 30 mm, a reusing
#: variant's check 0.05 s up to 8 mm, 0.09 s at 30 mm (its intervals grow).
ANCHOR_GAP_M = 8e-3
#: Numerical slack on every distance compared, m (GJK and the contact distances are exact to
#: far better).
SLACK_M = 5e-5
#: Reference scans kept per process.
KEPT = 4

_CACHE: OrderedDict[str, ReferenceScan] = OrderedDict()
#: Check models kept per process (the latest first), for other payloads of their cells.
_MODELS: list[CollisionModel] = []
#: Reference scans made and found in the cache by this process, and variants whose
#: collisions were checked in full after all (a contact not ruled out, or a cell not reusable).
STATS = {"scans": 0, "hits": 0, "full": 0}


@dataclass(frozen=True)
class ReferenceScan:
    """The reference's scan (module docstring).

    Attributes:
        near: At every coarse sample, each pair closer than :data:`NEAR_RANGE_M` with a lower
            bound of its distance (a pair not listed: at least :data:`NEAR_RANGE_M` apart).
        anchors: Positions in the coarse samples of the anchor samples, increasing, the first
            0 (:func:`anchor_samples`).
        ranged: At the anchor samples, each pair with the cell or a part closer than
            :data:`CLEARANCE_RANGE_M` with a lower bound of its distance (not listed: at least
            :data:`CLEARANCE_RANGE_M` apart).
        gap: How far any robot geom is at each coarse sample from where it is at its anchor
            (the last anchor at or before it), m, (M,).
        qpos: The reference's positions at the coarse samples, (M, nq).
    """

    near: Contacts
    anchors: NDArray[np.int64]
    ranged: Contacts
    gap: NDArray[np.float64]
    qpos: NDArray[np.float64]


def reusable(built: BuiltCell) -> bool:
    """One robot without parts, mechanisms or external axes: every degree of freedom is one of
    its joints (what :func:`collisions_from_reference` bounds)."""
    cell = built.cell
    return (not cell.partners and not built.part_qpos and not cell.mechanisms
            and len(built.joint_ids) == cell.robot.n_joints
            and built.model.nq == len(built.robot_qpos))


#: What a compiled cell's check model reads from it, as whole arrays: the kinematic tree, the
#: geoms' kinds, owners and collision bits, the meshes, exclusions and names.
_SAME_ARRAYS = ("body_parentid", "body_weldid", "body_pos", "body_quat", "jnt_type",
                "jnt_bodyid", "jnt_qposadr", "jnt_pos", "jnt_axis", "qpos0", "geom_type",
                "geom_bodyid", "geom_contype", "geom_conaffinity", "geom_group",
                "geom_dataid", "mesh_vertadr", "mesh_vert", "mesh_face", "exclude_signature",
                "names")
#: ... and for the checked geoms only (a payload's marker, never checked, grows with it).
_SAME_CHECKED = ("geom_size", "geom_pos", "geom_quat", "geom_rbound")


def same_checked_geometry(a: BuiltCell, b: BuiltCell, checked: Sequence[int]) -> bool:
    """Whether a check model made for ``a`` checks ``b`` as one made for ``b`` would: the
    same composed cell (its tree, tool, objects and parts: a sweep's other payload), compiled
    to the same bodies, joints, meshes, exclusions and names, with the ``checked`` geoms
    where and as large as ``a``'s. Masses and unchecked geoms may differ."""
    ma, mb = a.model, b.model
    if a.cell.mjcf is not b.cell.mjcf or a.cell.robot is not b.cell.robot:
        return False
    if any(getattr(ma, n) != getattr(mb, n) for n in ("nq", "nbody", "njnt", "ngeom", "nmesh",
                                                          "nmeshvert", "nmeshface", "nexclude",
                                                          "nnames")):
        return False
    if any(not np.array_equal(getattr(ma, n), getattr(mb, n)) for n in _SAME_ARRAYS):
        return False
    rows = np.asarray(sorted(checked), dtype=int)
    return all(np.array_equal(getattr(ma, n)[rows], getattr(mb, n)[rows])
               for n in _SAME_CHECKED)


def check_model(built: BuiltCell) -> CollisionModel:
    """The check model of ``built``: one made in this process for another payload of the same
    cell (:func:`same_checked_geometry`; :meth:`CollisionModel.rebound`), else a new one
    (kept: the latest :data:`KEPT`). The same checks, bit for bit, without compiling the check
    models again (two compiles per sweep variant)."""
    for cm in _MODELS:
        if same_checked_geometry(cm.built, built, list(cm.geoms)):
            return cm.rebound(built)
    cm = CollisionModel(built)
    _MODELS.insert(0, cm)
    del _MODELS[KEPT:]
    return cm


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
    phases) and the reference's joint positions there, bit for bit (and the anchors' gap)."""
    h = hashlib.sha256(geometry_key(cm))
    h.update(repr((ANCHOR_GAP_M, NEAR_RANGE_M)).encode())
    for arr in (coarse, samples.t[coarse], samples.phase[coarse], q_ref):
        h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()


def joint_gap(cm: CollisionModel, qa: NDArray[np.float64], qb: NDArray[np.float64]
              ) -> NDArray[np.float64]:
    """How far any robot geom moves from the robot's joint positions ``qa`` to ``qb`` (both
    (M, n)), m, per row: ``sum_j |qa_j - qb_j| R_j`` (``R_j``:
    :meth:`CollisionModel.reach_from_joint`; 1 for a slide joint)."""
    mujoco = mujoco_module()
    m = cm.built.model
    out = np.zeros(qa.shape[0])
    for k, j in enumerate(cm.built.joint_ids):
        slide = m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE
        out += np.abs(qa[:, k] - qb[:, k]) * (1.0 if slide else cm.reach_from_joint(int(j)))
    return out


def anchor_samples(cm: CollisionModel, q: NDArray[np.float64]
                   ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Anchors of the reference's coarse samples (joint positions ``q``, (M, n)): the first
    sample, then each sample farther than :data:`ANCHOR_GAP_M` (:func:`joint_gap`) from the
    anchor before it. Returns the anchors' positions and each sample's gap to its anchor."""
    mujoco = mujoco_module()
    m = cm.built.model
    reach = np.array([1.0 if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE
                      else cm.reach_from_joint(int(j)) for j in cm.built.joint_ids])
    anchors = [0]
    gap = np.zeros(q.shape[0])
    a = q[0]
    for i in range(1, q.shape[0]):
        g = float(np.abs(q[i] - a) @ reach)
        if g > ANCHOR_GAP_M:
            anchors.append(i)
            a = q[i]
            g = 0.0
        gap[i] = g
    idx = np.array(anchors, dtype=int)
    # the gaps again, as joint_gap computes them (the same sums as the variant's deviation)
    at = np.searchsorted(idx, np.arange(q.shape[0]), side="right") - 1
    return idx, joint_gap(cm, q, q[idx[at]])


def _near_pass(cm: CollisionModel, qpos: NDArray[np.float64], samples: NDArray[np.int64]
               ) -> Contacts:
    """Every pair the check model (margin :data:`NEAR_RANGE_M`) reports at the given samples,
    with a lower bound of its distance: the least of its contact distances and its
    ``mj_geomDistance`` when these are positive; a contact distance below 0 (with a margin, no
    measure of the depth) counts as a penetration as deep as ``mj_geomDistance`` measures, and
    at least the tolerance."""
    mujoco = mujoco_module()
    model = cm.model
    data = mujoco.MjData(model)
    fromto = np.zeros(6)
    distmax = 2.0 * DETECTION_MARGIN_M
    out_s: list[int] = []
    out_g1: list[int] = []
    out_g2: list[int] = []
    out_d: list[float] = []
    kinematics, collision, geom_distance = (mujoco.mj_kinematics, mujoco.mj_collision,
                                            mujoco.mj_geomDistance)
    dq = data.qpos
    for i in samples.tolist():
        dq[:] = qpos[i]
        kinematics(model, data)
        collision(model, data)
        n = data.ncon
        if not n:
            continue
        geom = data.contact.geom[:n]
        dist = data.contact.dist[:n]
        best: dict[tuple[int, int], float] = {}
        for (x, y), dc in zip(geom.tolist(), dist.tolist(), strict=True):
            key = (x, y) if x < y else (y, x)
            if dc < best.get(key, np.inf):
                best[key] = dc
        for (a, b), dc in best.items():
            dg = geom_distance(model, data, a, b, distmax, fromto)
            out_s.append(i)
            out_g1.append(a)
            out_g2.append(b)
            out_d.append(min(dc, dg) if dc >= 0.0 else min(dg, -PENETRATION_TOLERANCE_M))
    s, g1, g2 = (np.array(x, dtype=int) for x in (out_s, out_g1, out_g2))
    order = np.argsort(_pair_key(cm, s, g1, g2), kind="stable")  # by sample, then pair
    return Contacts(s[order], g1[order], g2[order], np.array(out_d, dtype=float)[order])


def _pair_key(cm: CollisionModel, s: NDArray[np.int64], g1: NDArray[np.int64],
              g2: NDArray[np.int64]) -> NDArray[np.int64]:
    n = max(1, cm.model.ngeom)
    return (s.astype(np.int64) * n + g1) * n + g2


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
    near = _near_pass(cm, qpos, coarse)  # every checked pair, margin NEAR_RANGE_M
    anchors, gap = anchor_samples(cm, q_ref)
    ranged = cm.scan(qpos, coarse[anchors], ranged=True)
    # a negative contact distance with a margin is no measure of the depth: the near pass's
    # bound where it lists the pair (it does wherever the geoms are that close)
    ranged.dist[ranged.dist < 0.0] = -np.inf
    k_near = _pair_key(cm, near.s, near.g1, near.g2)
    k_ranged = _pair_key(cm, ranged.s, ranged.g1, ranged.g2)
    pos = np.searchsorted(k_near, k_ranged)  # near's rows are sorted by sample, then pair
    pos = np.minimum(pos, max(k_near.size - 1, 0))
    listed = (k_near.size > 0) & (k_near[pos] == k_ranged) if k_near.size else \
        np.zeros(k_ranged.size, bool)
    ranged.dist[listed] = np.minimum(ranged.dist[listed], near.dist[pos[listed]])
    ranged.dist[~np.isfinite(ranged.dist)] = -PENETRATION_TOLERANCE_M
    scan = ReferenceScan(near, anchors, ranged, gap, qpos[coarse])
    _CACHE[key] = scan
    while len(_CACHE) > KEPT:
        _CACHE.popitem(last=False)
    return scan


def deviation(cm: CollisionModel, qpos: NDArray[np.float64], q_ref: NDArray[np.float64]
              ) -> NDArray[np.float64]:
    """How far any robot geom is from where it is in the reference, m, per row of ``qpos``
    ((M, nq), the variant's positions at the coarse samples) and ``q_ref`` ((M, n))."""
    return joint_gap(cm, qpos[:, np.asarray(cm.built.robot_qpos)], q_ref)


def lower_bounds(cm: CollisionModel, ref: ReferenceScan, coarse: NDArray[np.int64],
                 dev2: NDArray[np.float64], reach: NDArray[np.float64]
                 ) -> tuple[Contacts, NDArray[np.float64]]:
    """The variant's pairs at the coarse samples that may be within ``reach`` ((M,): how much
    closer any pair may get in the intervals next to each sample) of the tolerance, each with
    a lower bound of its distance there, and the lower bound of every pair not listed, (M,).

    ``dev2``: twice how far any robot geom of the variant is from where it is in the reference
    at each coarse sample, plus the slack. A pair listed by the near pass at a sample: that
    bound less ``dev2``; else at least :data:`NEAR_RANGE_M` apart in the reference and at least
    its anchor's bound (or :data:`CLEARANCE_RANGE_M`, not listed there) less twice the gap to
    the anchor: the larger of the two, less ``dev2``."""
    m_near = np.searchsorted(coarse, ref.near.s)
    lo_near = ref.near.dist - dev2[m_near]
    keep = lo_near - reach[m_near] < -PENETRATION_TOLERANCE_M
    near = Contacts(ref.near.s[keep], ref.near.g1[keep], ref.near.g2[keep], lo_near[keep])
    # each anchor's rows on every coarse sample it anchors
    starts = ref.anchors
    stops = np.append(ref.anchors[1:], coarse.size)
    a_of = np.searchsorted(coarse[starts], ref.ranged.s)
    # a row that cannot be risky anywhere its anchor reaches is left out before it is spread
    gap_hi = np.maximum.reduceat(ref.gap, starts)
    loss_hi = np.maximum.reduceat(dev2 + reach, starts)
    may = np.maximum(NEAR_RANGE_M, ref.ranged.dist - 2.0 * gap_hi[a_of]) - loss_hi[a_of] \
        < -PENETRATION_TOLERANCE_M
    counts = np.where(may, (stops - starts)[a_of], 0)
    rows = np.repeat(np.arange(a_of.size), counts)
    first = np.cumsum(counts) - counts
    m = np.repeat(starts[a_of], counts) + (np.arange(rows.size) - np.repeat(first, counts))
    lo = np.maximum(NEAR_RANGE_M, ref.ranged.dist[rows] - 2.0 * ref.gap[m]) - dev2[m]
    keep = lo - reach[m] < -PENETRATION_TOLERANCE_M
    rows, m, lo = rows[keep], m[keep], lo[keep]
    s, g1, g2 = coarse[m], ref.ranged.g1[rows], ref.ranged.g2[rows]
    # the near pass's bound where it has one (what the pair measures at that very sample)
    measured = np.isin(_pair_key(cm, s, g1, g2),
                       _pair_key(cm, ref.near.s, ref.near.g1, ref.near.g2))
    far = Contacts(s[~measured], g1[~measured], g2[~measured], lo[~measured])
    unlisted = np.maximum(NEAR_RANGE_M, CLEARANCE_RANGE_M - 2.0 * ref.gap) - dev2
    return Contacts.concat([near, far]), unlisted


def scanned_intervals(cm: CollisionModel, ref: ReferenceScan, samples: MotionSamples,
                      coarse: NDArray[np.int64], allowed: Sequence[AllowedContact]
                      ) -> list[tuple[int, int]] | None:
    """The coarse intervals ``(first, last sample)`` of the variant ``samples`` to check at
    every sample: every interval :func:`~sim.simulation.collisions.find_collisions` checks so,
    and maybe more (module docstring); None when the variant strays so far from the
    reference that a robot's own pair the near pass does not list may touch."""
    # against the positions the scan was made at (whatever the cache gave back)
    scanned_q = ref.qpos[:, np.asarray(cm.built.robot_qpos)]
    dev2 = 2.0 * deviation(cm, samples.qpos[coarse], scanned_q) + SLACK_M
    # a robot's own pair is listed by the full check's scan only where it touches; one the
    # near pass does not list (at least NEAR_RANGE_M apart) cannot unless the variant strays
    # that far
    if np.any(dev2 >= NEAR_RANGE_M - PENETRATION_TOLERANCE_M):
        return None
    # how much closer a pair gets inside interval k (its two geoms' bounds; one robot)
    move = 2.0 * _col.motion_bound(cm, samples, coarse)["link"]
    reach = np.maximum(np.append(move, 0.0), np.append(0.0, move))
    rows, unlisted = lower_bounds(cm, ref, coarse, dev2, reach)
    intervals = _col._intervals_to_check(cm, samples, coarse, rows, allowed)
    # a pair listed nowhere near: at least `unlisted` apart at each end of the interval
    worst = np.minimum(unlisted[:-1], unlisted[1:]) - move
    extra = [(int(coarse[k]), int(coarse[k + 1]))
             for k in np.flatnonzero(worst < -PENETRATION_TOLERANCE_M)]
    return sorted(set(intervals) | set(extra))


def collisions_from_reference(built: BuiltCell, samples: MotionSamples,
                              phase_names: Sequence[str], phase_seams: Sequence[str | None],
                              weaves: Sequence[float], q_ref: NDArray[np.float64],
                              cm: CollisionModel | None = None, *, scan: bool = True
                              ) -> tuple[list[dict[str, Any]], list[str]]:
    """The collisions :func:`~sim.simulation.collisions.check_motion` reports for ``samples``
    (the variant's simulated motion) and the allowed contacts' reasons, using the reference's
    scan (module docstring). ``q_ref``: the reference's joint positions at
    ``coarse_samples(samples)``; ``scan``: scan the reference when it is not in the cache
    (else check in full)."""
    cm = cm or check_model(built)
    allowed = allowed_contacts(cm, samples, phase_seams, weaves)
    reasons = sorted({a.reason for a in allowed})
    coarse = _col.coarse_samples(samples)
    if len(coarse) < 2 or not reusable(built):
        return _full(cm, samples, phase_names, allowed), reasons
    ref = reference_scan(cm, samples, coarse, q_ref, make=scan)
    if ref is None or ref.qpos.shape[0] != coarse.size:
        return _full(cm, samples, phase_names, allowed), reasons
    intervals = scanned_intervals(cm, ref, samples, coarse, allowed)
    if intervals is None:
        return _full(cm, samples, phase_names, allowed), reasons
    fine = np.unique(np.concatenate([np.arange(a, b + 1) for a, b in intervals]
                                    or [np.zeros(0, int)])).astype(int)
    c = cm.scan(samples.qpos, fine)
    if c.select(~allowed_mask(c, allowed)).s.size:  # a collision, or one not ruled out
        return _full(cm, samples, phase_names, allowed), reasons
    return [], reasons


def clear_cache() -> None:
    """Forget every reference scan and check model of this process (and zero
    :data:`STATS`)."""
    _CACHE.clear()
    _MODELS.clear()
    STATS.update(scans=0, hits=0, full=0)


def _full(cm: CollisionModel, samples: MotionSamples, phase_names: Sequence[str],
          allowed: list[AllowedContact]) -> list[dict[str, Any]]:
    STATS["full"] += 1
    return _col.find_collisions(cm, samples, phase_names, allowed)


__all__ = ["ANCHOR_GAP_M", "KEPT", "NEAR_RANGE_M", "SLACK_M", "STATS", "ReferenceScan",
           "anchor_samples", "check_model", "clear_cache", "collisions_from_reference",
           "deviation", "geometry_key", "joint_gap", "lower_bounds", "reference_key",
           "reference_scan", "reusable", "same_checked_geometry", "scanned_intervals"]
