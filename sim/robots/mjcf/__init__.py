"""The MJCF writers: :mod:`~sim.robots.mjcf.builder` (a serial chain from a kinematic table,
the seeds' textbook examples) and :mod:`~sim.robots.mjcf.generate` (a robot folder's model from
its DH table or URDF: links, masses, drives, gains, scene). Both take their rows from
:mod:`sim.robots.kinematics.dh` (one row type per convention).

The package imports none of its modules itself. May import: :mod:`sim.core`, :mod:`sim.errors`,
:mod:`sim.robots.kinematics`, :mod:`sim.robots.drive` (never the registry or the robot files).
"""
