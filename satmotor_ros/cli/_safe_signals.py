# SPDX-License-Identifier: Apache-2.0
"""
Ctrl-C and SIGTERM delivered where the demo can act on them, not inside rclpy's internals.

Python raises a signal's exception at whatever bytecode runs when it arrives. While an rclpy
executor spins, that is often a ``Future.__del__`` of a finished callback's task: an exception
raised in a finaliser is printed (``Exception ignored in: Future.__del__``) and dropped, so the
Ctrl-C was lost. Inside :func:`signals_at_safe_points` the signal is only noted; the spin loop
calls the returned check between spins, where the program's own handler then raises it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
import signal
import threading
from types import FrameType
from typing import Any

_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _deliver(signum: int, handler: Any) -> None:
    """Act on `signum` as `handler` (what was installed before) would have."""
    if callable(handler):
        handler(signum, None)
    elif handler == signal.SIG_DFL:
        signal.raise_signal(signum)  # the handler is restored by now: the default action
    # SIG_IGN, or None (not installed from Python): nothing to do


@contextmanager
def signals_at_safe_points() -> Iterator[Callable[[], None]]:
    """
    Note SIGINT and SIGTERM instead of raising them; yield the check that raises them.

    Yields
    ------
    callable
        ``check()``: if a signal came, restore the handlers and run the one of the first
        signal (for Ctrl-C, raise KeyboardInterrupt) here. A signal that comes after the last
        check is delivered when the block ends.

    """
    if threading.current_thread() is not threading.main_thread():
        yield lambda: None  # only the main thread receives signals and may set handlers
        return
    pending: list[int] = []

    def note(signum: int, frame: FrameType | None) -> None:
        pending.append(signum)

    previous: dict[int, Any] = {signum: signal.signal(signum, note) for signum in _SIGNALS}

    def restore() -> None:
        for signum, handler in previous.items():
            signal.signal(signum, handler)

    def check() -> None:
        if pending:
            signum = pending[0]
            restore()
            pending.clear()  # once: the handlers are the program's own again
            _deliver(signum, previous[signum])

    try:
        yield check
    finally:
        restore()
    if pending:
        _deliver(pending[0], previous[pending[0]])
