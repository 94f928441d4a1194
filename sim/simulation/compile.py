"""Compile a scenario's cell for simulation: the MuJoCo model, its sensors and the ids.

:func:`build` composes the scenario's cell (:mod:`sim.cells`), adds the sensors the runner
records (actuator forces, tcp position and orientation) and compiles it once; the returned
:class:`BuiltCell` hands out every id the simulation needs (joint qpos/dof addresses,
actuators, suction actuator, part free joints), resolved here and nowhere else.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sim.errors import CellError, CellsimError, InternalError
from sim.scenario import Scenario
from sim.simulation.motion import CartesianContext
from sim.simulation.motion.checks import MAX_STEPS

if TYPE_CHECKING:  # sim.cells imports mujoco: the command line picks MUJOCO_GL first
    from sim.cells import Cell
    from sim.robots.kinematics.model import KinematicModel
    from sim.robots.registry import Drive


@dataclass
class BuiltCell:
    """A compiled cell and every id the simulation needs, resolved once.

    Attributes:
        cell: The composed cell.
        model: The compiled ``mujoco.MjModel`` (with the runner's sensors).
        xml: The compiled model as MJCF (``model.xml`` of the run folder).
        robot_qpos, robot_dof: qpos and dof addresses of the driven joints (the robot's, then
            the mechanisms' axes: ``cell.joint_names``), in order, (n,).
        robot_act: Ids of their position actuators, in joint order, (n,).
        suction_act: Id of the suction actuator, or None.
        sensor_slices: Slices of ``sensordata`` by recorded quantity (``tau0..``, ``tcp_pos``,
            ``tcp_quat``).
        part_qpos: qpos addresses (7 each: position, quaternion) of the parts' free joints.
        context: Kinematics, seams and frame 0 for the Cartesian phases.
        joint_ids: Ids of the robot joints, in order, (n,).
        tcp_site, frame0_site: Ids of the sites ``tcp`` and ``frame0``.
        force_limits: Each robot drive's torque limit at the joint (its ``forcerange``;
            +-inf when unlimited), N m, (n, 2).
        friction_act: Ids of the robot joints' friction actuators (joints without friction
            have none).
        partner_cols: The cell's other robots' columns in the joint vector, by name.
        partner_tcp: Ids of their ``tcp`` sites, by name.
    """

    cell: Cell
    model: Any
    _xml: str | Callable[[], str]
    robot_qpos: NDArray[np.int64]
    robot_dof: NDArray[np.int64]
    robot_act: NDArray[np.int64]
    suction_act: int | None
    sensor_slices: dict[str, slice]
    part_qpos: list[NDArray[np.int64]]
    context: CartesianContext
    joint_ids: NDArray[np.int64]
    tcp_site: int
    frame0_site: int
    force_limits: NDArray[np.float64]
    friction_act: NDArray[np.int64]
    partner_cols: dict[str, slice] = field(default_factory=dict)
    partner_tcp: dict[str, int] = field(default_factory=dict)

    @property
    def xml(self) -> str:
        """The compiled model as MJCF; written when first asked for where the cell was built
        from a kept spec (:mod:`sim.simulation.build_cache`: a metrics-only sweep variant never
        asks)."""
        if callable(self._xml):
            self._xml = self._xml()
        return self._xml


# --------------------------------------------------------------------------------------------
# Cell compilation
# --------------------------------------------------------------------------------------------


@dataclass
class ComposedCell:
    """A scenario's composed cell with the runner's sensors, before compiling.

    Attributes:
        cell: The composed cell (its ``mjcf`` holds the sensors).
        sensors: The recorded quantities and their sizes, in ``sensordata`` order.
        xml: The cell's MJCF as ``dm_control`` writes it (what is compiled).
        assets: Its assets (meshes, textures), by file name.
    """

    cell: Cell
    sensors: list[tuple[str, int]]
    xml: str
    assets: dict[str, Any]


def build(scenario: Scenario) -> BuiltCell:
    """Compose and compile the scenario's cell, with the sensors the runner records."""
    composed = compose(scenario)
    model, saved_xml = compile_composed(composed)
    return assemble(scenario, composed.cell, model, saved_xml, composed.sensors)


def compose(scenario: Scenario) -> ComposedCell:
    """The scenario's cell composed with the sensors the runner records (not compiled)."""
    from sim.cells import build_cell

    cell = build_cell(scenario.cell, scenario.robot, tool=scenario.tool,
                      mount=scenario.mount, payload_kg=scenario.payload_kg)
    root = cell.mjcf
    if scenario.simulation.timestep_s is not None:
        root.option.timestep = scenario.simulation.timestep_s
    # the drive each joint really has (a scenario's [drives] override included) sets its
    # actuator's force range and its joint's armature: one drive everywhere
    drives = scenario.drive_train
    sensors: list[tuple[str, int]] = []
    for i, name in enumerate(cell.actuator_names):
        actuator = root.find("actuator", name)
        if drives:
            _apply_drive(actuator, root.find("joint", cell.joint_names[i]), drives[i])
        # the control carries the feed-forward torque (ctrl = q_ref + kv/kp qd_ref + tau_ff/kp):
        # no clamp on it; the drive's limit is its forcerange
        actuator.ctrllimited = False
        root.sensor.add("actuatorfrc", name=f"cellsim_tau{i}", actuator=actuator)
        sensors.append((f"tau{i}", 1))
    tcp = root.find("site", cell.tcp_site)
    root.sensor.add("framepos", name="cellsim_tcp_pos", objtype="site", objname=tcp)
    root.sensor.add("framequat", name="cellsim_tcp_quat", objtype="site", objname=tcp)
    sensors += [("tcp_pos", 3), ("tcp_quat", 4)]
    for cr in cell.partners:  # each other robot's tool point
        tcp_p = root.find("site", cr.tcp_site)
        root.sensor.add("framepos", name=f"cellsim_{cr.name}_tcp_pos", objtype="site",
                        objname=tcp_p)
        root.sensor.add("framequat", name=f"cellsim_{cr.name}_tcp_quat", objtype="site",
                        objname=tcp_p)
        sensors += [(f"{cr.name}_tcp_pos", 3), (f"{cr.name}_tcp_quat", 4)]
    return ComposedCell(cell, sensors, root.to_xml_string(), root.get_assets())


def compile_composed(composed: ComposedCell) -> tuple[Any, str]:
    """Compile a composed cell: the ``mujoco.MjModel`` and its MJCF as MuJoCo saves it."""
    import mujoco

    try:
        model = mujoco.MjModel.from_xml_string(composed.xml, composed.assets)
    except ValueError as exc:  # a bug in a cell builder, not a user mistake
        raise InternalError(f"cell {composed.cell.name!r} does not compile: {exc}") from exc
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.xml"
        mujoco.mj_saveLastXML(str(path), model)
        saved_xml = path.read_text()
    return model, saved_xml


def assemble(scenario: Scenario, cell: Cell, model: Any, saved_xml: str | Callable[[], str],
             sensors: list[tuple[str, int]]) -> BuiltCell:
    """The :class:`BuiltCell` of a compiled cell: every id, the sensors' slices and the
    Cartesian context, resolved from ``model``; ``saved_xml``: its MJCF, or what writes it
    when first asked for."""
    import mujoco

    from sim.cells.compose import FRICTION_PREFIX
    from sim.robots.kinematics.model import closed_form_model

    slices, start = {}, 0
    for name, size in sensors:
        slices[name] = slice(start, start + size)
        start += size
    jids = np.array([model.joint(n).id for n in cell.joint_names])
    robot_qpos = np.array([model.jnt_qposadr[j] for j in jids])
    robot_dof = np.array([model.jnt_dofadr[j] for j in jids])
    robot_act = np.array([model.actuator(n).id for n in cell.actuator_names])
    suction = (None if cell.adhesion_actuator is None
               else model.actuator(cell.adhesion_actuator).id)
    part_qpos = [np.arange(model.jnt_qposadr[model.body(p).jntadr[0]],
                           model.jnt_qposadr[model.body(p).jntadr[0]] + 7)
                 for p in cell.parts]
    tcp_site, frame0_site = model.site(cell.tcp_site).id, model.site(cell.frame0_site).id
    kin = _tool_kinematics(closed_form_model(scenario.robot), model, frame0_site, tcp_site,
                           robot_qpos,
                           None if cell.tool is None or cell.tool.straight
                           else model.site(cell.flange_site).id)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    fl = model.site(cell.flange_site).id

    def site_T(i: int) -> NDArray[np.float64]:
        T = np.eye(4)
        T[:3, :3] = data.site_xmat[i].reshape(3, 3)
        T[:3, 3] = data.site_xpos[i]
        return T

    ctx = CartesianContext(kinematics=kin, seams=dict(cell.seams),
                           world_from_frame0=np.asarray(cell.world_from_frame0, dtype=float),
                           frames=dict(cell.frames), home_q=np.asarray(cell.home_q, float),
                           flange_to_tcp=np.linalg.inv(site_T(fl)) @ site_T(tcp_site),
                           robot=scenario.robot, max_phase_s=MAX_STEPS * float(model.opt.timestep),
                           **_mechanism_context(cell))
    cols, start_col = {}, len(cell.joint_names) - sum(cr.robot.n_joints for cr in cell.partners)
    for cr in cell.partners:  # each other robot plans with its own kinematics and seams
        t_p, f0_p = model.site(cr.tcp_site).id, model.site(cr.frame0_site).id
        kin_p = _tool_kinematics(closed_form_model(cr.robot), model, f0_p, t_p, robot_qpos,
                                 None if cr.tool is None or cr.tool.straight
                                 else model.site(cr.flange_site).id)
        ctx.partners[cr.name] = CartesianContext(
            kinematics=kin_p, seams=dict(cr.seams),
            world_from_frame0=np.asarray(cr.world_from_frame0, dtype=float),
            frames=dict(cell.frames), home_q=np.asarray(cr.home_q, float),
            flange_to_tcp=np.linalg.inv(site_T(model.site(cr.flange_site).id)) @ site_T(t_p),
            robot=cr.robot, seam_mechanism=dict(ctx.seam_mechanism),
            frame_mechanism=dict(ctx.frame_mechanism), max_phase_s=ctx.max_phase_s)
        cols[cr.name] = slice(start_col, start_col + cr.robot.n_joints)
        start_col += cr.robot.n_joints
    limits = np.where(model.actuator_forcelimited[robot_act, None].astype(bool),
                      model.actuator_forcerange[robot_act] * model.actuator_gear[robot_act, :1],
                      np.array([-np.inf, np.inf]))
    prefixes = ("robot", *(cr.name for cr in cell.partners))
    friction = np.array([a for a in range(model.nu)
                         if model.actuator(a).name.startswith(
                             (*(f"{p}/{FRICTION_PREFIX}" for p in prefixes), FRICTION_PREFIX))],
                        dtype=int)
    return BuiltCell(cell, model, saved_xml, robot_qpos, robot_dof, robot_act, suction, slices,
                     part_qpos, ctx, jids, tcp_site, frame0_site, limits, friction, cols,
                     {cr.name: model.site(cr.tcp_site).id for cr in cell.partners})


def _mechanism_context(cell: Cell) -> dict[str, Any]:
    """What Cartesian phases need of the cell's mechanisms (:class:`CartesianContext`)."""
    if not cell.mechanisms:
        return {}
    carrier = {obj: pm.name for pm in cell.mechanisms for obj in pm.carries if obj != "robot"}
    return {"mechanisms": tuple(cell.mechanisms),
            "seam_mechanism": {seam: carrier[objs[0]] for seam, objs in cell.seam_objects.items()
                               if objs and objs[0] in carrier},
            "frame_mechanism": {obj: m for obj, m in carrier.items() if obj in cell.frames},
            "robot_on": next((pm.name for pm in cell.mechanisms if "robot" in pm.carries), None)}


def _apply_drive(actuator: Any, joint: Any, drive: Drive) -> None:
    """A joint's drive in its MJCF: the actuator's force range is the drive's peak torque at the
    joint (peak motor torque x ratio x efficiency, through the actuator's gear) and the joint's
    armature the rotor's reflected inertia ``J_r N^2``."""
    gear = float(actuator.gear[0]) if actuator.gear is not None else 1.0
    peak = drive.peak_torque * drive.gear_ratio * drive.efficiency / gear
    actuator.forcelimited = True
    actuator.forcerange = [-peak, peak]
    joint.armature = drive.rotor_inertia * drive.gear_ratio ** 2


def _tool_kinematics(kin: KinematicModel, model: Any, f0: int, tcp: int,
                     robot_qpos: NDArray[np.int64], flange: int | None = None) -> KinematicModel:
    """The closed-form kinematics with the attached tool, measured from the compiled cell.

    Tools are straight (their tip lies on the seeds' tool axis), so the tool changes one
    number: ``l3`` of the 5R family (seed 000 Table 1, J4 axis to the tool point) or the tool
    length ``r`` of the 200iC (seed 004, along z6 beyond R6). It is read off MuJoCo's ``tcp``
    in ``frame0`` at q = 0, where the seeds put the tool point at ``(l1 + l2 + l3, 0, d1)`` and
    ``(d2 + R4 + R6 + r, 0, d3 + d4)``; :func:`_check_tcp_consistency` then checks the whole pose.

    A tool that is not straight (``flange`` given: a tool file's turned or offset tcp) keeps the
    seed's tool frame on the flange, and the constant transform from it to MuJoCo's ``tcp``
    at q = 0 becomes the model's ``tcp_offset`` (six-axis arms take any; the 5R family only
    one on its J5 axis, and says so).
    """
    import dataclasses

    import mujoco

    data = mujoco.MjData(model)
    data.qpos[robot_qpos] = 0.0
    mujoco.mj_kinematics(model, data)
    R0 = data.site_xmat[f0].reshape(3, 3)
    p = R0.T @ (data.site_xpos[tcp] - data.site_xpos[f0])
    if flange is None:
        return kin.with_family(kin.family.tool_from_home_tcp(p))
    p_flange = R0.T @ (data.site_xpos[flange] - data.site_xpos[f0])
    base = kin.with_family(kin.family.tool_from_home_tcp(p_flange))
    T_tcp = np.eye(4)
    T_tcp[:3, :3] = R0.T @ data.site_xmat[tcp].reshape(3, 3)
    T_tcp[:3, 3] = p
    offset = base.tcp_offset @ np.linalg.solve(base.fk(np.zeros(base.n_joints)), T_tcp)
    offset[np.abs(offset) < 1e-15] = 0.0
    try:
        return dataclasses.replace(base, tcp_offset=offset)
    except CellsimError as exc:
        raise CellError(f"tool {model.site(tcp).name}: {exc}") from None

