"""What a metrics-only sweep variant reuses from the other variants of its plan, in one worker
process: the plan (:mod:`sim.pipeline.run` keeps it by the scenario without its payload) and
the reference's collision scan (:mod:`sim.simulation.collision_reuse`, kept by the geometry,
the coarse samples and the reference's positions there).

:func:`reuse_collisions` stands in for :func:`sim.pipeline.run.add_collisions` in a variant's
checks: the same ``collisions`` and ``allowed_contacts`` (bit for bit), no ``clearance`` (a
warning check: no verdict and no row of the sweep's table depends on it). ``ENABLED`` turns
the reuse off for this process (a variant is then checked as a run checks it).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Reuse the plan's scan in metrics-only variants of this process (a plan's first variant
#: scans its reference: cheaper than a run's own check, so even a plan with one variant in a
#: process gains).
ENABLED = True


def reuse_collisions(summary: dict[str, Any], built: Any, motion: Any,
                     arrays: dict[str, NDArray[Any]]) -> None:
    """:func:`sim.pipeline.run.add_collisions` for a metrics-only variant (module docstring):
    ``collisions``, ``allowed_contacts`` and ``collision_check_s`` in the summary, and
    ``clearance_skipped`` (True) instead of ``clearance``."""
    from sim.simulation.collision_reuse import collisions_from_reference
    from sim.simulation.collisions import (
        check_motion,
        coarse_samples,
        phase_seams,
        phase_weaves,
        samples_from_arrays,
    )

    start = time.perf_counter()
    samples = samples_from_arrays(arrays, motion)
    names = [pm.name for pm in motion.phases]
    if not np.all(np.isfinite(samples.qpos)):  # the full check names the sample
        check_motion(built, samples, names, phase_seams(motion), weaves=phase_weaves(motion))
    coarse = coarse_samples(samples)
    q_ref = np.asarray(motion.at(samples.t[coarse]).q, dtype=float)
    found, reasons = collisions_from_reference(built, samples, names, phase_seams(motion),
                                               phase_weaves(motion), q_ref)
    summary["collisions"] = found
    summary["clearance_skipped"] = True
    summary["allowed_contacts"] = reasons
    summary["collision_check_s"] = time.perf_counter() - start


def collide_hook() -> Any:
    """What a metrics-only variant gives :func:`sim.pipeline.run.evaluate_scenarios` as
    ``collide``: :func:`reuse_collisions`, or None (a run's own check) when ``ENABLED`` is
    off."""
    return reuse_collisions if ENABLED else None


__all__ = ["ENABLED", "collide_hook", "reuse_collisions"]
