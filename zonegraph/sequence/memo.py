"""A memo that forgets its least recently used entries past a size budget.

Proposal generation keeps what it computes per face group, and random completions (the labels)
meet new groups and canvases at every step: kept whole, those memos grew to gigabytes on graphs
of a few hundred zones (11 GB labelling a 627-zone corpus part). Recent entries are the ones
that recur (a search's siblings, a completion's first steps), so dropping the oldest keeps the
hits and bounds the memory.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

V = TypeVar("V")


class Memo(Generic[V]):
    """Values by key, at most ``budget`` in total ``size`` (bytes, or any additive measure).

    The newest entry is always kept, whatever its size. Reading an entry makes it the most
    recently used; a value may be None (a memoised failure) and is told apart from a missing one
    with ``in``.
    """

    def __init__(self, budget: int, size: Callable[[V], int] = lambda value: 1) -> None:
        self.budget = budget
        self.size = size
        self.total = 0
        self._entries: OrderedDict[Hashable, tuple[V, int]] = OrderedDict()

    def __contains__(self, key: Hashable) -> bool:
        return key in self._entries

    def __len__(self) -> int:
        return len(self._entries)

    def __getitem__(self, key: Hashable) -> V:
        self._entries.move_to_end(key)
        return self._entries[key][0]

    def get(self, key: Hashable) -> V | None:
        """The value of ``key`` (now the most recently used), or None when it is not kept."""
        return self[key] if key in self._entries else None

    def __setitem__(self, key: Hashable, value: V) -> None:
        if key in self._entries:
            self.total -= self._entries.pop(key)[1]
        size = self.size(value)
        self._entries[key] = (value, size)
        self.total += size
        while self.total > self.budget and len(self._entries) > 1:
            self.total -= self._entries.popitem(last=False)[1][1]
