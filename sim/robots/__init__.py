"""Robots layer: robot specs and their registry, kinematic families, kinematics.

Owns:

* :mod:`~sim.robots.registry`: :class:`RobotSpec`, :class:`Drive`, ``ROBOTS``, joint ranges;
* :mod:`~sim.robots.families`: one class per kinematic family (:class:`FiveR`, seed 000;
  :class:`Fanuc6`, seed 004): closed-form FK, analytic IK, task Jacobian, singular factors,
  wrist, reach, ``with_tool``;
* :mod:`~sim.robots.closed_form`: the seeds' forward models, transcribed literally;
* :mod:`~sim.robots.model`: :class:`KinematicModel` (family + tcp frame + ranges + speeds);
* :mod:`~sim.robots.ik`: IK ranking and branch-continuous paths;
* :mod:`~sim.robots.jacobian`: geometric/task Jacobians, manipulability, singularity measures;
* :mod:`~sim.robots.mujoco_fk`: the same through MuJoCo (``mj_jacSite``);
* :mod:`~sim.robots.workspace`: reach and workspace sections;
* :mod:`~sim.robots.builder`: MJCF serial chains from DH / modified DH / screw tables.

May import: planners, :mod:`sim.errors`, :mod:`sim.core`.
"""
