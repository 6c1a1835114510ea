"""The store's write discipline on its one SQLite connection: transactions that group an
operation's writes into one fsynced commit, writes to a session only while this kiosk holds it,
and the outbox row each change queues for the ward station.

Apart from :class:`kiosk.store.database.Store` so the leases (:mod:`kiosk.store.custody`) and the
writes share one transaction without either knowing the store."""

from __future__ import annotations

import contextlib
import json
import sqlite3
from collections.abc import Callable, Iterator
from datetime import UTC, datetime
from typing import Any

#: session-log kinds that are alerts for the ward (or end one), with the name the station protocol
#: gives them; sent before any other row. A patient leaving (person_lost) is sent first too, but
#: the ward is alerted only by away_alert, once they have been away as long as the site says.
ALERT_EVENTS = {
    "call_doctor": "doctor_called",
    "clinician_continue": "doctor_continued",
    "person_lost": "person_lost",
    "person_back": "person_back",
    "away_alert": "away_alert",
    "unattended": "unattended",
    "unattended_ended": "unattended_ended",
}


class Transactions:
    """Writes on ``db`` (autocommit mode: this class begins and ends transactions).

    ``guard(session_id)`` raises unless this kiosk holds the session (called once per transaction
    and session); ``outbox`` queues every change for the station; ``wall`` dates the rows.
    """

    def __init__(
        self, db: sqlite3.Connection, *, wall: Callable[[], float], outbox: bool, guard: Callable[[str], None]
    ) -> None:
        self.db = db
        self.wall = wall
        self.outbox = outbox
        self._guard = guard
        #: depth of nested transaction() blocks; writes inside them commit when the outermost ends
        self._grouping = 0
        #: sessions whose lease this transaction has checked (a check per transaction is enough: it
        #: holds the write lock, so no other kiosk can take the lease before it ends)
        self.held: set[str] = set()
        #: outbox rows written in this transaction: (any, any alert)
        self._queued = (False, False)
        #: called after a commit that queued outbox rows (True: one is an alert): the sync client's wake-up
        self.on_outbox: Callable[[bool], None] | None = None

    @contextlib.contextmanager
    def transaction(self) -> Iterator[None]:
        """Group writes into one commit (fsynced): a crash keeps all of them or none.

        The session runs each of its operations in one, so an answer is never stored without the
        QoS context batch it published. Nested use joins the outer transaction. If the outermost
        block raises (an error, Ctrl-C) everything it wrote is rolled back: half an operation is
        never stored.

        The transaction begins with its first write, so an operation that writes nothing (most
        polls of the attempt clock) takes no write lock and syncs nothing.
        """
        self._grouping += 1
        completed = False
        try:
            yield
            completed = True
        finally:
            self._grouping -= 1
            if not self._grouping and self.db.in_transaction:
                if completed:
                    self._commit()
                else:
                    self._rollback()

    def _commit(self) -> None:
        try:
            self.db.commit()
        except BaseException:
            self._rollback()
            raise
        queued, alert = self._queued
        self.held.clear()
        self._queued = (False, False)
        if queued and self.on_outbox is not None:
            self.on_outbox(alert)

    def _rollback(self) -> None:
        self.held.clear()
        self._queued = (False, False)
        if self.db.in_transaction:
            self.db.rollback()

    def write(self, sql: str, args: tuple[Any, ...], session: str | None = None) -> None:
        """One statement in the current transaction; with ``session``, only while this kiosk holds it."""
        with self.transaction():
            if not self.db.in_transaction:
                self.db.execute("BEGIN IMMEDIATE")
            if session is not None and session not in self.held:
                self._guard(session)
                self.held.add(session)
            self.db.execute(sql, args)

    def record(self, kind: str, session_id: str, payload: dict[str, Any], sql: str, args: tuple[Any, ...]) -> None:
        """A change to a held session, and its outbox row, in one transaction."""
        with self.transaction():
            self.write(sql, args, session=session_id)
            self.queue(kind, session_id, payload)

    def queue(self, kind: str, session_id: str | None, payload: dict[str, Any]) -> None:
        """The change's outbox row (protocol §1), when a station is configured."""
        if not self.outbox:
            return
        alert = kind == "record_event" and payload.get("kind") in ALERT_EVENTS
        if alert:
            payload = {**payload, "kind": ALERT_EVENTS[payload["kind"]]}
        self.db.execute(
            "INSERT INTO outbox (kind, session_id, payload, at, alert) VALUES (?, ?, ?, ?, ?)",
            (kind, session_id, json.dumps(payload, ensure_ascii=False), self.iso_now(), int(alert)),
        )
        self._queued = (True, self._queued[1] or alert)

    def next_seq(self, table: str, session_id: str) -> int:
        """The next ``seq`` of a session's rows in ``table``."""
        row = self.db.execute(
            f"SELECT COALESCE(MAX(seq), -1) + 1 FROM {table} WHERE session_id = ?", (session_id,)
        ).fetchone()
        return int(row[0])

    def iso_now(self) -> str:
        """Now, ISO 8601 UTC with a Z."""
        return datetime.fromtimestamp(self.wall(), UTC).isoformat().replace("+00:00", "Z")
