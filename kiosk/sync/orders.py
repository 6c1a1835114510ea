"""The kiosk's side of orders (protocol §4): a thread that long-polls the station for the visits
ordered for this kiosk, and the call that starts one with the code staff typed.

The thread never touches the session or the screens: it hands each new list to ``on_orders``,
which the app runs on its own thread (``app.call_from_thread``).
"""

from __future__ import annotations

import sqlite3
import threading
from collections.abc import Callable, Sequence
from contextlib import closing
from pathlib import Path
from urllib.parse import quote

from kiosk.core.visits import Order, parse_cancelled, parse_orders
from kiosk.sync.client import Backoff
from kiosk.sync.http import Station, Unreachable

#: how long one long poll for orders may wait at the station
POLL_WAIT_S = 20.0
#: the most orders a poll reports as held (the newest sessions')
MOST_HELD = 200
#: the orders whose visit a kiosk can still go on with: a session of them running or interrupted
#: (staff continue it), or with rows the station has not had yet (it cannot judge the visit yet)
HELD = """
SELECT e.detail FROM events e JOIN sessions s ON s.id = e.session_id
WHERE e.kind = 'visit' AND e.detail LIKE 'order %'
  AND (s.status IN ('running', 'interrupted')
       OR EXISTS (SELECT 1 FROM outbox o WHERE o.session_id = s.id AND o.parked IS NULL))
ORDER BY s.started_at DESC LIMIT ?
"""


def held_orders(path: Path) -> list[str]:
    """The orders the kiosk database at ``path`` holds (:data:`HELD`), read through a connection
    of its own (the poll's thread shares none). A database not made yet holds none."""
    if not Path(path).exists():
        return []
    with closing(sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=10.0)) as db:
        rows = db.execute(HELD, (MOST_HELD,)).fetchall()
    return list(dict.fromkeys(detail.partition(" ")[2] for (detail,) in rows))


class OrderRefused(Exception):
    """The station did not start the order (wrong code, too many tries, refused): one sentence for staff."""


class OrderWatcher:
    """Keeps ``on_orders(orders, problems)`` told of the visits waiting for this kiosk."""

    def __init__(
        self,
        station: Station,
        *,
        instruments: Sequence[str],
        languages: Sequence[str],
        on_orders: Callable[[list[Order], list[str]], None],
        poll_wait_s: float = POLL_WAIT_S,
        backoff: tuple[float, float] = (0.5, 30.0),
        held: Callable[[], list[str]] | None = None,
        on_cancelled: Callable[[tuple[str, ...]], None] | None = None,
    ) -> None:
        """``held()``: the orders this kiosk can still go on with (:func:`held_orders`), told to
        the station on every poll so an order whose kiosk stopped mid-visit heals (None: not told).
        ``on_cancelled(ids)``: the station's cancelled orders this kiosk may run, with each new list
        (the kiosk ends a running visit among them)."""
        self.station = station
        self._held = held
        self._instruments, self._languages = list(instruments), list(languages)
        self._on_orders = on_orders
        self._on_cancelled = on_cancelled
        self._poll_wait_s = poll_wait_s
        self._backoff = backoff
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        #: the last problem reaching the station (None while all is well)
        self.problem: str | None = None

    def start(self) -> None:
        self._thread = threading.Thread(target=self._poll_forever, name="station orders", daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        self._stopping.set()
        self.station.abort()
        if self._thread is not None:
            self._thread.join(timeout)

    def _poll_forever(self) -> None:
        backoff = Backoff(*self._backoff)
        version: str | None = None
        while not self._stopping.is_set():
            query = f"/api/v1/orders?wait={self._poll_wait_s:g}" + (f"&version={version}" if version else "")
            try:
                if self._held is not None:
                    query += "&held=" + quote(",".join(self._held()), safe=",")
                status, body = self.station.request("GET", query, timeout=self._poll_wait_s + 15)
            except (Unreachable, sqlite3.Error) as exc:
                self.problem = str(exc)
                self._stopping.wait(backoff.next())
                continue
            if status != 200 or not isinstance(body, dict):
                self.problem = f"the station answered {status} to the orders poll"
                self._stopping.wait(backoff.next())
                continue
            self.problem = None
            backoff.reset()
            if body.get("version") != version and not self._stopping.is_set():
                version = str(body.get("version"))
                self._on_orders(*parse_orders(body, self._instruments, self._languages))
                if self._on_cancelled is not None:
                    self._on_cancelled(parse_cancelled(body))


def start_order(station: Station, code: str, *, instruments: Sequence[str], languages: Sequence[str]) -> Order:
    """Start the visit whose code staff typed, checked as :func:`kiosk.core.visits.parse_orders` checks
    the list; :class:`OrderRefused` (or ``Unreachable``) with why not."""
    status, body = station.request("POST", "/api/v1/orders/start", {"code": code})
    error = body.get("error") if isinstance(body, dict) else None
    if status == 404:
        raise OrderRefused("That code is not one of this kiosk's visits: check it on the ward station.")
    if status == 429:
        wait = body.get("retry_after_s") if isinstance(body, dict) else None
        when = f"in {wait} seconds" if isinstance(wait, int) and 0 < wait <= 3600 else "in a few minutes"
        raise OrderRefused(f"After wrong codes the ward station checks the next one {when}: type it again then.")
    if status != 200 or not isinstance(body, dict):
        raise OrderRefused(f"The ward station answered {status}{': ' + error if error else ''}.")
    found, problems = parse_orders({"orders": [body.get("order")]}, instruments, languages)
    if not found:
        raise OrderRefused(f"The ward station's order cannot be run here: {'; '.join(problems)}.")
    return found[0]
