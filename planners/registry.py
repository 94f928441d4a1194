"""The one registry type of cellsim, and the registry of the joint-space planners.

:class:`Registry` maps names to objects (robot, tool and cell specs, planners, shipped
scenarios): ``add``, ``get`` (an :class:`~planners.errors.UnknownNameError` with a "did you
mean" hint listing the valid names), ``names``, and the read-only mapping protocol. It lives
in this bottom layer so that the planners use it too; ``sim`` builds every other registry from
it.

``PLANNERS`` maps ``"434"`` (seed 001) and ``"546"`` (seed 000) to their planning functions;
both take ``(times, q, *, v0, vf, a0, af, j0, jf)`` and return a
:class:`planners.trajectory.PiecewisePolynomialTrajectory` (4-3-4 rejects j0/jf).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from typing import Generic, TypeVar

from planners.errors import InternalError, UnknownNameError, UnknownPlannerError
from planners.poly434 import plan_434
from planners.poly546 import plan_546
from planners.trajectory import PiecewisePolynomialTrajectory

T = TypeVar("T")


class Registry(Mapping[str, T], Generic[T]):
    """Named objects of one kind, in the order they were added.

    Args:
        kind: What the entries are, for messages (``"robot"``, ``"planner"``, ...).
        error: The :class:`UnknownNameError` subclass :meth:`get` raises.
        normalize: Maps a requested name onto a registered one before the look-up (e.g.
            ``"4-3-4"`` -> ``"434"``); identity by default.
    """

    def __init__(self, kind: str, *, error: type[UnknownNameError] = UnknownNameError,
                 normalize: Callable[[str], str] | None = None) -> None:
        self.kind = kind
        self._error = error
        self._normalize = normalize
        self._items: dict[str, T] = {}

    def add(self, name: str, item: T) -> T:
        """Register ``item`` under ``name`` and return it.

        Raises:
            InternalError: ``name`` is already registered (two entries must not share a name).
        """
        if name in self._items:
            raise InternalError(f"{self.kind} {name!r} is registered twice")
        self._items[name] = item
        return item

    def get(self, name: str) -> T:  # type: ignore[override]
        """The entry called ``name``.

        Raises:
            UnknownNameError: Not registered; the message lists the valid names (sorted) with a
                "did you mean" hint for a close one.
        """
        key = self._normalize(name) if self._normalize is not None else name
        try:
            return self._items[key]
        except (KeyError, TypeError):
            raise self._error(self.kind, name, self._items) from None

    def names(self) -> tuple[str, ...]:
        """Registered names, in the order they were added."""
        return tuple(self._items)

    def __getitem__(self, name: str) -> T:
        return self.get(name)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in self._items

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}: {', '.join(self._items)})"


Planner = Callable[..., PiecewisePolynomialTrajectory]

#: Planner name -> planning function (``"4-3-4"`` and ``"5-4-6"`` are accepted spellings).
PLANNERS: Registry[Planner] = Registry(
    "planner", error=UnknownPlannerError, normalize=lambda name: str(name).strip().replace("-", ""))
PLANNERS.add("434", plan_434)
PLANNERS.add("546", plan_546)


def get_planner(name: str) -> Planner:
    """The planning function called ``name`` ("434" or "546"; "4-3-4" and "5-4-6" also work).

    Raises:
        UnknownPlannerError: Unknown name; the message lists the valid names.
    """
    return PLANNERS.get(name)
