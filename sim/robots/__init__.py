"""Kinematics of the cellsim robots.

* :mod:`~sim.robots.closed_form`: the seeds' forward models, transcribed literally.
* :mod:`~sim.robots.model`: :class:`KinematicModel` (vectorized FK, joint axes, ranges),
  :func:`kinematic_model` (tool frame = the MJCF ``tcp`` site), :func:`closed_form_model`.
* :mod:`~sim.robots.ik`: analytic IK (seed 000 eq. 13-17, seed 004 eq. 9-18),
  :func:`solve_ik`, :func:`ik_path`, :class:`SingularityWarning`.
* :mod:`~sim.robots.jacobian`: geometric/task Jacobians, manipulability, singularity
  measures (seed 004 eq. 22-25).
* :mod:`~sim.robots.mujoco_fk`: the same through MuJoCo (``mj_jacSite``).
* :mod:`~sim.robots.workspace`: reach and workspace sections.
* :mod:`~sim.robots.builder`: MJCF serial chains from DH / modified DH / screw tables.
"""
