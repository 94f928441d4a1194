"""Closed-form forward kinematics exactly as the seeds print them.

These are transcriptions of the papers' equations, kept literal so that tests can compare the
MuJoCo models and the inverse kinematics against the seeds themselves.

* :func:`fk_5r`: seed 000 eq. (5) (position and rotation 0_6[R]) for the 5R structure of seed 000
  Table 1 (FANUC LR Mate 100iB, and the 5R welding robot of seed 001 with its own dimensions).
* :func:`fk_fanuc6`: seed 004 eq. (6)-(7) for the FANUC LR Mate 200iC/5L; the tool frame E is
  frame 6 moved ``R6 + r`` along z6 (tool length r = 0 for the bare robot).

All positions are in metres in the seed's base frame 0 (on the J1 axis at the height of J2);
joint values are the seeds' generalized coordinates in radians.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray


def fk_5r(q: ArrayLike, dims: Mapping[str, float]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Tool-point pose of the 5R arm, seed 000 eq. (5).

    Args:
        q: Joint values q1..q5, rad, shape (5,).
        dims: ``l1``, ``d1``, ``l2``, ``l3`` in metres (seed 000 Table 1).

    Returns:
        ``(R, p)``: rotation matrix 0_6[R], shape (3, 3), and tool-point position, m, shape (3,).
    """
    q1, q2, q3, q4, q5 = np.asarray(q, dtype=float)
    l1, d1, l2, l3 = dims["l1"], dims["d1"], dims["l2"], dims["l3"]
    c1, s1 = np.cos(q1), np.sin(q1)
    c5, s5 = np.cos(q5), np.sin(q5)
    c23, s23 = np.cos(q2 + q3), np.sin(q2 + q3)
    c234, s234 = np.cos(q2 + q3 + q4), np.sin(q2 + q3 + q4)
    R = np.array([
        [c234 * c1, s5 * s234 * c1 - c5 * s1, c5 * s234 * c1 + s5 * s1],
        [c234 * s1, s5 * s234 * s1 + c5 * c1, c5 * s234 * s1 - s5 * c1],
        [-s234, c234 * s5, c234 * c5],
    ])
    reach = l1 + d1 * np.sin(q2) + l2 * c23 + l3 * c234
    p = np.array([c1 * reach, s1 * reach, d1 * np.cos(q2) - l2 * s23 - l3 * s234])
    return R, p


def fk_fanuc6(q: ArrayLike, dims: Mapping[str, float], tool_length: float = 0.0
              ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Tool-frame pose of the LR Mate 200iC, seed 004 eq. (6)-(7).

    Args:
        q: theta1..theta6, rad, shape (6,) (seed 004 Table 1; theta2 without the pi/2 offset).
        dims: ``d2``, ``d3``, ``d4``, ``R4``, ``R6`` in metres.
        tool_length: Tool length r along z6 beyond R6, m.

    Returns:
        ``(R, p)``: rotation [s n a] of the tool frame E, shape (3, 3), and its origin, m, (3,).
    """
    t1, t2, t3, t4, t5, t6 = np.asarray(q, dtype=float)
    d2, d3, d4, R4 = dims["d2"], dims["d3"], dims["d4"], dims["R4"]
    R6 = dims["R6"] + tool_length
    c1, s1 = np.cos(t1), np.sin(t1)
    S2 = np.sin(t2)
    C2 = np.cos(t2)
    c4, s4 = np.cos(t4), np.sin(t4)
    c5, s5 = np.cos(t5), np.sin(t5)
    c6, s6 = np.cos(t6), np.sin(t6)
    c23, s23 = np.cos(t2 + t3), np.sin(t2 + t3)
    # eq. (6)
    px = c1 * d2 + R6 * (c5 * c1 * c23 + s5 * (s1 * s4 - c4 * c1 * s23)) - d4 * c1 * s23 \
        + R4 * c1 * c23 - c1 * S2 * d3
    py = d2 * s1 - d4 * s1 * s23 + R6 * (c5 * s1 * c23 - s5 * (c1 * s4 + c4 * s1 * s23)) \
        + R4 * s1 * c23 - d3 * s1 * S2
    pz = C2 * d3 + d4 * c23 + R4 * s23 + R6 * (c5 * s23 + c4 * s5 * c23)
    # eq. (7)
    s = np.array([
        s6 * (c4 * s1 + s4 * c1 * s23) + c6 * (c5 * (s1 * s4 - c4 * c1 * s23) - s5 * c1 * c23),
        -s6 * (c1 * c4 - s4 * s1 * s23) - c6 * (c5 * (c1 * s4 + c4 * s1 * s23) + s5 * s1 * c23),
        -c6 * (s5 * s23 - c4 * c5 * c23) - s4 * s6 * c23,
    ])
    n = np.array([
        c6 * (c4 * s1 + s4 * c1 * s23) - s6 * (c5 * (s1 * s4 - c4 * c1 * s23) - s5 * c1 * c23),
        s6 * (c5 * (c1 * s4 + c4 * s1 * s23) + s5 * s1 * c23) - c6 * (c1 * c4 - s4 * s1 * s23),
        s6 * (s5 * s23 - c4 * c5 * c23) - c6 * s4 * c23,
    ])
    a = np.array([
        s5 * (s1 * s4 - c4 * c1 * s23) + c5 * c1 * c23,
        -s5 * (c1 * s4 + c4 * s1 * s23) + c5 * s1 * c23,
        c5 * s23 + c4 * s5 * c23,
    ])
    return np.column_stack([s, n, a]), np.array([px, py, pz])


def mdh_transform(alpha: float, d: float, theta: float, r: float) -> NDArray[np.float64]:
    """Khalil-Dombre modified DH transform ``j-1 T j``, seed 004 eq. (1); shape (4, 4)."""
    ca, sa = np.cos(alpha), np.sin(alpha)
    ct, st = np.cos(theta), np.sin(theta)
    return np.array([
        [ct, -st, 0.0, d],
        [ca * st, ca * ct, -sa, -r * sa],
        [sa * st, sa * ct, ca, r * ca],
        [0.0, 0.0, 0.0, 1.0],
    ])


def fanuc6_mdh_table(q: Sequence[float], dims: Mapping[str, float]
                     ) -> list[tuple[float, float, float, float]]:
    """Rows (alpha, d, theta, r) of seed 004 Table 1 for joint values ``q`` (rad, m)."""
    t1, t2, t3, t4, t5, t6 = q
    h = np.pi / 2
    return [
        (0.0, 0.0, t1, 0.0),
        (h, dims["d2"], h + t2, 0.0),
        (0.0, dims["d3"], t3, 0.0),
        (h, dims["d4"], t4, dims["R4"]),
        (-h, 0.0, t5, 0.0),
        (h, 0.0, t6, 0.0),
    ]


def fk_fanuc6_mdh(q: ArrayLike, dims: Mapping[str, float], tool_length: float = 0.0
                  ) -> NDArray[np.float64]:
    """Tool frame of the 200iC as the product of seed 004 Table 1's transforms times E, (4, 4).

    A second formulation of :func:`fk_fanuc6` (eq. 2-3), used to cross-check eq. (6)-(7).
    """
    T = np.eye(4)
    for row in fanuc6_mdh_table(list(np.asarray(q, dtype=float)), dims):
        T = T @ mdh_transform(*row)
    E = np.eye(4)
    E[2, 3] = dims["R6"] + tool_length
    return T @ E
