"""Kinematics of the cellsim robots.

* :mod:`~sim.kinematics.closed_form`: the seeds' forward models, transcribed literally.
* :mod:`~sim.kinematics.model`: :class:`KinematicModel` (vectorized FK, joint axes, ranges),
  :func:`kinematic_model` (tool frame = the MJCF ``tcp`` site), :func:`closed_form_model`.
* :mod:`~sim.kinematics.ik`: analytic IK (seed 000 eq. 13-17, seed 004 eq. 9-18),
  :func:`solve_ik`, :func:`ik_path`, :class:`SingularityWarning`.
* :mod:`~sim.kinematics.jacobian`: geometric/task Jacobians, manipulability, singularity
  measures (seed 004 eq. 22-25).
* :mod:`~sim.kinematics.mujoco_fk`: the same through MuJoCo (``mj_jacSite``).
* :mod:`~sim.kinematics.workspace`: reach and workspace sections.
* :mod:`~sim.kinematics.builder`: MJCF serial chains from DH / modified DH / screw tables.
"""
