"""Kinematics of the cellsim robots: closed-form forward models from the seeds, analytic
inverse kinematics, Jacobians and singularity measures."""
