"""End-of-arm tools built from MuJoCo primitives with ``dm_control.mjcf``.

Every tool is built in its own *tool frame*: origin on the robot's flange face, ``+z`` along the
flange's approach axis (out of the flange), so that a tool is *straight*: its tool centre point
(site ``tip``) lies on the flange axis at ``(0, 0, length_m)``, with the orientation of the tool
frame. The seeds' closed-form kinematics therefore still hold with the tool length added (5R
family: ``l3_eff = (J4 axis -> flange) + length_m``; LR Mate 200iC: ``r = length_m`` in seed 004
eq. 6-7). :mod:`sim.cells` attaches a tool at the robot's ``flange`` site, turning the tool frame
so that its ``+z`` is the flange approach axis, and moves the robot's ``tcp`` site onto the tool
tip.

Tools (all dimensions along the tool axis from the flange face; masses from the geometry and the
materials below, set explicitly on every geom so the numbers are visible and testable):

``mig_torch`` - a straight (0 deg neck) robotic MIG/MAG torch, 145 mm from the flange face to the
wire tip (the split of the LR Mate 100iB's l3 = 225 mm into an 80 mm flange and a 145 mm torch,
``sim/robots/registry.py``), 1.0 kg in total:

====================  ============  ====================  ===================================
part                  z range (mm)  primitive             mass (material)
====================  ============  ====================  ===================================
insulating adapter    0 - 12        cylinder r 25 mm      0.064 kg (aluminium, 2700 kg/m^3)
collision sensor and  12 - 57       cylinder r 30 mm      0.782 kg (steel housing with a hollow
clamp                                                     core: effective 6150 kg/m^3)
torch neck            57 - 85       cylinder r 12 mm      0.081 kg (copper conductor in its
                                                          insulation: effective 6400 kg/m^3)
gas nozzle            85 - 128      cylinder r 11 mm      0.069 kg (copper tube OD 22 / ID 16,
                                                          smeared over the OD: 4193 kg/m^3)
contact tip           118 - 130     cylinder r 4 mm       0.005 kg (CuCrZr, 8900 kg/m^3)
wire stick-out        130 - 145     cylinder r 0.6 mm     0.0001 kg (steel, 7850 kg/m^3)
====================  ============  ====================  ===================================

``mig_torch_long`` - the same design sized for the large 5R welding robot: a straight water-cooled
500 A torch, 300 mm from the flange face to the wire tip (the 5R robot's l3 = 400 mm = 100 mm
flange + 300 mm torch, ``models/robot_5r/README.md``), 1.70 kg: adapter r 32 mm 0-15 mm (0.130 kg,
aluminium), collision sensor r 34 mm 15-65 mm (0.939 kg, effective 5170 kg/m^3), neck r 14 mm
65-230 mm (0.508 kg, effective 5000 kg/m^3), nozzle r 13 mm 230-283 mm (0.117 kg, copper tube OD 26
/ ID 19), contact tip r 4.5 mm 273-285 mm (0.007 kg), wire 285-300 mm.

With its default torch each robot's tcp is where the seed dimensions put it (100iB: l3 = 80 + 145 =
225 mm; 5R: l3 = 100 + 300 = 400 mm), so ``sim/robots/registry.py``'s dims hold as they are in the welding
cells. The 15 mm wire stick-out is the contact-tip-to-work distance usual for 1.0-1.2 mm wire in
short-arc MAG welding. Touch sensing (the wire tip set on the root with the arc off) may press
the tip up to ``touch_depth_m`` = 0.5 mm beyond the wire's radius into the work
(:mod:`sim.simulation.collisions`). The hose package is not modelled (it hangs from the robot's
arm). Torch geoms do not collide with anything (``contype = conaffinity = 0``): a welding torch never touches
the work, and contact forces would pollute the joint torques used for motor sizing.

``vacuum_gripper`` - a single Ø40 mm suction cup on a stem, 100 mm from the flange face to the cup
lip, 0.25 kg. The cup is its own body (``cup``) carrying a MuJoCo ``adhesion`` actuator
(``suction``, ``ctrl`` in [0, 1]). Its lip is a ring of 8 spheres (r 3 mm on a 17 mm radius) that
touch the part: sphere-box contacts are exact and give 8 well-spread contact points, which keeps a
held box from rocking. Adhesion force (MuJoCo's ``adhesion`` actuator): ``gain * ctrl`` = 40 N at
full suction, split equally between the cup's contacts, pulling along each contact normal; 40 N is
about half the theoretical hold of a Ø40 mm cup at -60 kPa (75 N), the usual safety factor 2. The
lip geoms have ``margin`` 0 and ``gap`` 3 mm. In MuJoCo 4 (checked with ``mj_forward`` on two
geoms, ``tests/test_tools.py``) a contact is *active* (in the solver, repulsive) while the distance
is below ``margin`` and is still *detected* but inactive (``exclude = 1``) for a further ``gap``;
the adhesion actuator pulls at every detected contact, so suction attracts a part lying up to 3 mm
below the lip, as a real cup does, while the lip only pushes on actual penetration. (Older MuJoCo
versions read these two attributes the other way round: active within ``margin - gap``.) The lip
uses a stiff contact (``solref`` 0.002 s, the smallest time constant MuJoCo accepts at the robots'
1 ms step; ``solimp`` 0.95-0.99): MuJoCo's friction is soft, and a held part creeps by about
``timeconst / 2`` times the velocity change friction has to give it (measured: a part carried
through a 90 deg J1 swing drifts outwards 12 mm with 0.01 s, 1.3 mm with 0.002 s). Parts are held
by these contact forces and friction (``friction`` 1.0, rubber), never by constraints or
teleporting.

Integrator: with a suction tool the cell switches the model from ``implicitfast`` to ``implicit``:
with ``implicitfast`` a 0.5 kg part held by adhesion started to tumble and the simulation diverged
within 0.35 s of lifting, while ``implicit``, ``Euler`` and ``RK4`` held it (see
:func:`sim.cells.compose.prepare_robot`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from planners.registry import Registry
from sim.errors import CellsimError

if TYPE_CHECKING:  # dm_control is imported where a tool model is built
    from dm_control import mjcf

#: Contact bit masks used across cellsim's cells (MuJoCo ``contype``/``conaffinity``): a contact
#: is generated when ``(contype1 & conaffinity2) | (contype2 & conaffinity1)`` is non-zero.
#: Robot links keep MuJoCo's default (1, 1) and so touch none of these.
CONTACT_FIXTURE = 2  #: static cell geometry (floor, tables, trays): touches parts only
CONTACT_CUP = 4  #: suction-cup lip: touches parts only
CONTACT_PART_TYPE = 2  #: parts: contype
CONTACT_PART_AFFINITY = 2 | 4  #: parts: conaffinity (fixtures, other parts, the cup)

#: Standard gravity, m/s^2, and the factor of its weight a suction cup's holding force must
#: give a part (the margin for the cycle's accelerations and a cup that does not seal
#: perfectly): the vacuum gripper's rating is its 40 N over twice a part's weight, 2.04 kg.
GRAVITY = 9.80665
SUCTION_SAFETY = 2.0
#: Name of the adhesion actuator, the cup body and the tip site inside a tool model.
TIP_SITE = "tip"
CUP_BODY = "cup"
SUCTION_ACTUATOR = "suction"

#: Time constant of the vacuum in the cup, s: suction builds and decays as a first-order lag
#: of the valve command (about 50 ms for a small cup on an ejector); the scenario's 0.3 s dwells
#: leave it at 99.8 %. A step in the adhesion force instead struck the held part against the lip
#: and made the torque peak depend on the timestep.
VACUUM_TIME_CONSTANT_S = 0.05
#: Vacuum-gripper suction parameters (see the module docstring for where they come from).
SUCTION_GAIN_N = 40.0
SUCTION_GAP_M = 0.003
LIP_SOLREF = (0.002, 1.0)
LIP_SOLIMP = (0.95, 0.99, 0.001, 0.5, 2.0)
LIP_FRICTION = (1.0, 0.005, 0.0001)


@dataclass(frozen=True)
class ToolSpec:
    """Static description of one end-of-arm tool.

    Attributes:
        name: Registry name (``--tool`` on the command line, ``tool`` in scenarios).
        description: One line for ``cellsim list``.
        mass_kg: Total mass, kg (the geoms' masses add up to it, see the module docstring).
        length_m: Distance from the flange face to the tool centre point along the flange's
            approach axis, m. The tip lies on that axis (straight tool).
        kind: ``"torch"`` or ``"gripper"``.
        suction_gain_n: Adhesion force at full suction (``ctrl = 1``), N; 0 for a torch.
        work_geoms: The tool's geoms that touch the work by design (names inside the tool
            model): a torch's welding wire, which may touch the seam's workpiece while the arc
            is on; a gripper's cup lip, which may touch the part it picks. Every other geom of
            the tool (nozzle, torch body, ...) must never touch anything
            (:mod:`sim.simulation.collisions`).
        tcp_in_tool: Pose of the tool centre point in the tool frame, (4, 4) as nested tuples,
            for a tool whose tcp is off the flange axis or turned (a tool file's ``tcp_mm`` and
            ``tcp_euler_zyx_deg``); None for a straight tool (tcp at ``(0, 0, length_m)``,
            oriented as the tool frame).
        stickout_m: Nominal wire stick-out of a torch (contact tip to wire tip), m.
        touch_depth_m: How far the wire tip of a torch may press into a workpiece beyond the
            wire's radius with the arc off (touch sensing, the tip set on the root), m
            (:mod:`sim.simulation.collisions`).
        max_payload_kg: The heaviest mass the tool is rated to hold (a gripper's part and
            the scenario's payload), kg; None for a tool that holds nothing (a torch). The
            verdict checks it (:mod:`sim.analysis.verdict`, ``tool_payload``).
        source: The tool file, for a tool given as a file (:mod:`sim.cells.toolfile`).
        builder: Builds the tool's MJCF (a tool file's own); None for the shipped tools.
    """

    name: str
    description: str
    mass_kg: float
    length_m: float
    kind: str = "torch"
    suction_gain_n: float = 0.0
    work_geoms: tuple[str, ...] = ()
    tcp_in_tool: tuple[tuple[float, ...], ...] | None = None
    stickout_m: float = 0.015
    touch_depth_m: float = 0.0005
    max_payload_kg: float | None = None
    source: Path | None = None
    builder: Callable[[], object] | None = field(default=None, repr=False, compare=False)

    @property
    def straight(self) -> bool:
        """The tcp lies on the flange axis, oriented as the tool frame."""
        return self.tcp_in_tool is None

    def standoff(self, ctwd: float) -> float:
        """The stand-off of a contact-tip-to-work distance ``ctwd`` (m) with this torch: ``ctwd``
        less its nominal stick-out, m (how far its tool point keeps back from the seam,
        :mod:`sim.cells.seam`).

        Raises:
            CellsimError: ``ctwd`` is shorter than the nominal stick-out: the modelled wire,
                that long, would reach into the work (the message names no key: callers add it).
        """
        if ctwd < self.stickout_m - 1e-12:
            raise CellsimError(f"{ctwd * 1e3:g} mm is shorter than the nominal stick-out of tool "
                               f"{self.name!r}, {self.stickout_m * 1e3:g} mm: its wire would reach "
                               f"{(self.stickout_m - ctwd) * 1e3:g} mm into the work")
        return ctwd - self.stickout_m

    def tcp_pose(self) -> np.ndarray:
        """Pose of the tcp in the tool frame, (4, 4), m."""
        if self.tcp_in_tool is None:
            T = np.eye(4)
            T[2, 3] = self.length_m
            return T
        return np.array(self.tcp_in_tool, dtype=float)


#: The shipped tools by name.
TOOLS: Registry[ToolSpec] = Registry("tool")
for _spec in (
        ToolSpec(
            name="mig_torch",
            description="straight robotic MIG/MAG torch, 145 mm to the wire tip, 1.0 kg",
            mass_kg=1.0,
            length_m=0.145,
            kind="torch",
            work_geoms=("wire",),
        ),
        ToolSpec(
            name="mig_torch_long",
            description="straight water-cooled MIG/MAG torch, 300 mm to the wire tip, 1.7 kg",
            mass_kg=1.7,
            length_m=0.300,
            kind="torch",
            work_geoms=("wire",),
        ),
        ToolSpec(
            name="vacuum_gripper",
            description="single Ø40 mm suction cup (MuJoCo adhesion, 40 N), 100 mm, 0.25 kg",
            mass_kg=0.25,
            length_m=0.100,
            kind="gripper",
            suction_gain_n=SUCTION_GAIN_N,
            work_geoms=tuple(f"lip{k}" for k in range(8)),
            max_payload_kg=SUCTION_GAIN_N / (GRAVITY * SUCTION_SAFETY),
        ),
):
    TOOLS.add(_spec.name, _spec)


def get_tool(name: str) -> ToolSpec:
    """Look a tool up by name.

    Raises:
        UnknownNameError: Not a registered tool; the message lists the known ones.
    """
    return TOOLS.get(name)


def _cyl_mass(radius: float, length: float, density: float) -> float:
    """Mass of a solid cylinder, kg (radius, length in m; density in kg/m^3)."""
    return float(np.pi * radius**2 * length * density)


def _axial_cylinder(body: mjcf.Element, name: str, radius: float, z0: float, z1: float,
                    mass: float, rgba: tuple[float, float, float, float],
                    contype: int = 0, conaffinity: int = 0) -> mjcf.Element:
    """Add a cylinder along the tool axis from ``z0`` to ``z1`` (m) with the given mass (kg)."""
    return body.add("geom", name=name, type="cylinder", size=[radius, (z1 - z0) / 2],
                    pos=[0.0, 0.0, (z0 + z1) / 2], mass=mass, rgba=rgba,
                    contype=contype, conaffinity=conaffinity)


# Materials (kg/m^3) and colours.
_AL, _STEEL, _CU = 2700.0, 7850.0, 8900.0
_GREY = (0.55, 0.57, 0.6, 1.0)
_DARK = (0.15, 0.15, 0.17, 1.0)
_COPPER = (0.80, 0.50, 0.25, 1.0)
_BRASS = (0.85, 0.70, 0.35, 1.0)
_WIRE = (0.75, 0.75, 0.78, 1.0)
_BLUE = (0.15, 0.35, 0.75, 1.0)
_RUBBER = (0.10, 0.10, 0.10, 1.0)


#: Straight torches: segments (geom, radius m, z0 m, z1 m, density kg/m^3, colour) from the
#: flange face to the wire tip; the masses follow from the densities (module docstring).
_TORCHES: dict[str, tuple[tuple[str, float, float, float, float, tuple], ...]] = {
    "mig_torch": (
        ("adapter", 0.025, 0.000, 0.012, _AL, _GREY),
        ("collision_sensor", 0.030, 0.012, 0.057, 6150.0, _DARK),
        ("neck", 0.012, 0.057, 0.085, 6400.0, _DARK),
        ("nozzle", 0.011, 0.085, 0.128, _CU * (1.0 - (0.008 / 0.011) ** 2), _COPPER),
        ("contact_tip", 0.004, 0.118, 0.130, _CU, _BRASS),
        ("wire", 0.0006, 0.130, 0.145, _STEEL, _WIRE),
    ),
    "mig_torch_long": (
        ("adapter", 0.032, 0.000, 0.015, _AL, _GREY),
        ("collision_sensor", 0.034, 0.015, 0.065, 5170.0, _DARK),
        ("neck", 0.014, 0.065, 0.230, 5000.0, _DARK),
        ("nozzle", 0.013, 0.230, 0.283, _CU * (1.0 - (0.0095 / 0.013) ** 2), _COPPER),
        ("contact_tip", 0.0045, 0.273, 0.285, _CU, _BRASS),
        ("wire", 0.0006, 0.285, 0.300, _STEEL, _WIRE),
    ),
}


def _build_torch(spec: ToolSpec) -> mjcf.RootElement:
    from dm_control import mjcf

    model = mjcf.RootElement(model=spec.name)
    body = model.worldbody.add("body", name="torch")
    for name, r, z0, z1, rho, rgba in _TORCHES[spec.name]:
        _axial_cylinder(body, name, r, z0, z1, _cyl_mass(r, z1 - z0, rho), rgba)
    body.add("site", name=TIP_SITE, pos=[0.0, 0.0, spec.length_m], size=[0.002],
             rgba=(1.0, 0.2, 0.1, 1.0))
    return model


def _build_vacuum_gripper(spec: ToolSpec) -> mjcf.RootElement:
    from dm_control import mjcf

    model = mjcf.RootElement(model=spec.name)
    body = model.worldbody.add("body", name="gripper")
    # adapter plate, vacuum ejector block, stem (tube), cup holder; the cup is a separate body.
    _axial_cylinder(body, "adapter", 0.025, 0.000, 0.010, 0.053, _GREY)  # Al, r 25 mm, 10 mm
    body.add("geom", name="ejector", type="box", size=[0.025, 0.018, 0.015],
             pos=[0.0, 0.0, 0.025], mass=0.110, rgba=_BLUE, contype=0, conaffinity=0)
    _axial_cylinder(body, "stem", 0.008, 0.040, 0.082, 0.040, _GREY)  # steel tube 16x10
    cup_top, lip = 0.082, spec.length_m
    cup = body.add("body", name=CUP_BODY, pos=[0.0, 0.0, 0.0])
    # Cup holder (visual, no contact) and the rubber cup (visual cone as a short cylinder).
    _axial_cylinder(cup, "holder", 0.010, cup_top, cup_top + 0.006, 0.020, _GREY)
    _axial_cylinder(cup, "bellows", 0.016, cup_top + 0.006, lip - 0.004, 0.020, _RUBBER)
    # Lip: 8 spheres, r 3 mm, on a 17 mm radius, bottoms exactly at the tcp plane z = length.
    r_ball, r_ring, n = 0.003, 0.017, 8
    for k in range(n):
        phi = 2.0 * np.pi * k / n
        cup.add("geom", name=f"lip{k}", type="sphere", size=[r_ball],
                pos=[r_ring * np.cos(phi), r_ring * np.sin(phi), lip - r_ball],
                mass=0.001, rgba=_RUBBER, contype=CONTACT_CUP, conaffinity=CONTACT_CUP,
                condim=4, friction=LIP_FRICTION, solref=LIP_SOLREF, solimp=LIP_SOLIMP,
                margin=0.0, gap=SUCTION_GAP_M, priority=1)
    cup.add("site", name=TIP_SITE, pos=[0.0, 0.0, lip], size=[0.002], rgba=(1.0, 0.2, 0.1, 1.0))
    model.actuator.add("adhesion", name=SUCTION_ACTUATOR, body=cup, ctrlrange=[0.0, 1.0],
                       gain=spec.suction_gain_n)
    return model


_BUILDERS = {"mig_torch": _build_torch, "mig_torch_long": _build_torch,
             "vacuum_gripper": _build_vacuum_gripper}


def build_tool(spec: ToolSpec) -> mjcf.RootElement:
    """Build a tool's MJCF model in its tool frame (origin on the flange face, +z out).

    Args:
        spec: The tool.

    Returns:
        A ``dm_control.mjcf`` model named ``name`` with one top-level body, a site ``tip`` at
        ``(0, 0, length_m)`` (the tool centre point, oriented as the tool frame) and, for the
        vacuum gripper, a body ``cup`` and an adhesion actuator ``suction``.
    """
    if spec.builder is not None:
        return spec.builder()  # type: ignore[return-value]
    return _BUILDERS[spec.name](spec)
