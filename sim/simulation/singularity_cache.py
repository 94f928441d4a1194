"""The reference's distance to singularities, kept for the variants of a sweep's plan.

:func:`sim.simulation.metrics.singularity_summary` measures the reference joints ``q_ref``
(the plan's, not the simulated motion's): every variant of one plan (another payload) asks for
the same measures of the same joints again. :func:`singularity_measures` answers from the
latest answers this process computed, by the exact value of the kinematic model (its pickle)
and of the joints (their bits), and computes the rest with
:func:`sim.robots.kinematics.jacobian.singularity_measures`. Each call gets its own arrays.
"""

from __future__ import annotations

import hashlib
import pickle
from collections import OrderedDict
from collections.abc import Hashable
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: How many answers this process keeps, most recent first.
KEPT = 4
_ANSWERS: OrderedDict[Hashable, dict[str, NDArray[np.float64]]] = OrderedDict()


def measures_key(model: Any, q: NDArray[np.float64]) -> Hashable | None:
    """The exact key of a question: the model's pickle and the joints' dtype, shape and bits
    (None for a model that does not pickle: then it is not kept)."""
    try:
        blob = pickle.dumps(model)
    except Exception:  # noqa: BLE001 - an unpicklable model is measured every time
        return None
    q = np.ascontiguousarray(q)
    return (hashlib.sha256(blob).hexdigest(), q.dtype.str, q.shape,
            hashlib.sha256(q.tobytes()).hexdigest())


def singularity_measures(model: Any, q: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
    """:func:`sim.robots.kinematics.jacobian.singularity_measures` of ``model`` at ``q``, kept
    per process (the same bits as computing it again)."""
    from sim.robots.kinematics.jacobian import singularity_measures as measure

    key = measures_key(model, q)
    got = _ANSWERS.get(key) if key is not None else None
    if got is None:
        got = measure(model, q)
        if key is not None:
            _ANSWERS[key] = {k: np.array(v, copy=True) for k, v in got.items()}
            while len(_ANSWERS) > KEPT:
                _ANSWERS.popitem(last=False)
        return got
    _ANSWERS.move_to_end(key)
    return {k: np.array(v, copy=True) for k, v in got.items()}


def clear() -> None:
    """Forget every kept answer."""
    _ANSWERS.clear()


__all__ = ["KEPT", "clear", "measures_key", "singularity_measures"]
