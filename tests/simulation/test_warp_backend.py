"""MuJoCo Warp backend (issue 16): the batched float32 simulation agrees with MuJoCo in C.

A short joint move of each robot, two payloads in one batch (their masses and inertias differ
world by world), simulated by both backends from the same reference and feed-forward. Bounds:
joint paths within 1e-4 rad; each joint's peak and RMS torque within 1 %; every sample's torque
within 1 % of the joint's peak plus the float32 floor of the position servo (kp times the
rounding of the set-point and the joint angle: about 0.4 N m for the 5R's J1, kp = 3.3e6),
except a few steps after a joint's speed crosses the Coulomb friction's linear zone, where
the two engines' implicit steps treat the clamped friction actuator differently.
A drive too weak for its arm (issue 26, one drive everywhere): the Warp worlds hold it where
its motor gives its peak at the motor's own speed, as the MuJoCo backend does, checked with the
motor torque recomputed from the drive's numbers; planted clamp faults show the check bites.
Warp runs on its CPU device here (a GPU where there is one); kernels are compiled once and
cached (~/.cache/warp).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="MuJoCo Warp is not installed (pip install "
                    "'cellsim[warp]')")

from sim.analysis.sizing import rms  # noqa: E402
from sim.cli import main  # noqa: E402
from sim.pipeline.run import RunOptions, evaluate_scenarios  # noqa: E402
from sim.robots.registry import COULOMB_SPEED  # noqa: E402
from sim.scenario import load_scenario  # noqa: E402

#: robot -> target of a 0.8 s joint move from zero, deg
MOVES = {
    "lrmate100ib": [20.0, 15.0, -10.0, 25.0, 30.0],
    "lrmate200ic5l": [20.0, 15.0, -10.0, 25.0, 30.0, 40.0],
    "robot_5r": [-10.0, 30.0, 10.0, -10.0, 5.0],
}
EPS32 = float(np.finfo(np.float32).eps)


def _scenario(tmp_path: Path, robot: str, payload: float = 1.0) -> Path:
    target = np.array(MOVES[robot])
    rows = [[round(float(x), 6) for x in f * target] for f in (0.0, 1 / 3, 2 / 3, 1.0)]
    text = (f'name = "warp_{robot}"\ndescription = "a short joint move for backend parity"\n'
            f'robot = "{robot}"\npayload_kg = {payload}\n\n[[phases]]\nname = "move"\n'
            'planner = "546"\ntime_s = [0.0, 0.2667, 0.5333, 0.8]\njoints_deg = [\n'
            + "".join(f"  {r},\n" for r in rows) + "]\n")
    path = tmp_path / f"warp_{robot}.toml"
    path.write_text(text)
    return path


@pytest.mark.slow
@pytest.mark.parametrize("robot", sorted(MOVES))
def test_warp_matches_mujoco_on_a_short_joint_move(tmp_path, robot):
    base = load_scenario(_scenario(tmp_path, robot))
    variants = [base.scaled(1.0, 1.0), base.scaled(1.0, 3.0)]
    options = dict(video=False, plots=False, progress=False)
    cpu = evaluate_scenarios(variants, RunOptions(**options, backend="mujoco"))
    gpu = evaluate_scenarios(variants, RunOptions(**options, backend="warp"))
    for c, g in zip(cpu, gpu):
        a, b = c.record.arrays, g.record.arrays
        assert g.summary["backend"] == "warp" and a["t"].shape == b["t"].shape
        assert np.abs(a["q"] - b["q"]).max() < 1e-4
        built = c.built
        kp = built.model.actuator_gainprm[built.robot_act, 0]
        for j in range(a["tau"].shape[1]):
            ta, tb = a["tau"][:, j], b["tau"][:, j]
            peak = np.abs(ta).max()
            assert abs(np.abs(tb).max() - peak) <= 0.01 * peak, (j, peak)
            ra, rb = rms(a["t"], ta), rms(a["t"], tb)
            assert abs(rb - ra) <= 0.01 * ra, (j, ra, rb)
            floor = kp[j] * 2 * EPS32 * max(1.0, np.abs(a["q"][:, j]).max())
            off = np.nonzero(np.abs(ta - tb) > 0.01 * peak + floor)[0]
            # except at the steps where the joint's speed crosses the edge of the Coulomb
            # friction's linear zone (|qd| = COULOMB_SPEED): there the friction actuator is
            # clamped on one side and not on the other, and MuJoCo and MuJoCo Warp count its
            # slope differently in the implicit step (a difference in acceleration that dies
            # out within a few steps)
            edge = np.abs(a["qd"][:, j]) - COULOMB_SPEED
            crossings = np.nonzero(np.diff(np.sign(edge)) != 0)[0]
            near = [bool(np.any((k - crossings >= -1) & (k - crossings <= 5))) for k in off]
            assert all(near), (j, off, crossings)
            assert off.size <= 6 * crossings.size, (j, off.size, crossings.size)
        # the payload reached the device world by world: heavier, more torque at J2
    assert np.abs(gpu[1].record.arrays["tau"][:, 1]).max() > \
        np.abs(gpu[0].record.arrays["tau"][:, 1]).max()


@pytest.mark.slow
def test_size_with_the_warp_backend_gives_the_mujoco_table(tmp_path, capsys):
    """Payloads 0 and 2 kg (one model structure: a massless payload body at 0 kg) at two
    speeds (two durations in one batch), no drive saturated: the sweep table agrees with the CPU backend's within the parity bounds."""
    path = _scenario(tmp_path, "robot_5r")
    args = ["size", str(path), "--payload", "0,2", "--speed-scale", "0.75,1", "--workers", "1",
            "--quiet"]
    assert main([*args, "--out", str(tmp_path / "cpu")]) == 0
    assert main([*args, "--out", str(tmp_path / "warp"), "--backend", "warp"]) == 0
    cpu = list(csv.DictReader(open(tmp_path / "cpu" / "sweep.csv")))
    gpu = list(csv.DictReader(open(tmp_path / "warp" / "sweep.csv")))
    assert len(cpu) == len(gpu) == 4 * 5
    for a, b in zip(cpu, gpu):
        assert (a["payload_kg"], a["speed_scale"], a["joint"]) == \
               (b["payload_kg"], b["speed_scale"], b["joint"])
        assert a["verdict"] == b["verdict"] and a["pass"] == b["pass"]
        for key in ("peak_torque_sim_nm", "rms_torque_sim_nm", "peak_torque_id_nm"):
            x, y = float(a[key]), float(b[key])
            assert abs(x - y) <= 0.01 * abs(x) + 1e-9, (key, a["joint"], x, y)
        assert float(a["duration_s"]) == float(b["duration_s"])


@pytest.mark.slow
def test_run_with_the_warp_backend_writes_a_complete_run(tmp_path, capsys):
    path = _scenario(tmp_path, "lrmate100ib")
    out = tmp_path / "run"
    assert main(["run", str(path), "--out", str(out), "--backend", "warp", "--no-video",
                 "--no-plots", "--quiet"]) == 0
    from sim.simulation.runfolder import load_run

    summary = load_run(out).summary
    assert summary["backend"] == "warp" and summary["verdict"] == "pass"


@pytest.mark.slow
def test_a_drive_torque_speed_curve_reaches_the_device(tmp_path):
    """A move fast enough that a drive is held at its torque-speed curve, below its flat peak:
    the Warp worlds get the curve step by step (their force ranges change during the move), so
    the torque applied follows the recorded limit and never exceeds it."""
    base = load_scenario(_scenario(tmp_path, "robot_5r"))
    import dataclasses

    fast = base.scaled(1.6, 1.0)  # past the joints' speed limits: simulated all the same
    fast = dataclasses.replace(fast, simulation=fast.simulation.model_copy(
        update={"enforce_speed_limits": False, "enforce_accel_limits": False}))
    (ev,) = evaluate_scenarios([fast], RunOptions(video=False, plots=False, progress=False,
                                                  backend="warp"))
    a = ev.record.arrays
    flat = ev.built.force_limits[:, 1]
    assert np.any(a["tau_limit"] < flat * (1 - 1e-6)), "the curve never binds: pick a faster move"
    held = (np.abs(a["tau_actuator"]) >= a["tau_limit"] * (1 - 1e-4)) & \
        (a["tau_limit"] < flat * (1 - 1e-6))
    assert held.any(), "no drive is held at its curve: pick a faster move"
    assert np.all(np.abs(a["tau_actuator"]) <= a["tau_limit"] * (1 + 1e-5) + 1e-3)


#: The 5R's J2 drive made too weak for its arm (models/robot_5r/README.md: ratio 160, efficiency
#: 0.8; here a twentieth of its 46 N m peak motor torque, rated half of that, another rotor
#: and a 2500 rpm motor): the arm sags, the drive saturates, and the arm falls faster than the
#: motor's top speed, where the motor has nothing to give.
WEAK_J2 = {"peak": 46.0 / 20, "rated": 46.0 / 40, "ratio": 160.0, "eta": 0.8, "rotor": 1.0e-3,
           "top_rpm": 2500.0}


def _weak_j2(tmp_path: Path):
    d = WEAK_J2
    path = _scenario(tmp_path, "robot_5r")
    path.write_text(path.read_text() + f"\n[drives.j2]\npeak_torque_nm = {d['peak']}\n"
                    f"rated_torque_nm = {d['rated']}\nrotor_inertia_kg_m2 = {d['rotor']}\n"
                    f"max_speed_rpm = {d['top_rpm']}\n")
    return load_scenario(path)


def _motor_excess(arrays) -> np.ndarray:
    """Per sample, J2's motor torque past the motor's peak at the motor's own speed, in peak
    torques, recomputed from the recorded joint torque, speed and acceleration with
    :data:`WEAK_J2`'s numbers: the gear's efficiency on the load torque in the direction power
    flows (the motor drives at standstill), the rotor's inertia on the motor side; the peak
    flat to 70 % of the top speed, then straight down to the rated torque at it, 0 beyond."""
    d = WEAK_J2
    tau, qd, qdd = (arrays[k][:, 1] for k in ("tau", "qd", "qdd"))
    n, eta, rotor, peak, top = d["ratio"], d["eta"], d["rotor"], d["peak"], d["top_rpm"]
    load = tau - rotor * n**2 * qdd
    drives = (load * qd >= 0) | (np.abs(qd) < 1e-3)
    motor = np.where(drives, load / (n * eta), load * eta / n) + rotor * n * qdd
    rpm = np.abs(qd) * n * 60 / (2 * np.pi)
    curve = np.where(rpm <= 0.7 * top, peak, np.where(
        rpm <= top, peak + (d["rated"] - peak) * (rpm - 0.7 * top) / (0.3 * top), 0.0))
    return (np.abs(motor) - curve) / peak


#: float32 state: the step's acceleration from float32 speeds, the torque a float32 clamp
F32_MOTOR_TOL = 1e-4


@pytest.mark.slow
def test_a_saturated_drive_is_held_at_its_motor_peak_at_the_motor_speed(tmp_path):
    """Issue 26, one drive everywhere: the Warp worlds clamp each drive where its motor gives
    its peak at the motor's own speed and acceleration, as the CPU path does. Two payloads in
    one batch; the oracle is the drive's numbers written above, applied to what was recorded."""
    base = _weak_j2(tmp_path)
    variants = [base.scaled(1.0, 1.0), base.scaled(1.0, 2.0)]
    options = {"video": False, "plots": False, "progress": False}
    gpu = evaluate_scenarios(variants, RunOptions(**options, backend="warp"))
    cpu = evaluate_scenarios(variants, RunOptions(**options, backend="mujoco"))
    top = WEAK_J2["top_rpm"] * 2 * np.pi / 60 / WEAK_J2["ratio"]
    for g, c in zip(gpu, cpu):
        a = g.record.arrays
        excess = _motor_excess(a)
        assert excess.max() <= F32_MOTOR_TOL, (int(np.argmax(excess)), excess.max())
        # the case reaches what it is meant to: the drive at its limit, the curve's falling
        # part and the motor past its top speed, where the drive is held where its motor
        # gives 0 N m (not at 0 N m: its rotor accelerates with the arm)
        held = np.abs(a["tau_actuator"][:, 1]) >= a["tau_limit"][:, 1] * (1 - 1e-6)
        assert held.sum() > 100
        fast = held & (np.abs(a["qd"][:, 1]) > 1.01 * top)
        assert fast.any() and np.all(np.abs(a["tau"][fast, 1]) > 1.0)
        assert np.all(np.abs(excess[fast]) <= F32_MOTOR_TOL)
        # and the MuJoCo backend's record passes the same oracle, at its own 1e-9
        assert _motor_excess(c.record.arrays).max() <= 1e-9
        # the verdict reports the saturation as the MuJoCo backend's does
        failed = {k["name"] for k in g.summary["checks"] if not k["pass"]}
        assert "saturation" in failed
        assert failed == {k["name"] for k in c.summary["checks"] if not k["pass"]}
        assert "j2" in {s["joint"] for s in g.summary["saturation"]}


@pytest.mark.slow
@pytest.mark.parametrize("fault", ["flat force range", "curve at the joint, no motor law"])
def test_the_motor_oracle_catches_a_planted_clamp_fault(tmp_path, monkeypatch, fault):
    """The oracle above is not blind: a Warp batch whose drives keep the actuator's flat force
    range (the limit the reference's speed gives below the curve's knee), or follow the curve
    at the joint's speed without the motor's law (no gear direction, no rotor), lets J2's
    motor pass its curve at its own speed."""
    from sim.simulation import warp_batch

    def flat(self, qd, qdd):
        return -self.flat.copy(), self.flat.copy()

    def joint_curve(self, qd, qdd):
        hi = self.flat.copy()
        for j, d, ws in self.groups:
            hi[ws, j] = np.minimum(d.joint_peak_torque_at(qd[ws, j]), hi[ws, j])
        return -hi, hi

    monkeypatch.setattr(warp_batch._MotorBounds, "bounds",
                        flat if fault == "flat force range" else joint_curve)
    (ev,) = evaluate_scenarios([_weak_j2(tmp_path)], RunOptions(
        video=False, plots=False, progress=False, backend="warp"))
    assert _motor_excess(ev.record.arrays).max() > 100 * F32_MOTOR_TOL


class _FakeDevice:
    """Warp and MuJoCo Warp as far as the batch's stepper uses them: a step advances the
    state by one, unless a CUDA graph is being captured (then it is recorded, as Warp records
    kernel launches), and a launched graph runs what it recorded."""

    def __init__(self, cuda: bool) -> None:
        self.cuda, self.state, self.recording, self.log = cuda, 0, None, []

    # wp
    def get_device(self):
        return type("Device", (), {"is_cuda": self.cuda})()

    def ScopedCapture(self):  # noqa: N802 - Warp's name
        fake = self

        class Capture:
            def __enter__(self):
                fake.recording = []
                return self

            def __exit__(self, *exc):
                self.graph, fake.recording = tuple(fake.recording), None
                fake.log.append("captured")

        return Capture()

    def capture_launch(self, graph):
        self.log.append("graph")
        for op in graph:
            op()

    # mjw
    def step(self, mw, dw):
        def advance():
            self.state += 1

        if self.recording is not None:
            self.recording.append(advance)
        else:
            self.log.append("step")
            advance()


@pytest.mark.parametrize("cuda, graph", [(True, True), (False, False)])
def test_a_gpu_batch_steps_as_one_cuda_graph_after_its_first_step(monkeypatch, cuda, graph):
    """On a GPU the first step runs plainly (it loads the kernels), is then captured without
    being run, and every later step launches the graph: n calls advance the state n steps.
    Warp's CPU device has no graphs. (The graph's numbers are the plain step's: the H200 run
    in benchmarks/results/ agrees with MuJoCo in C as closely with graphs as without.)"""
    from sim.simulation import warp_batch

    monkeypatch.delenv("CELLSIM_WARP_GRAPH", raising=False)
    fake = _FakeDevice(cuda)
    step = warp_batch._Stepper(fake, fake, None, None)
    for _ in range(4):
        step()
    assert fake.state == 4
    assert warp_batch.STEP_STATS == {"steps": 4, "graph": graph}
    assert fake.log == (["step", "captured", "graph", "graph", "graph"] if graph
                        else ["step"] * 4)
    # switched off for a comparison (benchmarks/bench_warp_gpu.py --no-graph)
    monkeypatch.setenv("CELLSIM_WARP_GRAPH", "0")
    fake = _FakeDevice(True)
    step = warp_batch._Stepper(fake, fake, None, None)
    for _ in range(3):
        step()
    assert fake.state == 3 and fake.log == ["step"] * 3
