"""cellsim: physics simulation of industrial robot welding and pick cells on MuJoCo."""

__version__ = "0.1.0"
