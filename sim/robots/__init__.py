"""Robots layer: robot data and its registry, kinematic families, kinematics, MJCF writers.

Owns (no module imports one that imports it back, directly or around a circle):

* :mod:`~sim.robots.drive`: :class:`Drive`, the drive physics of a joint (torque-speed curve,
  motor torque of a joint torque and back, reflected inertia) and the Coulomb friction law;
* :mod:`~sim.robots.families`: one class per kinematic family (:class:`FiveR`, seed 000;
  :class:`Fanuc6`, seed 004; :class:`ChainFamily`, an arm given as data): closed-form FK,
  analytic IK, task Jacobian, singular factors, wrist, reach, ``with_tool``;
* :mod:`~sim.robots.spec`: :class:`RobotSpec` and :func:`joint_ranges` (read from the MJCF);
* :mod:`~sim.robots.kinematics`: table rows, chains, the closed forms (the seeds', OPW,
  5-axis), numeric IK, the kinematic model, IK ranking and paths, Jacobians, MuJoCo FK,
  workspace;
* :mod:`~sim.robots.mjcf`: the MJCF writers (a chain from a table; a robot folder's model);
* :mod:`~sim.robots.schema`: the ``robot.toml`` schema;
* :mod:`~sim.robots.arm`: an arm given as data (a URDF or a DH table) and its IK;
* :mod:`~sim.robots.accel_limits`: acceleration limits derived from the drives;
* :mod:`~sim.robots.robotfile`: a robot folder (or URDF) read into a :class:`RobotSpec`;
* :mod:`~sim.robots.registry`: ``ROBOTS``, ``get_robot``, ``resolve_robot`` (and the old
  import path of :class:`Drive`, :class:`RobotSpec`, :func:`joint_ranges`);
* :mod:`~sim.robots.drives`: a scenario's ``[drives.jN]`` overrides applied to the defaults;
* :mod:`~sim.robots.maker`: the maker's joint convention.

May import: planners, :mod:`sim.errors`, :mod:`sim.core`.
"""
