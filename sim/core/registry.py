"""A registry filled on first use: :class:`LazyRegistry`.

The shipped cells (and any registry whose entries are read from files) are a
:class:`planners.registry.Registry` like every other, but reading their files when the module
is imported would make every ``import`` pay for it; a :class:`LazyRegistry` reads them the first
time it is looked into (as dm_control's suites do), so importing costs nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from planners.registry import Registry

T = TypeVar("T")


class LazyRegistry(Registry[T]):
    """A :class:`~planners.registry.Registry` whose entries come from ``entries()``, called once,
    on first use (a look-up, iteration, ``len``, ``names`` or ``add``).

    Args:
        kind: What the entries are, for messages.
        entries: Gives the ``(name, item)`` pairs, in order; if it raises, the registry stays
            empty and the next use calls it again (the error is raised each time).
        **options: As for :class:`~planners.registry.Registry` (``error``, ``normalize``).
    """

    def __init__(self, kind: str, entries: Callable[[], Iterable[tuple[str, T]]],
                 **options: Any) -> None:
        super().__init__(kind, **options)
        self._entries: Callable[[], Iterable[tuple[str, T]]] | None = entries

    def _fill(self) -> None:
        entries, self._entries = self._entries, None
        if entries is None:
            return
        try:
            for name, item in entries():
                super().add(name, item)
        except BaseException:
            self._items.clear()
            self._entries = entries
            raise

    @property
    def loaded(self) -> bool:
        """Whether the entries have been read."""
        return self._entries is None

    def add(self, name: str, item: T) -> T:
        self._fill()
        return super().add(name, item)

    def get(self, name: str) -> T:  # type: ignore[override]
        self._fill()
        return super().get(name)

    def names(self) -> tuple[str, ...]:
        self._fill()
        return super().names()

    def __getitem__(self, name: str) -> T:
        return self.get(name)

    def __contains__(self, name: object) -> bool:
        self._fill()
        return super().__contains__(name)

    def __iter__(self) -> Iterator[str]:
        self._fill()
        return super().__iter__()

    def __len__(self) -> int:
        self._fill()
        return super().__len__()

    def __repr__(self) -> str:
        if not self.loaded:
            return f"LazyRegistry({self.kind!r}: not read yet)"
        return super().__repr__()


__all__ = ["LazyRegistry"]
