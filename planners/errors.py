"""Exception hierarchy of the planners.

Every message is one line that names the offending field, joint or value, so that the
command line can print it as it is.
"""

from __future__ import annotations


class PlannerError(ValueError):
    """Base class of every planning error (a user mistake, not a bug)."""


class InvalidKnotsError(PlannerError):
    """Knot times or knot values are unusable (too few, non-increasing, NaN, wrong shape)."""


class InvalidBoundaryError(PlannerError):
    """Boundary velocities, accelerations or jerks have the wrong shape or are not finite."""


class UnknownPlannerError(PlannerError):
    """A planner name that is not registered; the message lists the valid names."""


class LimitViolationError(PlannerError):
    """A trajectory exceeds a joint's position, velocity or acceleration limit.

    Attributes:
        joint: Index of the joint (0-based).
        quantity: "position", "velocity" or "acceleration".
        time: Time of the worst violation, s.
        value: Value at that time (SI units).
        limit: The limit that was exceeded (SI units).
    """

    def __init__(self, message: str, *, joint: int, quantity: str, time: float,
                 value: float, limit: float) -> None:
        super().__init__(message)
        self.joint = joint
        self.quantity = quantity
        self.time = time
        self.value = value
        self.limit = limit
