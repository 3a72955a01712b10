"""Named wall-clock timers for the phases that the model's item timers cannot split
(e.g. the contact search inside a contact pair's assembly)."""
from __future__ import annotations

import time
from collections import defaultdict
from contextlib import contextmanager
from typing import Iterator

__all__ = ["TIMERS", "timed", "reset"]

#: phase name -> accumulated seconds (process-wide; reset by the runner per run)
TIMERS: dict[str, float] = defaultdict(float)


@contextmanager
def timed(name: str) -> Iterator[None]:
    """Add the time spent in the block to ``TIMERS[name]``."""
    t0 = time.perf_counter()
    try:
        yield
    finally:
        TIMERS[name] += time.perf_counter() - t0


def reset() -> None:
    TIMERS.clear()
