"""The outbox table as the sync client sees it, through its own SQLite connection.

The session's :class:`~kiosk.store.database.Store` writes rows in the same transaction as each change;
this side reads them in ``seq`` order (alerts first), deletes the ones the station stored, and
parks one the station refuses (kept, with the reason, never silently dropped). Its own
connection means the client's thread never shares the session's ``sqlite3`` connection.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import Any

from basis import record

#: how long a delete waits for the kiosk's own write transaction (they are short)
BUSY_TIMEOUT_S = 10.0


@record
class Row:
    """One stored change waiting for the station."""

    seq: int
    kind: str
    session_id: str | None
    payload: dict[str, Any]
    at: str
    alert: bool

    def event(self) -> dict[str, Any]:
        """The row as the protocol's ``events`` entry."""
        return {
            "seq": self.seq,
            "kind": self.kind,
            "session_id": self.session_id,
            "payload": self.payload,
            "at": self.at,
        }


class Outbox:
    """Read, acknowledge and park outbox rows of the kiosk database at ``path``."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._db = sqlite3.connect(path, isolation_level=None, timeout=BUSY_TIMEOUT_S, check_same_thread=False)
        self._db.execute("PRAGMA synchronous=FULL")

    def close(self) -> None:
        """Close this connection."""
        self._db.close()

    def pending(self, limit: int, alerts_only: bool = False, routine_only: bool = False) -> list[Row]:
        """Up to ``limit`` rows not yet delivered nor parked, in ``seq`` order (only the alerts, or
        only the other rows, when asked)."""
        where = "parked IS NULL" + (" AND alert = 1" if alerts_only else " AND alert = 0" if routine_only else "")
        rows = self._db.execute(
            f"SELECT seq, kind, session_id, payload, at, alert FROM outbox WHERE {where} ORDER BY seq LIMIT ?", (limit,)
        ).fetchall()
        return [
            Row(seq, kind, session_id, json.loads(payload), at, bool(alert))
            for seq, kind, session_id, payload, at, alert in rows
        ]

    def count(self) -> int:
        """Rows waiting for the station (parked ones excluded)."""
        return int(self._db.execute("SELECT COUNT(*) FROM outbox WHERE parked IS NULL").fetchone()[0])

    def delivered(self, seqs: list[int]) -> None:
        """The station stored these: they leave the outbox."""
        if seqs:  # one transaction: one sync to disk for the batch
            self._db.execute("BEGIN IMMEDIATE")
            try:
                self._db.executemany("DELETE FROM outbox WHERE seq = ?", [(s,) for s in seqs])
                self._db.execute("COMMIT")
            except BaseException:
                self._db.execute("ROLLBACK")
                raise

    def park(self, seq: int, reason: str) -> None:
        """The station refuses this row: keep it aside with the reason, for an engineer to look at."""
        self._db.execute("UPDATE outbox SET parked = ? WHERE seq = ?", (reason[:500] or "refused", seq))

    def parked(self) -> list[tuple[int, str]]:
        """The rows kept aside, with why."""
        return [
            (int(s), str(r))
            for s, r in self._db.execute("SELECT seq, parked FROM outbox WHERE parked IS NOT NULL ORDER BY seq")
        ]
