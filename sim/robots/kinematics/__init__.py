"""Kinematics of serial arms, apart from the robot data and the MJCF writers.

Owns the kinematic table rows (:mod:`~sim.robots.kinematics.dh`), chains and their forward
kinematics from DH tables and URDFs (:mod:`~sim.robots.kinematics.chain`), the seeds' closed
forms (:mod:`~sim.robots.kinematics.closed_form`), the OPW closed form
(:mod:`~sim.robots.kinematics.opw`), the 5-axis closed form
(:mod:`~sim.robots.kinematics.five_axis`), numeric IK (:mod:`~sim.robots.kinematics.numeric_ik`),
a robot's kinematic model (:mod:`~sim.robots.kinematics.model`), IK ranking and paths
(:mod:`~sim.robots.kinematics.ik`), Jacobians (:mod:`~sim.robots.kinematics.jacobian`), the same
through MuJoCo (:mod:`~sim.robots.kinematics.mujoco_fk`) and workspace sections
(:mod:`~sim.robots.kinematics.workspace`). The kinematic families stay in
:mod:`sim.robots.families`, which builds on the closed forms and numeric IK here and under the
model, IK and Jacobians here.

The package imports none of its modules itself (each is imported by its own path), so a family
may import a closed form here without loading the rest. May import: :mod:`sim.core`,
:mod:`sim.errors`, :mod:`sim.robots.families`, :mod:`sim.robots.spec` (never the registry,
the robot files or the MJCF writers).
"""
