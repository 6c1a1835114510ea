"""One writer at a time on SQLite, alerts first.

SQLite lets one transaction write at a time; the others wait in its busy handler, which sleeps
and retries with no order, so under 50 kiosks' routine batches a doctor call's transaction lost
the race again and again (alert -> stored p99 6.5 s, page p99 16.2 s in ``bench/station.py
--history --database sqlite``). The station's kiosk-facing writers take this gate instead: a
waiting urgent writer (a batch of alerts) goes before every waiting routine one, so it waits for
at most the one transaction in progress. PostgreSQL writes rows concurrently and has no gate.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator


class WriteGate:
    """A lock with two queues: urgent holders are admitted before routine ones. Re-entrant per
    thread (a writer inside the gate may open another gated transaction)."""

    def __init__(self) -> None:
        self._cond = threading.Condition()
        self._holder: int | None = None
        self._depth = 0
        self._urgent_waiting = 0
        self._waiting_routine = 0

    @contextlib.contextmanager
    def held(self, urgent: bool = False) -> Iterator[None]:
        """Hold the gate for the ``with`` block."""
        me = threading.get_ident()
        with self._cond:
            if self._holder == me:
                self._depth += 1
            else:
                if urgent:
                    self._urgent_waiting += 1
                else:
                    self._waiting_routine += 1
                self._cond.notify_all()  # (for whoever watches the queues)
                try:
                    while self._holder is not None or (not urgent and self._urgent_waiting):
                        self._cond.wait()
                finally:
                    if urgent:
                        self._urgent_waiting -= 1
                    else:
                        self._waiting_routine -= 1
                self._holder, self._depth = me, 1
        try:
            yield
        finally:
            with self._cond:
                self._depth -= 1
                if self._depth == 0:
                    self._holder = None
                    self._cond.notify_all()
