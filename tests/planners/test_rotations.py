"""Tool-frame orientation laws (planners.rotations), seed 003 eq. (8), (19)-(24).

Independent references: scipy's quaternion Slerp for the geodesic law, scipy rotation vectors
for Rodrigues' formula, finite differences of R(u) for the angular velocity, and the seed's
eq. (19)-(21) evaluated with the math module in degrees.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp

from planners.errors import PlannerError
from planners.rotations import (
    AxisCarriedOrientation,
    GeodesicOrientation,
    InvalidOrientationError,
    SphericalVersorOrientation,
    angular_velocity,
    as_rotation,
    axis_angle_matrix,
    spherical_angles,
    spherical_versor,
)

rotvecs = st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3).map(np.array)


def _orthonormal(R: np.ndarray, tol: float = 1e-12) -> None:
    RtR = np.swapaxes(R, -1, -2) @ R
    assert np.max(np.abs(RtR - np.eye(3))) < tol
    assert np.max(np.abs(np.linalg.det(R) - 1.0)) < tol


def _fd_angular_velocity(law, u: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """w from log(R(u+h) R(u-h)^T) / 2h (base frame)."""
    Rp, _ = law.evaluate(u + h)
    Rm, _ = law.evaluate(u - h)
    return Rotation.from_matrix(Rp @ np.swapaxes(Rm, -1, -2)).as_rotvec() / (2 * h)


def test_axis_angle_matches_scipy() -> None:
    k = np.array([0.3, -0.5, 0.8])
    th = np.linspace(-4, 4, 9)
    ref = Rotation.from_rotvec(th[:, None] * k / np.linalg.norm(k)).as_matrix()
    assert np.allclose(axis_angle_matrix(k, th), ref, atol=1e-14)


def test_angular_velocity_of_constant_axis_spin() -> None:
    k = np.array([1.0, 2.0, -2.0]) / 3.0
    w = 0.7
    t = np.linspace(0, 2, 5)
    R0 = Rotation.from_rotvec([0.2, 0.1, -0.4]).as_matrix()
    R = axis_angle_matrix(k, w * t) @ R0
    dR = w * np.cross(k, R, axisa=0, axisb=-2, axisc=-2)  # d/dt = [w k]x R
    assert np.allclose(angular_velocity(R, dR), w * k, atol=1e-14)


@settings(max_examples=40, deadline=None)
@given(rotvecs, rotvecs)
def test_geodesic_equals_quaternion_slerp(w0: np.ndarray, w1: np.ndarray) -> None:
    R0, R1 = Rotation.from_rotvec(w0).as_matrix(), Rotation.from_rotvec(w1).as_matrix()
    law = GeodesicOrientation(R0, R1)
    u = np.linspace(0, 1, 11)
    R, _ = law.evaluate(u)
    _orthonormal(R)
    if law.angle < np.pi - 1e-6:      # the half-turn has two shortest arcs
        ref = Slerp([0, 1], Rotation.from_matrix([R0, R1]))(u).as_matrix()
        assert np.allclose(R, ref, atol=1e-10)
    assert np.allclose(R[-1], R1, atol=1e-12)
    assert np.allclose(R[0], R0, atol=1e-14)
    um = np.linspace(0.05, 0.95, 7)
    assert np.allclose(angular_velocity(*law.evaluate(um)), _fd_angular_velocity(law, um), atol=1e-7)


def test_carry_keeps_angles_to_the_seam() -> None:
    """Carried frame: its components in the rotating (radial, tangent, axis) frame stay constant."""
    axis = np.array([0.0, 0.0, 1.0])
    R0 = Rotation.from_euler("zyx", [0.3, -0.6, 0.2]).as_matrix()
    law = AxisCarriedOrientation(R0, axis, 1.5 * np.pi)
    u = np.linspace(0, 1, 13)
    R, dR = law.evaluate(u)
    _orthonormal(R)
    seam = axis_angle_matrix(axis, u * 1.5 * np.pi)     # radial/tangent/axis frame of the arc
    local = np.swapaxes(seam, -1, -2) @ R
    assert np.allclose(local, R0, atol=1e-14)
    assert np.allclose(angular_velocity(R, dR), 1.5 * np.pi * axis, atol=1e-13)
    assert np.allclose(angular_velocity(R[1:-1], dR[1:-1]), _fd_angular_velocity(law, u[1:-1]), atol=1e-7)


def test_seed_versor_example_eq_19_to_21() -> None:
    """Seed 003 eq. (19)-(21): a from (varphi, phi) = (0, 90 deg) to (90, 45 deg), N = 10."""
    a0 = spherical_versor(0.0, np.pi / 2)
    a1 = spherical_versor(np.pi / 2, np.pi / 4)
    # right-handed frames with these approach vectors (n = o x a)
    o0 = np.array([0.0, 1.0, 0.0])
    o1 = np.array([-1.0, 0.0, 0.0])
    R0 = np.column_stack([np.cross(o0, a0), o0, a0])
    R1 = np.column_stack([np.cross(o1, a1), o1, a1])
    law = SphericalVersorOrientation(R0, R1)
    N = 10
    u = np.arange(N + 1) / N
    R, _ = law.evaluate(u)
    _orthonormal(R)
    d = math.radians
    for l in range(N + 1):
        a_seed = [math.sin(d(90 - l * 4.5)) * math.cos(d(0 + l * 9)),
                  math.sin(d(90 - l * 4.5)) * math.sin(d(0 + l * 9)),
                  math.cos(d(90 - l * 4.5))]
        assert np.allclose(R[l, :, 2], a_seed, atol=1e-15)
    assert np.allclose(law.angles[2, 2:], [d(90), d(-45)], atol=1e-15)
    assert np.allclose(R[0], R0, atol=1e-14) and np.allclose(R[-1], R1, atol=1e-14)
    raw = law.raw_versors(u)
    assert np.allclose(np.linalg.norm(raw, axis=-2), 1.0, atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(rotvecs, st.lists(st.floats(-0.8, 0.8), min_size=3, max_size=3).map(np.array))
def test_spherical_versor_law_orthonormal_and_rates(w0: np.ndarray, dw: np.ndarray) -> None:
    R0 = Rotation.from_rotvec(w0).as_matrix()
    R1 = Rotation.from_rotvec(dw).as_matrix() @ R0
    try:
        law = SphericalVersorOrientation(R0, R1)
    except InvalidOrientationError:
        return          # the seed's scheme can degenerate; that case is tested separately
    u = np.linspace(0, 1, 21)
    R, dR = law.evaluate(u)
    _orthonormal(R)
    assert np.allclose(R[0], R0, atol=1e-12) and np.allclose(R[-1], R1, atol=1e-12)
    um = np.linspace(0.05, 0.95, 5)
    ref = _fd_angular_velocity(law, um)
    assert np.allclose(angular_velocity(*law.evaluate(um)), ref, atol=1e-6 * (1 + np.abs(ref).max()))


def test_spherical_versor_law_degenerate_case() -> None:
    """a goes z -> x while o goes x -> z: half-way both are (x + z)/sqrt 2, no frame exists."""
    R0 = np.column_stack([[0, -1, 0], [1, 0, 0], [0, 0, 1]]).astype(float)
    R1 = np.column_stack([[0, 1, 0], [0, 0, 1], [1, 0, 0]]).astype(float)
    with pytest.raises(InvalidOrientationError, match="^orientation: .*geodesic"):
        SphericalVersorOrientation(R0, R1)
    GeodesicOrientation(R0, R1)   # the geodesic law has no such problem


def test_spherical_angles_round_trip() -> None:
    rng = np.random.default_rng(3)
    v = rng.normal(size=(50, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    assert np.allclose(spherical_versor(*spherical_angles(v)), v, atol=1e-15)


@pytest.mark.parametrize("R, msg", [
    (np.eye(3) * 1.01, "not orthonormal"),
    (np.diag([1.0, 1.0, -1.0]), "reflection"),
    (np.full((3, 3), np.nan), "NaN"),
    (np.eye(4), "shape"),
    ("x", "3x3"),
])
def test_bad_rotation_inputs(R, msg: str) -> None:
    with pytest.raises(InvalidOrientationError, match=f"^rotation_start: .*{msg}") as e:
        as_rotation(R, "rotation_start")
    assert isinstance(e.value, PlannerError) and "\n" not in str(e.value)


def test_nearly_orthonormal_input_is_projected() -> None:
    R = Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix() + 1e-8
    P = as_rotation(R)
    _orthonormal(P, 1e-14)
    assert np.max(np.abs(P - R)) < 1e-7
