"""A search's wall-clock deadline, checked cooperatively by the work it bounds.

One expansion of a many-zone graph can take longer than the whole budget (thousands of face
groups to sketch and sweep), so a check between expansions cannot hold a budget: the proposal
generator checks the same deadline between groups and sketches and stops there. The clock is a
parameter so that a test can make the deadline pass after a known number of checks instead of
racing the wall clock.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field


@dataclass
class Deadline:
    """A point on ``clock`` past which bounded work stops; ``checks`` counts the calls of
    `passed` (how often the work looked), ``expired_checks`` those that found it passed."""

    at: float = math.inf
    clock: Callable[[], float] = field(default=time.perf_counter, repr=False)
    checks: int = 0
    expired_checks: int = 0

    @classmethod
    def after(cls, seconds: float, clock: Callable[[], float] = time.perf_counter) -> Deadline:
        """The deadline ``seconds`` from now on ``clock`` (infinite seconds: never)."""
        return cls(clock() + seconds, clock)

    def passed(self) -> bool:
        """Whether the deadline has passed (each call is one cooperative check)."""
        self.checks += 1
        expired = self.clock() > self.at
        self.expired_checks += expired
        return expired

    def left(self) -> float:
        """Seconds left on the clock (negative once passed); not counted as a check."""
        return self.at - self.clock()
