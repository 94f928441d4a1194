"""Estimate the drives of a shipped arm whose maker publishes none, by the rules its README states.

    python models/estimate_drives.py models/fanuc_m10ia          # the [[drives]] blocks
    python models/estimate_drives.py models/fanuc_m10ia --accel  # max_accel_deg_s2 for them

The rules (each folder's README says which numbers are estimates):

* motor top speed 4500 rpm (the AC servo motors of this class run to 4000-6000 rpm);
* gear ratio: the largest whole number at which the motor's top speed still reaches the joint's
  speed limit (URDF ``velocity``): ``floor(4500 * 6 / speed_deg_s)``;
* efficiency 0.8 on J1-J3 (cycloidal reducers), 0.75 on the wrist (its gear trains);
* peak motor torque: the URDF's ``effort`` through the ratio and efficiency where it gives
  one; else enough to take the joint to its top speed in 0.25 s (``a = speed / 0.25 s``) at the
  largest inertia it sees over 2000 random poses with the rated payload at the flange, a body
  of 100 mm radius of gyration (the link inertia ``M_ii`` from MuJoCo's mass matrix, armature
  left out), against the largest
  gravity torque, plus the rotor's own inertia at that acceleration:
  ``(M_ii a + g) / (ratio eta) + J_rotor ratio a``;
* rated motor torque: 1.5 times the largest static gravity torque of the joint with the rated
  payload at the flange over 4000 random poses (MuJoCo's inverse dynamics on the generated
  model), through the ratio and efficiency (1.1 times where the URDF's ``effort`` caps the
  peak: the rated torque stays under it), at least a third of that peak and at least
  0.16 N m (the smallest AC servo motors of this class, 50 W), rounded up to two significant
  digits; the peak is then 3 times the rated torque (the URDF's ``effort``
  where it gives one, rounded up, and at least the rated torque);
* rotor inertia 1.0e-4 kg m^2 per N m of rated torque (the ratio of the FANUC models' motors);
* acceleration limits (``--accel``): :func:`sim.robots.accel_limits.derive_accel_limits` with
  the rated payload, rounded down to two significant digits (run after the drives are written
  and ``models/build_data_robots.py`` has regenerated the model).
"""

from __future__ import annotations

import argparse
import math
import sys
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

MOTOR_RPM = 4500.0
HOLD_FACTOR = 1.5
HOLD_FACTOR_CAPPED = 1.1
RAMP_S = 0.25
MIN_RATED_NM = 0.16
GYRATION_M = 0.1
ROTOR_PER_NM = 1.0e-4


def _up2(x: float) -> float:
    """``x`` rounded up to two significant digits."""
    e = math.floor(math.log10(x)) - 1
    return math.ceil(x / 10**e - 1e-9) * 10**e


def _down2(x: float) -> float:
    e = math.floor(math.log10(x)) - 1
    return math.floor(x / 10**e + 1e-9) * 10**e


def urdf_efforts(folder: Path) -> list[float]:
    """The revolute joints' ``effort`` in the folder's URDF, in chain order (0: none given)."""
    data = tomllib.loads((folder / "robot.toml").read_text(encoding="utf-8"))
    root = ET.parse(folder / data["kinematics"]["urdf"]).getroot()
    return [float(j.find("limit").get("effort", "0")) for j in root.iter("joint")
            if j.get("type") == "revolute"]


def drives_toml(folder: Path) -> str:
    """The estimated ``[[drives]]`` blocks of a folder (module docstring)."""
    import mujoco
    import numpy as np

    from sim.robots.mjcf.generate import mass_matrix, max_gravity_torque
    from sim.robots.robotfile import generated_files, load_robot_folder

    spec = load_robot_folder(folder)
    chain = spec.family.arm.chain
    xml = next(t for p, t in generated_files(folder).items() if p.name != "scene.xml")
    model = mujoco.MjModel.from_xml_string(xml)
    lo = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    hi = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    g = max_gravity_torque(model, chain.n, lo, hi, spec.payload_kg, 4000,
                           np.random.default_rng(0))
    data = mujoco.MjData(model)
    jac, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    inertia = np.zeros(chain.n)
    for q in np.random.default_rng(1).uniform(lo, hi, size=(2000, chain.n)):
        M = mass_matrix(model, data, q, chain.n) - np.diag(model.dof_armature[:chain.n])
        mujoco.mj_jacSite(model, data, jac, jacr, model.site("flange").id)
        M = M + spec.payload_kg * (jac[:, :chain.n].T @ jac[:, :chain.n]
                                   + GYRATION_M**2 * jacr[:, :chain.n].T @ jacr[:, :chain.n])
        inertia = np.maximum(inertia, np.diag(M))
    out = []
    for i, effort in enumerate(urdf_efforts(folder)):
        speed = math.degrees(spec.max_speed[i])
        ratio = math.floor(MOTOR_RPM * 6.0 / speed)
        eta = 0.8 if i < 3 else 0.75
        accel = spec.max_speed[i] / RAMP_S
        if effort > 0:
            peak = effort / (ratio * eta)
        else:  # peak = load / (N eta) + (ROTOR_PER_NM * peak / 3) N a, solved for the peak
            peak = ((inertia[i] * accel + g[i]) / (ratio * eta)
                    / (1.0 - ROTOR_PER_NM / 3.0 * ratio * accel))
        hold = HOLD_FACTOR_CAPPED if effort > 0 else HOLD_FACTOR
        rated = _up2(max(hold * g[i] / (ratio * eta), peak / 3.0, MIN_RATED_NM))
        peak = max(_up2(peak), rated) if effort > 0 else 3.0 * rated
        out.append(f"[[drives]]  # j{i + 1}: gravity {g[i]:.4g} N m, inertia {inertia[i]:.4g} "
                   "kg m^2\n"
                   f"gear_ratio = {ratio}\nefficiency = {eta}\n"
                   f"rotor_inertia_kg_m2 = {_up2(ROTOR_PER_NM * rated):.2e}\n"
                   f"rated_torque_nm = {rated:.4g}\npeak_torque_nm = {peak:.4g}\n"
                   f"max_speed_rpm = {MOTOR_RPM:.0f}")
    return "\n".join(out)


def accel_toml(folder: Path) -> str:
    import numpy as np

    from sim.robots.accel_limits import derive_accel_limits
    from sim.robots.robotfile import load_robot_folder

    spec = load_robot_folder(folder)
    derived = np.degrees(derive_accel_limits(spec, spec.payload_kg))
    return "max_accel_deg_s2 = [" + ", ".join(f"{_down2(v):.0f}" for v in derived) + "]"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--accel", action="store_true", help="print max_accel_deg_s2 instead")
    args = ap.parse_args(argv)
    print(accel_toml(args.folder) if args.accel else drives_toml(args.folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
