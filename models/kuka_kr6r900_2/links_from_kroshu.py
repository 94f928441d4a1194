"""Derive ``robot.toml``'s ``[[links]]`` of the KR 6 R900-2 from the link inertials of
kroshu/kuka_robot_descriptions (``kr6_r900_2_kroshu.urdf``, Apache License 2.0).

That description numbers the same arm in other link frames (Khalil-Dombre's). Both files give
the same joint axis lines for every joint value, with the same signs and zeros (checked here at
200 random configurations), so each link's inertial is carried rigidly from its kroshu frame
to the ROS-Industrial joint frame cellsim uses (``kr6r900_2.urdf``), at q = 0:

    c_A = R_A^T (R_B c_B + p_B - p_A),   I_A = R_A^T R_B I_B R_B^T R_A

with ``(R_A, p_A)`` and ``(R_B, p_B)`` the two frames of joint i in the base frame.

    python models/kuka_kr6r900_2/links_from_kroshu.py   # prints the [[links]] tables
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))

SOURCE = ("kroshu/kuka_robot_descriptions kuka_agilus_support/urdf/kr6_r900_2_macro.xacro at "
          "7766e92a (Apache-2.0), carried into this URDF's joint frame")


def joint_frames(chain) -> list[np.ndarray]:
    """Each joint's frame in the base frame at q = 0, (4, 4)."""
    T, out = np.eye(4), []
    for i in range(chain.n):
        T = T @ chain.origins[i]
        out.append(T.copy())
    return out


def same_arm(a, b, samples: int = 200) -> float:
    """The largest distance between the two chains' joint axis lines and flange points over
    random configurations, m (0 when they describe the same arm with the same zeros)."""
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(samples):
        q = rng.uniform(a.lower, a.upper)
        aa, pa, Ta = a.frames(q)
        ab, pb, Tb = b.frames(q)
        d = pb - pa
        off = np.linalg.norm(d - np.sum(d * aa, axis=1)[:, None] * aa, axis=1)
        worst = max(worst, float(off.max()), float(np.abs(aa - ab).max()),
                    float(np.linalg.norm(Ta[:3, 3] - Tb[:3, 3])))
    return worst


def links() -> list[tuple[float, np.ndarray, np.ndarray]]:
    """``(mass kg, centre of mass mm, [ixx, iyy, izz, ixy, ixz, iyz] kg m^2)`` per link."""
    from sim.robots.kinematics.chain import chain_from_urdf

    a = chain_from_urdf(HERE / "kr6r900_2.urdf")
    b = chain_from_urdf(HERE / "kr6_r900_2_kroshu.urdf", tip="flange")
    gap = same_arm(a, b)
    if gap > 1e-9:
        raise SystemExit(f"the two URDFs are not the same arm ({gap:.3g} m apart)")
    out = []
    for Ta, Tb, (m, c, inertia) in zip(joint_frames(a), joint_frames(b), b.inertials,
                                       strict=True):
        Ra, Rb = Ta[:3, :3], Tb[:3, :3]
        com = Ra.T @ (Rb @ c + Tb[:3, 3] - Ta[:3, 3])
        R = Ra.T @ Rb
        ia = R @ inertia @ R.T
        out.append((m, com * 1e3, np.array([ia[0, 0], ia[1, 1], ia[2, 2], ia[0, 1], ia[0, 2],
                                             ia[1, 2]])))
    return out


def toml_text() -> str:
    parts = []
    for m, c, i in links():
        parts.append("[[links]]\n"
                     f"mass_kg = {m:.10g}\n"
                     f"com_mm = [{', '.join(f'{v:.6f}' for v in c + 0.0)}]\n"
                     f"inertia_kg_m2 = [{', '.join(f'{v:.10g}' for v in i + 0.0)}]\n"
                     f'source = "{SOURCE}"')
    return "\n".join(parts) + "\n"


if __name__ == "__main__":
    print(toml_text(), end="")
