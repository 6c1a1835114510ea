"""Who holds a session, for :class:`kiosk.store.database.Store`: the lease taken when a session is
created or continued and checked in every write, its renewal and release, and the sweep that marks
interrupted the running sessions whose kiosk is gone or that grew too old (see
:mod:`kiosk.store.lease` for when a lease lapses). It shares the store's connection and
transactions (:mod:`kiosk.store.transactions`), given to it when it is made."""

from __future__ import annotations

import sqlite3
from collections.abc import Callable
from datetime import UTC, datetime

from kiosk.store.lease import Owner, SessionTaken, lapsed
from kiosk.store.transactions import Transactions


class Custody:
    """This kiosk's leases on sessions. ``owner`` is this kiosk process; ``lease_ttl_s`` how long an
    unrenewed lease lasts; ``interrupt_after_s`` the age after which a running session counts as
    interrupted (None: no limit); ``wall`` the epoch seconds leases are dated with."""

    def __init__(
        self,
        tx: Transactions,
        *,
        owner: Owner,
        lease_ttl_s: float,
        interrupt_after_s: float | None,
        wall: Callable[[], float],
    ) -> None:
        self.tx = tx
        self._db: sqlite3.Connection = tx.db
        self.owner = owner
        self.lease_ttl_s = lease_ttl_s
        self.interrupt_after_s = interrupt_after_s
        self._wall = wall

    def status(self, session_id: str) -> str | None:
        """The session's status ("running", "finished", ...), or None if it is not stored."""
        row = self._db.execute("SELECT status FROM sessions WHERE id = ?", (session_id,)).fetchone()
        return row[0] if row else None

    def _holder(self, session_id: str) -> tuple[Owner, float] | None:
        row = self._db.execute(
            "SELECT host, pid, token, renewed_at FROM leases WHERE session_id = ?", (session_id,)
        ).fetchone()
        return (Owner(row[0], int(row[1]), row[2]), float(row[3])) if row else None

    def check_held(self, session_id: str) -> None:
        """Inside a write transaction: this kiosk holds the session, else SessionTaken."""
        why = self.why_not_held(session_id)
        if why is not None:
            raise SessionTaken(why)

    def why_not_held(self, session_id: str) -> str | None:
        """Why this kiosk may not record in the session (a sentence for staff), or None if it holds it."""
        holder = self._holder(session_id)
        if holder is not None and holder[0].token == self.owner.token:
            return None
        if holder is not None:
            return (
                f"session {session_id} is open on another kiosk, {holder[0].describe()}: "
                "one kiosk at a time records a test"
            )
        row = self._db.execute("SELECT status, interrupted_reason FROM sessions WHERE id = ?", (session_id,)).fetchone()
        if row is None:
            return f"session {session_id} is not stored"
        why = f" ({row[1]})" if row[0] == "interrupted" and row[1] else ""
        return f"session {session_id} is no longer held by this kiosk: it is {row[0]}{why}"

    def take(self, session_id: str) -> None:
        """Inside a write transaction: take the session's lease unless a live kiosk holds it."""
        holder = self._holder(session_id)
        now = self._wall()
        if (
            holder is not None
            and holder[0].token != self.owner.token
            and lapsed(holder[0], holder[1], now, self.lease_ttl_s, self.owner) is None
        ):
            raise SessionTaken(
                f"session {session_id} is open on another kiosk, {holder[0].describe()}: "
                "one kiosk at a time records a test"
            )
        self._db.execute(
            "INSERT OR REPLACE INTO leases VALUES (?, ?, ?, ?, ?, ?)",
            (session_id, self.owner.host, self.owner.pid, self.owner.token, now, now),
        )
        self.tx.held.add(session_id)

    def my_sessions(self) -> list[str]:
        return [r[0] for r in self._db.execute("SELECT session_id FROM leases WHERE token = ?", (self.owner.token,))]

    def held_elsewhere(self, session_id: str) -> bool:
        """Whether another running kiosk process holds the session (say another browser tab of
        `kiosk serve` on this data directory)."""
        holder = self._holder(session_id)
        return (
            holder is not None
            and holder[0].token != self.owner.token
            and lapsed(holder[0], holder[1], self._wall(), self.lease_ttl_s, self.owner) is None
        )

    def holds(self, session_id: str) -> bool:
        """Whether this kiosk holds the session now."""
        return self.why_not_held(session_id) is None

    def renew(self) -> None:
        """Renew this kiosk's leases (the running kiosk calls this every third of the lease time)."""
        if not self.my_sessions():
            return
        with self.tx.transaction():
            self.tx.write("UPDATE leases SET renewed_at = ? WHERE token = ?", (self._wall(), self.owner.token))

    def release(self, session_id: str, reason: str = "its kiosk moved on to another test") -> None:
        """Give up the session: this kiosk no longer records in it. Still running, it is interrupted."""
        with self.tx.transaction():
            if not self.holds(session_id):
                return
            if self.status(session_id) == "running":
                self._interrupt(session_id, reason)
            self.tx.write("DELETE FROM leases WHERE session_id = ?", (session_id,))

    def release_others(self, keep: str) -> None:
        """Release every session this kiosk holds but ``keep`` (its running one)."""
        for session_id in self.my_sessions():
            if session_id != keep:
                self.release(session_id)

    def _interrupt(self, session_id: str, reason: str) -> None:
        self.tx.write(
            "UPDATE sessions SET status = 'interrupted', interrupted_at = ?, interrupted_reason = ?"
            " WHERE id = ? AND status = 'running'",
            (self.tx.iso_now(), reason, session_id),
        )
        self.tx.queue("mark_interrupted", session_id, {"reason": reason})

    def _stale(self) -> list[tuple[str, str]]:
        """Running sessions whose kiosk is gone, or older than the limit: (id, why)."""
        now = self._wall()
        stale = []
        for session_id, started_at, simulated, host, pid, token, renewed_at in self._db.execute(
            "SELECT s.id, s.started_at, s.simulated, l.host, l.pid, l.token, l.renewed_at FROM sessions s"
            " LEFT JOIN leases l ON l.session_id = s.id WHERE s.status = 'running'"
        ).fetchall():
            why = (
                "no kiosk held it"
                if host is None
                else lapsed(Owner(host, int(pid), token), float(renewed_at), now, self.lease_ttl_s, self.owner)
            )
            # a simulated session's start is on the replay's simulated clock: its age means nothing
            if (
                why is None
                and not simulated
                and self.interrupt_after_s is not None
                and _age_s(started_at, now) > self.interrupt_after_s
            ):
                why = f"not finished within {self.interrupt_after_s / 60:g} minutes"
            if why is not None:
                stale.append((session_id, why))
        return stale

    def interrupt_stale(self) -> list[str]:
        """Mark interrupted every running session whose kiosk is gone (process ended on this host,
        lease not renewed) or that is older than ``interrupt_after_s``; returns their ids. A patient
        is never offered one; staff may continue it (:meth:`continue_session`)."""
        if not self._stale():
            return []  # the usual case: a read, no write lock
        with self.tx.transaction():
            self._db.execute("BEGIN IMMEDIATE")
            stale = self._stale()  # again under the lock: another kiosk may have acted meanwhile
            for session_id, why in stale:
                self._interrupt(session_id, why)
                self._db.execute("DELETE FROM leases WHERE session_id = ?", (session_id,))
        return [session_id for session_id, _ in stale]

    def continue_session(self, session_id: str) -> None:
        """Staff continue an interrupted session on this kiosk: it is taken (atomically; SessionTaken
        if a running kiosk holds it) and running again. ValueError if it cannot be continued."""
        self.interrupt_stale()
        with self.tx.transaction():
            self._db.execute("BEGIN IMMEDIATE")
            status, simulated = self._db.execute(
                "SELECT status, simulated FROM sessions WHERE id = ?", (session_id,)
            ).fetchone()
            if simulated:
                raise ValueError(f"session {session_id} is a simulated (replayed) session: it cannot be continued")
            if status == "running":
                self.take(session_id)  # SessionTaken unless it is this kiosk's already
            elif status != "interrupted":
                raise ValueError(f"session {session_id} is {status}: only an interrupted test can be continued")
            self.take(session_id)
            self._db.execute(
                "UPDATE sessions SET status = 'running', interrupted_at = NULL, interrupted_reason = NULL WHERE id = ?",
                (session_id,),
            )
            self.tx.queue("continue_session", session_id, {})


def _age_s(started_at: str, now: float) -> float:
    """Seconds since an ISO 8601 start time (naive times are UTC)."""
    try:
        started = datetime.fromisoformat(started_at.replace("Z", "+00:00"))
    except ValueError:
        return 0.0
    if started.tzinfo is None:
        started = started.replace(tzinfo=UTC)
    return now - started.timestamp()
