"""Corner blends (:mod:`planners.blend`): the tool's turn inside a corner zone.

The oracle is scipy's rotations: a frame's angular velocity is taken from two nearby frames
of the law (``log(R(u + d) R(u)^T) / d``), not from the law's own derivative.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from planners.blend import CornerOrientation

rotvecs = st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3).map(np.array)
rates = st.lists(st.floats(-30.0, 30.0), min_size=3, max_size=3).map(np.array)


def world_rate(law: CornerOrientation, u: float, length: float, d: float = 1e-5) -> np.ndarray:
    """Angular velocity of the law's frame at ``u``, rad per metre of the corner, from frames."""
    R0 = law.evaluate(np.array([u]))[0][0]
    R1 = law.evaluate(np.array([u + d]))[0][0]
    return Rotation.from_matrix(R1 @ R0.T).as_rotvec() / (d * length)


@settings(max_examples=60, deadline=None)
@given(a=rotvecs, b=rotvecs, wa=rates, wb=rates, length=st.floats(1e-3, 0.02))
def test_a_corner_meets_each_move_at_its_frame_and_turning_rate(a, b, wa, wb, length):
    """Generated corners: the blended turn starts on the first move's frame turning at that
    move's rate and ends on the next move's frame turning at its rate (so the tool's angular
    velocity is continuous where the corner meets the moves), and its derivative is the one
    of its frames."""
    Ra, Rb = Rotation.from_rotvec(a).as_matrix(), Rotation.from_rotvec(b).as_matrix()
    law = CornerOrientation(Ra, Rb, wa, wb, length)
    R, dR = law.evaluate(np.array([0.0, 0.37, 1.0]))
    assert np.allclose(R[0], Ra, atol=1e-9) and np.allclose(R[2], Rb, atol=1e-9)
    assert np.allclose(world_rate(law, 0.0, length), wa, atol=1e-3 * (1 + np.abs(wa).max()))
    assert np.allclose(world_rate(law, 1.0 - 1e-5, length), wb,
                       atol=1e-3 * (1 + np.abs(wb).max()))
    d = 1e-6
    fd = (law.evaluate(np.array([0.37 + d]))[0][0] - law.evaluate(np.array([0.37 - d]))[0][0])
    assert np.allclose(dR[1], fd / (2 * d), atol=1e-5 * (1 + np.abs(dR[1]).max()))


def test_a_corner_from_rest_jumps_the_rate_of_a_turning_move():
    """The planted fault the oracle must see: the turn from rest (no rates), between two moves
    that turn, starts at rate 0 where the move turned at 10 rad/m."""
    Ra, Rb = np.eye(3), Rotation.from_rotvec([0.0, 0.0, 0.3]).as_matrix()
    w = np.array([0.0, 0.0, 10.0])
    assert np.allclose(world_rate(CornerOrientation(Ra, Rb, w, w, 0.01), 0.0, 0.01), w, atol=0.05)
    assert np.linalg.norm(world_rate(CornerOrientation(Ra, Rb), 0.0, 0.01)) < 0.05


def test_without_rates_the_corner_is_a_smoothstep_geodesic():
    """Moves that do not turn (a polyline seam's straight legs): the shortest rotation, its
    angle a quintic smoothstep of u."""
    Rb = Rotation.from_rotvec([0.4, -0.2, 0.9]).as_matrix()
    law = CornerOrientation(np.eye(3), Rb, np.zeros(3), np.zeros(3), 0.01)
    u = np.linspace(0.0, 1.0, 11)
    h = u**3 * (10 - 15 * u + 6 * u * u)
    want = Rotation.from_rotvec(np.outer(h, [0.4, -0.2, 0.9])).as_matrix()
    assert np.allclose(law.evaluate(u)[0], want, atol=1e-9)
    assert law.angle == pytest.approx(np.linalg.norm([0.4, -0.2, 0.9]))
