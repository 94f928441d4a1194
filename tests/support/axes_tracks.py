"""A robot on a floor track welding a seam longer than its reach (issue 28's third acceptance
test), and the momentum balance that judges the track's force.

:class:`TrackCase`: the LR Mate 200iC/5L with the MIG torch on the 4 m track's carriage (the
track on the floor at ``x = track_x_mm``, its travel along the world's x), a table and on it a
T of two plates (flange and web) ``length_mm`` long (2-3.5 m), ``side_mm`` beside the track; the
fillet along the web's foot, work angle 45 deg. The scenario: the track alone moves the robot,
its arm held still, to 200 mm behind the seam's start (``shuttle``); a joint move to a ready
pose; a joint move 20 mm back from the seam's start; a straight touch; the weld in one pass
with ``follow = "track"``.

:func:`momentum_balance`: the track's force from the motion of everything it carries: the
bodies below its carriage (the carriage, the robot's links, the torch) placed by MuJoCo's
forward kinematics of the RECORDED reference ``q_ref`` (``xipos``, ``body_mass``: the compiled
model's geometry, not its dynamics), their centres of mass differenced twice in time, summed
``sum m_i a_i`` and projected on the track's axis, plus the armature ``rotor ratio^2 qdd`` and
the Coulomb friction of the mechanism file. No inverse dynamics of the simulator's is used.

Tolerance of the finite differences: the second difference ``(x(t+h) - 2 x(t) + x(t-h)) / h^2``
is the acceleration averaged over ``[t-h, t+h]`` with a hat weight, exactly (positions are C1).
Compared with the Simpson-weighted samples ``(R(t-h) + 10 R(t) + R(t+h)) / 12`` of the force
``R`` it predicts (``tau_id`` less armature and friction), the two agree to ``O(h^4)`` where the
acceleration is smooth; where it jumps (a phase or segment boundary of the reference) they
differ by at most the jump, which the second difference of ``R`` measures. So each sample is
allowed ``1e-6 * peak + |R(t+h) - 2 R(t) + R(t-h)|``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

from support.axes_cells import HOME_DEG, TRACK_FILE, mechanism_file, pose, track_cell
from support.scenarios import joint_phase, scenario_text
from support.seam_oracle import SeamGeom

#: Height of the flange's top above the floor, mm; the web's height, mm.
FLANGE_TOP_MM = 560.0
WEB_MM = 150.0
READY_DEG = ((30.0, 4.0, -25.0, 0.0, -75.0, 0.0), (60.0, 8.0, -30.0, 0.0, -60.0, 0.0))


@dataclass(frozen=True)
class TrackCase:
    """One generated long weld on a track (module docstring); mm, mm/s."""

    length_mm: float
    side_mm: float
    speed: float
    track_x_mm: float

    def __str__(self) -> str:
        return (f"{self.length_mm:.0f} mm fillet {self.side_mm:.0f} mm beside the track at x "
                f"{self.track_x_mm:.0f}, {self.speed:.1f} mm/s")

    def objects(self) -> list[dict[str, Any]]:
        L, y, z = self.length_mm, self.side_mm, FLANGE_TOP_MM
        x = self.track_x_mm
        return [dict(name="table", shape="box", size_mm=[L + 600.0, 400.0, z - 10.0],
                     pos_mm=[x, y + 50.0, (z - 10.0) / 2]),
                dict(name="flange", shape="box", size_mm=[L + 100.0, 150.0, 10.0],
                     pos_mm=[x, y, z - 5.0], role="workpiece"),
                dict(name="web", shape="box", size_mm=[L + 100.0, 10.0, WEB_MM],
                     pos_mm=[x, y, z + WEB_MM / 2], role="workpiece")]

    def seam_points_mm(self) -> list[list[float]]:
        """In the web's frame: along its foot on the track's side, in +x."""
        h = self.length_mm / 2
        return [[-h, -5.0, -WEB_MM / 2], [h, -5.0, -WEB_MM / 2]]

    def write(self, folder: Path) -> Path:
        folder.mkdir(parents=True, exist_ok=True)
        seam = dict(name="fillet", object="web", kind="line", points_mm=self.seam_points_mm(),
                    normal=[0, -1, 0], joins=["flange"], work_angle_deg=45)
        (folder / "cell.toml").write_text(track_cell((self.track_x_mm, 0.0, 0.0),
                                                     -self.length_mm / 2, self.objects(),
                                                     [seam]))
        H = list(HOME_DEG)
        phases = [
            joint_phase([H, H], name="shuttle", time_s=[0.0, 2.0],
                        axes={"track_travel_mm": -self.length_mm / 2 - 200.0}),
            joint_phase([list(r) for r in READY_DEG], name="ready", durations_s=[1.0, 1.0]),
            dict(name="to_seam", planner="434", durations_s=[1.5], to_seam="fillet",
                 approach_mm=20.0),
            dict(name="touch", kind="linear", to_seam="fillet", orientation="seam",
                 speed_mm_s=20.0),
            dict(name="weld", kind="linear", seam="fillet", orientation="seam",
                 speed_mm_s=self.speed, follow="track")]
        path = folder / "track.toml"
        path.write_text(scenario_text(
            "lrmate200ic5l", phases, name="track_weld", cell="cell.toml", tool="mig_torch",
            actions=[dict(action="arc_on", phase="weld"),
                     dict(action="arc_off", phase="weld", at="end")]))
        return path

    def web_pose(self) -> np.ndarray:
        """The web's frame in the world (static), (4, 4), m."""
        return pose((self.track_x_mm, self.side_mm, FLANGE_TOP_MM + WEB_MM / 2))

    def seam_geom(self) -> SeamGeom:
        """The seam in the web's frame: normal -y, work angle 45, lean left (the file's
        default), no travel angle."""
        return SeamGeom("line", np.asarray(self.seam_points_mm()) * 1e-3,
                        np.array([0.0, -1.0, 0.0]), 45.0, 0.0, side=1)


@st.composite
def track_cases(draw: Any, speeds: tuple[float, float] = (35.0, 50.0)) -> TrackCase:
    """A :class:`TrackCase`: 2-3.5 m, 460-540 mm beside the track, the track at x -300..300."""
    fl = lambda lo, hi: draw(st.floats(lo, hi, allow_nan=False))  # noqa: E731
    return TrackCase(length_mm=fl(2000.0, 3500.0), side_mm=fl(460.0, 540.0),
                     speed=fl(*speeds), track_x_mm=fl(-300.0, 300.0))


@dataclass
class Balance:
    """The momentum balance's verdict: ``ok`` when every sample is within its allowance;
    ``max_rel_smooth`` the largest error relative to the peak where the allowance is the
    floor alone (no jump in the acceleration near)."""

    ok: bool
    max_rel_smooth: float
    report: str


def momentum_balance(scenario: Any, arrays: Any, axis_name: str = "track_travel",
                     column: int = 6, tol: float = 1e-6, mass_scale: float = 1.0) -> Balance:
    """The track's recorded ``tau_id`` against the momentum balance of what it carries (module
    docstring); ``mass_scale`` multiplies the carried masses (a planted fault)."""
    import mujoco

    from sim.robots.drive import COULOMB_SPEED
    from sim.simulation.compile import build

    model = build(scenario).model
    carriage = model.body(axis_name).id

    def carried(b: int) -> bool:
        while b > 0:
            if b == carriage:
                return True
            b = int(model.body_parentid[b])
        return False

    bodies = [b for b in range(model.nbody) if carried(b) and model.body_mass[b] > 0]
    names = [f"robot/j{k}" for k in range(1, 7)] + [axis_name]
    adr = [int(model.joint(n).qposadr[0]) for n in names]
    data = mujoco.MjData(model)
    q_ref = np.asarray(arrays["q_ref"], dtype=float)
    X = np.zeros((len(q_ref), len(bodies), 3))
    for k, q in enumerate(q_ref):
        data.qpos[adr] = q
        mujoco.mj_kinematics(model, data)
        X[k] = data.xipos[bodies]
    t = np.asarray(arrays["t"], dtype=float)
    h = float(t[1] - t[0])
    assert np.allclose(np.diff(t), h, rtol=1e-9, atol=1e-12), "samples not evenly spaced"
    acc = (X[2:] - 2.0 * X[1:-1] + X[:-2]) / h**2
    mech = mechanism_file(TRACK_FILE)
    ax = mech["axes"][0]
    u = np.asarray(ax["axis"], dtype=float)
    u = u / np.linalg.norm(u)  # the track stands unturned: its axis is the world's
    force = mass_scale * np.einsum("b,nbi,i->n", model.body_mass[bodies], acc, u)
    drive = ax["drive"]
    arm = drive["rotor_inertia_kg_m2"] * drive["gear_ratio"] ** 2
    tau = np.asarray(arrays["tau_id"], dtype=float)[:, column]
    qd = np.asarray(arrays["qd_ref"], dtype=float)[:, column]
    qdd = np.asarray(arrays["qdd_ref"], dtype=float)[:, column]
    rigid = tau - arm * qdd - ax["friction_n"] * np.clip(qd / COULOMB_SPEED, -1.0, 1.0)
    simpson = (rigid[:-2] + 10.0 * rigid[1:-1] + rigid[2:]) / 12.0
    jump = np.abs(rigid[2:] - 2.0 * rigid[1:-1] + rigid[:-2])
    peak = float(np.abs(tau).max())
    err = np.abs(force - simpson)
    allowed = tol * peak + jump
    smooth = jump <= tol * peak
    worst = int(np.argmax(err - allowed))
    rel_smooth = float(err[smooth].max() / peak) if smooth.any() else 0.0
    report = (f"carried {model.body_mass[bodies].sum():.4f} kg in {len(bodies)} bodies; worst "
              f"sample t={t[worst + 1]:.3f} s: error {err[worst]:.4g} N, allowed "
              f"{allowed[worst]:.4g} N; peak {peak:.4g} N; smooth samples "
              f"{int(smooth.sum())}/{smooth.size}, largest error there {rel_smooth:.3g} of peak")
    return Balance(bool(np.all(err <= allowed)), rel_smooth, report)


__all__ = ["Balance", "TrackCase", "momentum_balance", "track_cases"]
