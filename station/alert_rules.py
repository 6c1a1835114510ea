"""When an alert is not one, and when it closes by itself (run in the sync's transaction, after
:mod:`station.sync` raised and resolved alerts from the same rows).

* Staff's own doing raises no alert: a patient marked away because staff pressed "Patient away"
  on the station (a ``person_away`` command for that session sent since its last such alert) is
  stored already closed, in the name of who sent it. Nobody needs telling what they just did.
* An alert closes when its situation ends: the patient is back, the doctor's call was answered,
  or the session ended (finished, abandoned, interrupted). It stays in the record with who or
  what closed it; only an alert whose situation is still on waits for a person to acknowledge it.
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import UTC, datetime
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from station import db
from station.db import alerts, commands

#: outbox kinds that end a session, and so every alert of it
ENDED = {"finish_session": "session finished", "abandon": "session ended", "mark_interrupted": "session interrupted"}


def _iso(epoch: float) -> str:
    return datetime.fromtimestamp(epoch, UTC).isoformat(timespec="milliseconds")


def settle(connection: Connection, kiosk_id: str, new: Sequence[Any]) -> list[dict[str, Any]]:
    """Close the alerts the new rows (``station.sync.Event``) make moot; the bus messages to publish."""
    now = db.now_iso()
    closed = 0
    seqs = [e.seq for e in new]
    raised = connection.execute(
        sa.select(alerts).where(
            alerts.c.kiosk_id == kiosk_id,
            alerts.c.seq.in_(seqs),
            alerts.c.kind == "person_lost",
            alerts.c.ack_at.is_(None),
        )
    ).all()
    for alert in raised:
        before = connection.execute(
            sa.select(sa.func.max(alerts.c.received_at)).where(
                alerts.c.session_id == alert.session_id, alerts.c.kind == "person_lost", alerts.c.id != alert.id
            )
        ).scalar()
        query = (
            sa.select(commands.c.by)
            .where(  # sent, and not refused by the kiosk
                commands.c.session_id == alert.session_id,
                commands.c.kind == "person_away",
                sa.or_(commands.c.result.is_(None), commands.c.result == "done"),
            )
            .order_by(commands.c.id.desc())
        )
        if before is not None:
            query = query.where(commands.c.at > _iso(before))
        sender = connection.execute(query).scalar()
        if sender is not None:
            closed += connection.execute(
                alerts.update().where(alerts.c.id == alert.id).values(ack_by=sender, ack_at=now)
            ).rowcount
    # resolved (patient back, doctor's call answered): closed with the resolution
    closed += connection.execute(
        alerts.update()
        .where(
            alerts.c.kiosk_id == kiosk_id,
            alerts.c.resolved_at.is_not(None),
            alerts.c.ack_at.is_(None),
            alerts.c.session_id.in_(sorted({e.session_id for e in new})),
        )
        .values(ack_by="closed: situation ended", ack_at=now)
    ).rowcount
    for event in new:
        if event.kind in ENDED:
            closed += connection.execute(
                alerts.update()
                .where(alerts.c.session_id == event.session_id, alerts.c.ack_at.is_(None))
                .values(ack_by=f"closed: {ENDED[event.kind]}", ack_at=now)
            ).rowcount
    return [{"type": "alert", "kiosk": kiosk_id}] if closed else []
