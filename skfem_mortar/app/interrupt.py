"""Ctrl-C that is never lost: a run stops at the next step at the latest.

Python turns SIGINT into a ``KeyboardInterrupt`` wherever the interpreter happens to
be, and where that is a finalizer or a callback from compiled code the exception is
printed as "ignored" and dropped: the run would go on.  While a command runs,
:func:`held_ctrl_c` installs a handler that records the signal before it raises, and
:func:`check` (called by the runner after every converged step) raises again when a
signal was recorded, so the command ends with exit 130 either way.
"""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Iterator

__all__ = ["held_ctrl_c", "check"]

_received = [False]


def _on_sigint(signum, frame) -> None:
    """Record the Ctrl-C, then raise as Python's own handler does."""
    _received[0] = True
    raise KeyboardInterrupt


@contextmanager
def held_ctrl_c() -> Iterator[None]:
    """Record every Ctrl-C while the block runs (only in the main thread and only
    over Python's own handler: a handler or ``SIG_IGN`` the caller set is kept)."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield
        return
    _received[0] = False
    signal.signal(signal.SIGINT, _on_sigint)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        _received[0] = False


def check() -> None:
    """Raise ``KeyboardInterrupt`` if a Ctrl-C was recorded (and perhaps dropped)."""
    if _received[0]:
        raise KeyboardInterrupt
