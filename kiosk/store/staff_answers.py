"""Storing what staff enter for a staff item (``answered_by: staff``), after the patient's visit.

Unlike the patient's answers, these come when the session may have ended and its lease is gone, so
they are written without holding it -- but never while another kiosk records the session. One
transaction: a chosen option replaces any earlier staff choice as an answer row answered by
``staff`` (the earlier one is withdrawn, so the station follows), and every staff answer adds a
:data:`kiosk.core.staff.STAFF_ANSWER` line to the session's log (the audit, and the value of a
number); each change queues its outbox row for the station like any other.
"""

from __future__ import annotations

from kiosk.core.staff import STAFF_ANSWER, answer_detail
from kiosk.store.custody import Custody
from kiosk.store.lease import SessionTaken
from kiosk.store.transactions import Transactions

#: what a staff answer records as its channel and attempt (the station checks both)
CHANNEL = "touch"
ATTEMPT = 1


def record_staff_answer(
    tx: Transactions,
    custody: Custody,
    session_id: str,
    *,
    item_id: str,
    option: int | None,
    points: int | None,
    value: float | None,
    at: str | None,
    by: str,
) -> None:
    """Store one staff answer: ``option`` (with its ``points``) for a choice, or ``value`` for a
    number, ``at`` (None: now). KeyError if the session is not stored; SessionTaken while another
    kiosk holds it."""
    at = at or tx.iso_now()
    with tx.transaction():
        found = tx.db.execute("SELECT status FROM sessions WHERE id = ?", (session_id,)).fetchone()
        if found is None:
            raise KeyError(f"session {session_id} is not stored")
        tx.write("SELECT 1", ())  # begins the write transaction: what follows is read under its lock
        holder = tx.db.execute("SELECT token FROM leases WHERE session_id = ?", (session_id,)).fetchone()
        if holder is not None and holder[0] != custody.owner.token:
            raise SessionTaken(f"session {session_id} is open on another kiosk: enter staff items once it ends there")
        t = float(
            tx.db.execute("SELECT COALESCE(MAX(t), 0) FROM events WHERE session_id = ?", (session_id,)).fetchone()[0]
        )
        if option is not None:
            if tx.db.execute(
                "SELECT 1 FROM answers WHERE session_id = ? AND item_id = ?", (session_id, item_id)
            ).fetchone():
                tx.write("DELETE FROM answers WHERE session_id = ? AND item_id = ?", (session_id, item_id))
                reason = "staff entered another answer"
                tx.queue("withdraw_answer", session_id, {"item_id": item_id, "t": t, "at": at, "reason": reason})
            row = (session_id, item_id, option, points, ATTEMPT, CHANNEL, "staff", t, at, f"entered by {by}")
            tx.write("INSERT INTO answers VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)", row)
            payload = dict(
                zip(("item_id", "option", "points", "attempt", "channel", "answered_by", "t", "at", "detail"), row[1:])
            )
            tx.queue("record_answer", session_id, payload)
        detail = answer_detail(item_id, option=option, value=value, by=by)
        seq = tx.next_seq("events", session_id)
        tx.write("INSERT INTO events VALUES (?, ?, ?, ?, ?)", (session_id, seq, t, STAFF_ANSWER, detail))
        tx.queue("record_event", session_id, {"t": t, "kind": STAFF_ANSWER, "detail": detail})
