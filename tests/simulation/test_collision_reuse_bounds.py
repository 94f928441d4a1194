"""A variant's collisions decided from its reference's scan (:mod:`sim.simulation.
collision_reuse`). Specification: what it reports is what the full check
(:func:`~sim.simulation.collisions.check_motion`) reports for the variant's motion, bit for
bit; and it scans every coarse interval the full check scans sample by sample (so that a
``[]`` it reports is the full check's ``[]``).

The motions are generated, not planned: the LR Mate 200iC/5L with the MIG torch on the weld
table, a reference whose j2 lowers the torch toward the base plate by a drawn angle (from
well clear of it to through it and the table), j1 and j5 swinging, and a variant that is the
reference plus a drawn deviation (an offset and a sine per joint: within a tracking error, or
far enough that the full check must run). The oracle is the full check itself, on the
variant's own samples.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.scenarios import joint_phase, write_scenario

from sim.scenario import load_scenario
from sim.simulation import collision_reuse as cr
from sim.simulation import collisions as col
from sim.simulation.allowed_contacts import allowed_contacts
from sim.simulation.collision_model import CollisionModel, MotionSamples, coarse_scan
from sim.simulation.compile import build

ROWS = [[0, 20, -60, 0, -30, 0], [0, 8, -60, 0, -30, 0]]
DT = 0.002
T = 1.0
NAMES, SEAMS, WEAVES = ["move"], [None], [0.0]


@pytest.fixture(scope="module")
def cell(tmp_path_factory: pytest.TempPathFactory):
    path = write_scenario(Path(tmp_path_factory.mktemp("reuse_bounds")), "lrmate200ic5l",
                          [joint_phase(ROWS, time_s=[0.0, 1.0])], cell="weld_table",
                          tool="mig_torch", payload_kg=1.0)
    built = build(load_scenario(path))
    return built, CollisionModel(built)


def _reference(t: np.ndarray, lower: float, swing: float, wrist: float) -> np.ndarray:
    """Joint positions (N, 6), rad: j2 lowered by ``lower`` (smoothstep), j1 swung by
    ``swing``, j5 waving by ``wrist``."""
    s = t / T
    step = s * s * (3.0 - 2.0 * s)
    q = np.tile(np.deg2rad(ROWS[0]), (t.size, 1)).astype(float)
    q[:, 1] += np.deg2rad(8.0 - 20.0) * step - lower * step
    q[:, 0] += swing * step
    q[:, 4] += wrist * np.sin(2.0 * np.pi * 1.5 * s)
    return q


def _samples(built, q: np.ndarray) -> MotionSamples:
    n = q.shape[0]
    qpos = np.tile(built.model.qpos0, (n, 1))
    qpos[:, built.robot_qpos] = q
    zeros = np.zeros(n, bool)
    return MotionSamples(DT * np.arange(n), qpos, np.zeros(n, int), zeros, zeros.copy())


def _case(built, lower, swing, wrist, offset, amp, freq):
    t = DT * np.arange(int(round(T / DT)) + 1)
    q_ref = _reference(t, lower, swing, wrist)
    dev = np.asarray(offset)[None, :] + np.asarray(amp)[None, :] * np.sin(
        2.0 * np.pi * np.asarray(freq)[None, :] * t[:, None])
    variant = _samples(built, q_ref + dev)
    coarse = col.coarse_samples(variant)
    return variant, coarse, q_ref[coarse]


def _full_intervals(cm, variant, coarse):
    allowed = allowed_contacts(cm, variant, SEAMS, WEAVES)
    return set(col._intervals_to_check(cm, variant, coarse,
                                       coarse_scan(cm, variant.qpos, coarse), allowed)), allowed


def _scanned(cm, variant, coarse, q_ref, allowed):
    ref = cr.reference_scan(cm, variant, coarse, q_ref)
    got = cr.scanned_intervals(cm, ref, variant, coarse, allowed)
    return None if got is None else set(got)


unit = st.tuples(*[st.floats(-1.0, 1.0)] * 6)
#: A deviation's scale, rad: within a tracking error (decided from the reference's scan,
#: three times in four), or far from the reference (checked in full).
scales = st.sampled_from([3e-5, 3e-5, 3e-5, 0.03])


@settings(max_examples=20, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lower=st.floats(-0.05, 0.45), swing=st.floats(-0.6, 0.6), wrist=st.floats(0.0, 0.8),
       scale=scales, offset=unit, amp=unit, freq=st.tuples(*[st.floats(0.0, 20.0)] * 6))
def test_a_variant_checked_from_its_reference_reports_what_the_full_check_reports(
        cell, lower, swing, wrist, scale, offset, amp, freq):
    built, cm = cell
    cr.clear_cache()
    variant, coarse, q_ref = _case(built, lower, swing, wrist, scale * np.asarray(offset),
                                   scale * np.asarray(amp), freq)
    full, allowed = _full_intervals(cm, variant, coarse)
    scanned = _scanned(cm, variant, coarse, q_ref, allowed)
    # every interval the full check scans sample by sample is scanned (None: checked in full)
    assert scanned is None or full <= scanned, sorted(full - scanned)[:5]
    oracle = col.check_motion(built, variant, NAMES, SEAMS, with_clearance=False,
                              weaves=WEAVES)
    found, reasons = cr.collisions_from_reference(built, variant, NAMES, SEAMS, WEAVES, q_ref,
                                                  cm)
    assert found == oracle.collisions
    assert reasons == oracle.allowed


def test_the_generated_motions_span_clear_colliding_and_strayed_variants(cell):
    """The cases above include a reference that hits the plate, a variant within a tracking
    error that is decided from the reference's scan alone, and one checked in full."""
    built, cm = cell
    cr.clear_cache()
    hit = _case(built, 0.3, 0.0, 0.0, [0.0] * 6, [1e-4] * 6, [5.0] * 6)
    assert col.check_motion(built, hit[0], NAMES, SEAMS, with_clearance=False,
                            weaves=WEAVES).collisions
    near = _case(built, 0.0, 0.3, 0.5, [2e-5] * 6, [2e-5] * 6, [7.0] * 6)
    allowed = allowed_contacts(cm, near[0], SEAMS, WEAVES)
    assert _scanned(cm, *near, allowed) is not None
    assert cr.collisions_from_reference(built, *near[0:1], NAMES, SEAMS, WEAVES, near[2],
                                        cm)[0] == []
    assert cr.STATS["full"] == 0
    strayed = _case(built, 0.0, 0.3, 0.5, [0.02] * 6, [0.0] * 6, [0.0] * 6)
    assert _scanned(cm, *strayed, allowed) is None


def test_a_bound_without_the_anchors_gap_is_caught(cell, monkeypatch):
    """Planted fault: the reference's distance at an anchor taken for its distance at every
    coarse sample the anchor bounds (the gap between the two dropped). As the torch comes down
    to the plate the pairs get closer than their anchor's distance, and intervals the full
    check scans are no longer scanned."""
    built, cm = cell
    case = _case(built, 0.25, 0.0, 0.0, [0.0] * 6, [0.0] * 6, [0.0] * 6)
    full, allowed = _full_intervals(cm, *case[:2])
    cr.clear_cache()
    assert full <= _scanned(cm, *case, allowed)
    real = cr.anchor_samples
    monkeypatch.setattr(cr, "anchor_samples",
                        lambda cm_, q: (real(cm_, q)[0], np.zeros(q.shape[0])))
    cr.clear_cache()
    assert not full <= _scanned(cm, *case, allowed), "the containment check missed the fault"
