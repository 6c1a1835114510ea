"""The sync client: two background threads between the kiosk's database and the ward station.

* **delivery** (protocol §1, §2): sends the outbox in ``seq`` order; deletes only the rows the station lists as
  stored, so a connection cut after the station stored a batch but before its reply only means
  the batch is sent again and acknowledged again (the station is idempotent on the seq); retries
  with exponential backoff (0.5 s doubling to 60 s, jittered) on any connection error, timeout,
  5xx, 401 or 429; parks the row a refusal names (a 422's ``seq``), or narrows a batch the
  station refuses (another 4xx) down to the row at fault and parks it, and goes on with the rest:
  one bad row never holds the outbox up. It also posts the live status on every change and as a heartbeat.
* **alerts** (doctor called, patient away/back): a thread and an outbox connection of their own,
  woken by the commit that queued one, in requests of their own; routine rows wait while an alert
  is pending (alerts first, as before), but an alert never waits for a routine batch in flight
  (under load a batch of 500 rows took seconds at the station, and the alert queued behind it:
  alert -> stored p99 4.4-6.5 s in ``bench/station.py --history``).
* **commands** (§3): long-polls the station and hands each command to ``on_command`` -- the app
  runs it on its own thread through the same operations as the clinician screen -- then acks it.

The kiosk never waits for either: a station down for an hour only means rows accumulate in the
outbox, and they go when it is back.
"""

from __future__ import annotations

import random
import secrets
import sqlite3
import threading
import time
from collections.abc import Callable, Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, cast

from kiosk.sync.http import Station, Unreachable
from kiosk.sync.outbox import Outbox

#: rows per request (the protocol's maximum)
BATCH = 500
#: the live status is re-sent at least this often (the station shows a kiosk offline after 30 s)
HEARTBEAT_S = 10.0
#: how long one long poll for commands may wait at the station
POLL_WAIT_S = 20.0
#: the alerts' thread looks at the outbox at least this often (a wake-up is what sends one at once)
ALERT_LOOK_S = 5.0

#: a command's outcome: ("done", None) or ("refused", why)
Outcome = tuple[str, str | None]


class Refused(Exception):
    """The station answered, but not with success: retried later (the message says what it said)."""


class Backoff:
    """Exponential backoff with jitter: ``first`` seconds, doubling up to ``most``."""

    def __init__(self, first: float = 0.5, most: float = 60.0) -> None:
        self.first, self.most = first, most
        self._failures = 0

    def next(self) -> float:
        """How long to wait after one more failure."""
        delay = min(self.most, self.first * 2**self._failures)
        self._failures += 1
        return delay * random.uniform(0.75, 1.0)

    def reset(self) -> None:
        """A success: the next failure waits ``first`` again."""
        self._failures = 0


class SyncClient:
    """Delivers the outbox of the database at ``db_path`` to the station at ``url`` as ``kiosk_id``.

    ``on_command(command) -> (result, reason)`` applies a station command (called on the commands
    thread; it must hand the work to the UI thread itself; None: not this process's to answer,
    no ack, so the station re-delivers it); without it no commands are fetched.
    ``backoff`` is (first, most) in seconds.
    """

    def __init__(
        self,
        db_path: Path,
        *,
        url: str,
        token: str,
        kiosk_id: str,
        on_command: Callable[[Mapping[str, Any]], Outcome | None] | None = None,
        backoff: tuple[float, float] = (0.5, 60.0),
        heartbeat_s: float = HEARTBEAT_S,
        poll_wait_s: float = POLL_WAIT_S,
    ) -> None:
        self.station = Station(url, token)
        self.kiosk_id = kiosk_id
        self.outbox = Outbox(db_path)
        self._on_command = on_command
        self._backoff = backoff
        self._heartbeat_s = heartbeat_s
        self._poll_wait_s = poll_wait_s
        self._wake = threading.Event()
        self._alert_wake = threading.Event()
        self._db_path = db_path
        self._stopping = threading.Event()
        self._lock = threading.Lock()
        self._status: dict[str, Any] = {"session_id": None, "phase": "welcome"}
        #: this process among the kiosk's (two browser tabs are two): the station shows the one
        #: running a test, not the other's welcome (station.ward.shown_status)
        self.instance = secrets.token_hex(6)
        self._status_changed = True
        #: rows per request, per lane: narrowed while the station refuses a batch without naming a row
        self._batch = {"all": BATCH, "alerts": BATCH, "routine": BATCH}
        self._threads: list[threading.Thread] = []
        #: the last problem reaching the station (None while all is well), for staff
        self.problem: str | None = None

    # -- the kiosk's side (any thread) ------------------------------------------------------------

    def start(self) -> None:
        """Start the delivery thread (and the commands thread, with ``on_command``)."""
        self._threads = [
            threading.Thread(target=self._deliver_forever, name="station sync", daemon=True),
            threading.Thread(target=self._alerts_forever, name="station alerts", daemon=True),
        ]
        if self._on_command is not None:
            self._threads.append(threading.Thread(target=self._poll_forever, name="station commands", daemon=True))
        for thread in self._threads:
            thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop the threads (a request in flight is cut short; undelivered rows stay in the outbox)."""
        self._stopping.set()
        self._wake.set()
        self._alert_wake.set()
        self.station.abort()
        for thread in self._threads:
            thread.join(timeout)
        if not any(thread.is_alive() for thread in self._threads):
            self.outbox.close()

    def wake(self, alert: bool = False) -> None:
        """Rows were committed to the outbox: deliver now (the store calls this after its commit;
        ``alert``: one of them is an alert, which goes on its own thread at once)."""
        if alert:
            self._alert_wake.set()
        self._wake.set()

    def set_status(self, status: Mapping[str, Any]) -> None:
        """What the ward view shows of this kiosk now (protocol §2); sent at once if it changed."""
        with self._lock:
            if dict(status) != self._status:
                self._status = dict(status)
                self._status_changed = True
                self._wake.set()

    def deliver_all(self, within_s: float) -> int:
        """Deliver what the outbox holds, trying for at most ``within_s`` seconds (for a command
        that exits, such as ``kiosk replay``); returns how many rows are still waiting."""
        deadline = time.monotonic() + within_s
        backoff = Backoff(*self._backoff)
        while self.outbox.count() and not self._stopping.is_set():
            try:
                self._deliver_step()
                self.problem = None
                backoff.reset()
            except (Unreachable, Refused) as problem:
                self.problem = str(problem)
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._stopping.wait(min(left, backoff.next()))
        return self.outbox.count()

    # -- delivery thread ----------------------------------------------------------------------------

    def _deliver_forever(self) -> None:
        backoff = Backoff(*self._backoff)
        next_heartbeat = 0.0
        while not self._stopping.is_set():
            self._wake.clear()  # before looking: a row committed from now on wakes the wait below
            try:
                sent = self._deliver_step(self.outbox, "routine")
                if self._status_due(next_heartbeat):
                    self._send_status()
                    next_heartbeat = time.monotonic() + self._heartbeat_s
            except (Unreachable, Refused, sqlite3.Error) as problem:  # a busy database too: try again
                self.problem = str(problem)
                self._stopping.wait(backoff.next())
                continue
            self.problem = None
            backoff.reset()
            if not sent:
                self._wake.wait(max(0.0, next_heartbeat - time.monotonic()))

    def _alerts_forever(self) -> None:
        """The alerts' own lane: woken by the commit that queued one (and every few seconds, for
        one committed before this thread started or left by a failure), sends them at once."""
        outbox = Outbox(self._db_path)
        backoff = Backoff(*self._backoff)
        try:
            while not self._stopping.is_set():
                self._alert_wake.clear()
                try:
                    if self._deliver_step(outbox, "alerts"):
                        backoff.reset()
                        self._wake.set()  # the routine rows waited for these
                        continue
                except (Unreachable, Refused, sqlite3.Error) as problem:
                    self.problem = str(problem)
                    self._stopping.wait(backoff.next())
                    continue
                self._alert_wake.wait(ALERT_LOOK_S)
        finally:
            outbox.close()

    def _deliver_step(self, outbox: Outbox | None = None, lane: str = "all") -> bool:
        """Send one batch of ``lane``: "alerts", "routine" (the rest), or "all" (alerts first);
        True if there was one. Unreachable/Refused to retry later."""
        outbox = outbox or self.outbox
        batch = self._batch[lane]
        if lane == "alerts":
            rows = outbox.pending(batch, alerts_only=True)
        elif lane == "routine":
            if outbox.pending(1, alerts_only=True):  # alerts first: their lane sends them, then wakes this one
                self._alert_wake.set()
                return False
            rows = outbox.pending(batch, routine_only=True)
        else:
            rows = outbox.pending(batch, alerts_only=True) or outbox.pending(batch)
        if not rows:
            return False
        status, body = self.station.request(
            "POST", "/api/v1/sync", {"kiosk_id": self.kiosk_id, "events": [r.event() for r in rows]}
        )
        if status == 200:
            sent = {r.seq for r in rows}
            stored = body.get("stored") if isinstance(body, dict) else None
            outbox.delivered(sorted(s for s in stored or () if isinstance(s, int) and s in sent))
            self._batch[lane] = BATCH
            return True
        if status in (401, 429) or status >= 500 or status < 400:
            raise Refused(f"the station answered {status}{_reason(body)}")
        # the station refuses something in this batch: park the row it names (protocol: a 422 body's
        # "seq"), else narrow the batch down to the row; the rest goes on in the next request
        named = body.get("seq") if isinstance(body, dict) else None
        if len(rows) == 1 or any(r.seq == named for r in rows):
            # several rows: the station named one of them (an int, checked just above)
            outbox.park(cast(int, named) if len(rows) > 1 else rows[0].seq, f"{status}{_reason(body)}")
        else:
            self._batch[lane] = max(1, len(rows) // 2)
        return True

    def _status_due(self, next_heartbeat: float) -> bool:
        with self._lock:
            return self._status_changed or time.monotonic() >= next_heartbeat

    def _send_status(self) -> None:
        with self._lock:
            status, self._status_changed = dict(self._status), False
        try:
            code, body = self.station.request(
                "POST",
                "/api/v1/status",
                {**status, "kiosk_id": self.kiosk_id, "instance": self.instance, "at": datetime.now(UTC).isoformat()},
            )
        except Unreachable:
            with self._lock:
                self._status_changed = True  # send it again once the station answers
            raise
        if code != 200:
            with self._lock:
                self._status_changed = True
            raise Refused(f"the station answered {code} to the status{_reason(body)}")

    # -- commands thread ----------------------------------------------------------------------------

    def _poll_forever(self) -> None:
        assert self._on_command is not None
        backoff = Backoff(*self._backoff)
        while not self._stopping.is_set():
            try:
                status, body = self.station.request(
                    "GET", f"/api/v1/commands?wait={self._poll_wait_s:g}", timeout=self._poll_wait_s + 15
                )
                if status != 200 or not isinstance(body, dict):
                    raise Refused(f"the station answered {status} to the command poll{_reason(body)}")
            except (Unreachable, Refused):
                self._stopping.wait(backoff.next())
                continue
            backoff.reset()
            for command in body.get("commands") or ():
                if self._stopping.is_set() or not isinstance(command, dict):
                    break
                try:
                    outcome = self._on_command(command)
                except Exception:  # the kiosk is closing: not acked, so re-delivered
                    continue
                if outcome is None:
                    continue
                result, reason = outcome
                ack: dict[str, Any] = {"result": result}
                if reason:
                    ack["reason"] = reason
                try:
                    self.station.request("POST", f"/api/v1/commands/{command.get('id')}/ack", ack)
                except Unreachable:
                    pass  # re-delivered, and refused then if it no longer applies


def _reason(body: Any) -> str:
    if isinstance(body, dict) and isinstance(body.get("error"), str):
        return f": {body['error']}"
    return ""
