"""The ward now: each kiosk's live status (protocol §2), open alerts and their acknowledgement,
and the staff commands a kiosk picks up (protocol §3).

Every staff action is also written to the audit trail (who, when, what), in the same transaction.
"""

from __future__ import annotations

import json
import math
from dataclasses import field
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from basis import record
from station import db
from station.db import alerts, audit, commands, inbox, kiosks, orders, visits

#: a kiosk without a heartbeat for this long shows offline (the kiosk sends one at least every 10 s)
OFFLINE_AFTER_S = 30.0
COMMAND_KINDS = ("continue", "person_away", "person_back", "end")
#: what staff read about a command they sent (never its name in the protocol)
COMMAND_WORDS = {
    "continue": "Asked {kiosk} to continue the session.",
    "person_away": "Told {kiosk} the patient is away from it.",
    "person_back": "Told {kiosk} the patient is back.",
    "end": "Asked {kiosk} to end the session.",
}
ALERT_TEXT = {
    "doctor_called": "Doctor called",
    "person_lost": "Patient away from the kiosk",
    "unattended": "No answer to questions in a row; the kiosk waits for a touch",
}
#: small counts in words, for an alert staff read at a glance ("no answer to two questions in a row")
_COUNTS = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight", 9: "nine", 10: "ten"}


def alert_text(kind: str, detail: str = "") -> str:
    """What staff read about an alert; ``detail`` is what the kiosk said with it (the seconds away,
    the questions unanswered), when it said it."""
    number = _number(detail)
    if kind == "person_lost" and number is not None and number > 0:
        span = f"{number / 60:g} min" if number % 60 == 0 else f"{number:g} s"
        return f"Patient away from the kiosk for {span}"
    if kind == "unattended" and number is not None and number >= 1 and number == int(number):
        count = int(number)
        if count == 1:
            return "No answer to the last question; the kiosk waits for a touch"
        return f"No answer to {_COUNTS.get(count, str(count))} questions in a row; the kiosk waits for a touch"
    return ALERT_TEXT.get(kind, kind)


def _number(detail: str) -> float | None:
    try:
        number = float(detail)
    except ValueError:
        return None
    return number if math.isfinite(number) else None


#: the fields of a status report the ward view shows, with their types
STATUS_FIELDS: dict[str, type | tuple[type, ...]] = {
    "session_id": (str, type(None)),
    "patient_id": (str, type(None)),
    "phase": (str, type(None)),
    "question": (int, type(None)),
    "of": (int, type(None)),
    "paused": bool,
    "person_away": bool,
    "doctor_called": bool,
    # no answer to questions in a row: the kiosk waits for the patient's touch
    "unattended": bool,
    "simulated": bool,
    "at": (str, type(None)),
    # why the kiosk takes no patient (its store failed: a full disk); None while it works
    "out_of_order": (str, type(None)),
    # the kiosk steers patients to touch: voice is not heard well in its room (a sentence for staff)
    "voice_room": (str, type(None)),
    # the kiosk process that reports (two browser tabs on one kiosk are two processes)
    "instance": (str, type(None)),
}
#: the most kiosk processes whose reports a kiosk's row keeps (the newest)
MOST_INSTANCES = 8


class WardError(ValueError):
    """A staff action that cannot be done (message says why)."""


@record
class Alert:
    id: int
    kiosk_id: str
    session_id: str
    kind: str
    raised_at: str
    resolved_at: str | None
    ack_by: str | None
    ack_at: str | None
    #: what the kiosk said with it (the row's ``detail``: seconds away, questions unanswered)
    detail: str = ""

    @property
    def text(self) -> str:
        return alert_text(self.kind, self.detail)


@record
class KioskView:
    name: str
    last_seen: float | None
    revoked: bool
    status: dict[str, Any] = field(default_factory=dict)
    alerts: tuple[Alert, ...] = ()
    #: the session it reports runs a visit staff cancelled (the kiosk is ending it)
    cancelled: bool = False

    def online(self, now: float) -> bool:
        return self.last_seen is not None and now - self.last_seen <= OFFLINE_AFTER_S and not self.revoked


def parse_status(body: Any) -> dict[str, Any]:
    """A status report's fields (WardError naming a wrong one); unknown fields are ignored."""
    if not isinstance(body, dict):
        raise WardError("the body must be a JSON object")
    status = {}
    for name, kind in STATUS_FIELDS.items():
        value = body.get(name)
        if value is None and kind in (bool,):
            value = False
        if not isinstance(value, kind) or (isinstance(value, bool) and kind not in (bool,)):
            raise WardError(f"status field {name!r}: wrong type {type(value).__name__}")
        status[name] = value
    return status


def merge_status(stored: str | None, status: dict[str, Any], now: float) -> str:
    """The kiosk's stored reports with ``status`` in, as stored: one report per kiosk process
    (its ``instance``; none: a kiosk from before, one process), each with when it came."""
    reports = _reports(stored)
    reports[status.get("instance") or ""] = {**status, "received": now}
    newest = sorted(reports.items(), key=lambda kv: kv[1].get("received", 0.0))[-MOST_INSTANCES:]
    return json.dumps({"reports": dict(newest)})


def _reports(stored: str | None) -> dict[str, dict[str, Any]]:
    """The stored reports by process (a row written before processes were told apart: one)."""
    value = json.loads(stored) if stored else {}
    if not isinstance(value, dict):
        return {}
    if "reports" in value:
        return dict(value["reports"])
    return {"": value} if value else {}


def shown_status(stored: str | None, now: float) -> dict[str, Any]:
    """What the kiosk's tile shows: the live session of a process that reported within
    :data:`OFFLINE_AFTER_S` (two tabs on one kiosk: the one running a test, not the other's
    welcome; the newest if both run one), else the newest report. Staff see the test that runs."""
    reports = sorted(_reports(stored).values(), key=lambda r: r.get("received", 0.0))
    live = [r for r in reports if r.get("session_id") and now - r.get("received", 0.0) <= OFFLINE_AFTER_S]
    shown = (live or reports or [{}])[-1]
    return {k: v for k, v in shown.items() if k != "received"}


def report_status(connection: Any, kiosk_id: str, status: dict[str, Any]) -> None:
    """Keep a process's status report beside the others of its kiosk (read under a row lock on
    PostgreSQL, so two processes reporting at once both count)."""
    stored = connection.execute(sa.select(kiosks.c.status).where(kiosks.c.name == kiosk_id).with_for_update()).scalar()
    merged = merge_status(stored, status, db.now())
    connection.execute(kiosks.update().where(kiosks.c.name == kiosk_id).values(status=merged))


def seen(engine: Engine, kiosk_id: str) -> None:
    with engine.begin() as connection:
        connection.execute(kiosks.update().where(kiosks.c.name == kiosk_id).values(last_seen=db.now()))


def _alert(row: Any) -> Alert:
    detail = ""
    if row.payload:
        try:
            detail = str(json.loads(row.payload).get("detail") or "")
        except (ValueError, AttributeError):
            detail = ""
    return Alert(
        row.id, row.kiosk_id, row.session_id, row.kind, row.raised_at, row.resolved_at, row.ack_by, row.ack_at, detail
    )


def open_alerts(engine: Engine, kiosk_id: str | None = None) -> list[Alert]:
    """Alerts nobody has acknowledged yet, oldest first, with what the kiosk said with each."""
    raised_by = sa.and_(inbox.c.kiosk_id == alerts.c.kiosk_id, inbox.c.seq == alerts.c.seq)
    query = (
        sa.select(alerts, inbox.c.payload)
        .select_from(alerts.outerjoin(inbox, raised_by))
        .where(alerts.c.ack_at.is_(None))
        .order_by(alerts.c.id)
    )
    if kiosk_id is not None:
        query = query.where(alerts.c.kiosk_id == kiosk_id)
    with engine.connect() as connection:
        return [_alert(r) for r in connection.execute(query)]


def kiosk_views(engine: Engine, name: str | None = None) -> list[KioskView]:
    """Every kiosk (or one), with its status and open alerts."""
    query = sa.select(kiosks).order_by(kiosks.c.name)
    if name is not None:
        query = query.where(kiosks.c.name == name)
    with engine.connect() as connection:
        rows = connection.execute(query).all()
    pending = open_alerts(engine, name)
    now = db.now()
    shown = {r.name: shown_status(r.status, now) for r in rows}
    cancelled = _cancelled_sessions(engine, [s["session_id"] for s in shown.values() if s.get("session_id")])
    return [
        KioskView(
            r.name,
            r.last_seen,
            r.revoked_at is not None,
            shown[r.name],
            tuple(a for a in pending if a.kiosk_id == r.name),
            shown[r.name].get("session_id") in cancelled,
        )
        for r in rows
    ]


def _cancelled_sessions(engine: Engine, session_ids: list[str]) -> set[str]:
    """Which of these sessions run a visit whose order staff cancelled (its ``visit`` entry)."""
    if not session_ids:
        return set()
    with engine.connect() as connection:
        return set(
            connection.execute(
                sa.select(visits.c.session_id)
                .join(orders, orders.c.id == visits.c.order_id)
                .where(visits.c.session_id.in_(session_ids), orders.c.state == "cancelled")
            ).scalars()
        )


def acknowledge(engine: Engine, alert_id: int, by: str) -> str:
    """Record who acknowledged an alert and when; returns its kiosk."""
    at = db.now_iso()
    with engine.begin() as connection:
        row = connection.execute(sa.select(alerts).where(alerts.c.id == alert_id)).first()
        if row is None:
            raise WardError(f"no alert {alert_id}")
        if row.ack_at is not None:
            return row.kiosk_id  # two nurses pressed at once: the first one is recorded
        connection.execute(
            alerts.update().where(alerts.c.id == alert_id, alerts.c.ack_at.is_(None)).values(ack_by=by, ack_at=at)
        )
        connection.execute(
            audit.insert().values(
                session_id=row.session_id,
                at=at,
                author=by,
                action="acknowledge",
                reason=f"{alert_text(row.kind)} on {row.kiosk_id}",
            )
        )
    return row.kiosk_id


def queue_command(engine: Engine, kiosk_id: str, session_id: str, kind: str, by: str) -> int:
    """Queue a command for the kiosk (it obeys only if the session is still its running one).
    A ``continue`` also acknowledges the session's open doctor call, or its open "no answer" alert
    (the kiosk then waits for the patient's touch: it never asks on with nobody there)."""
    if kind not in COMMAND_KINDS:
        raise WardError(f"unknown command {kind!r}")
    at = db.now_iso()
    with engine.begin() as connection:
        if connection.execute(sa.select(kiosks.c.name).where(kiosks.c.name == kiosk_id)).first() is None:
            raise WardError(f"no kiosk {kiosk_id!r}")
        inserted = connection.execute(
            commands.insert().values(kiosk_id=kiosk_id, session_id=session_id, kind=kind, by=by, at=at)
        ).inserted_primary_key
        assert inserted is not None  # a single-row INSERT has its key
        command_id = inserted[0]
        connection.execute(
            audit.insert().values(
                session_id=session_id,
                at=at,
                author=by,
                action="command",
                reason=COMMAND_WORDS[kind].format(kiosk=kiosk_id),
            )
        )
        if kind == "continue":
            connection.execute(
                alerts.update()
                .where(
                    alerts.c.session_id == session_id,
                    alerts.c.kind.in_(("doctor_called", "unattended")),
                    alerts.c.ack_at.is_(None),
                )
                .values(ack_by=by, ack_at=at)
            )
    return int(command_id)


def pending_commands(engine: Engine, kiosk_id: str) -> list[dict[str, Any]]:
    """Commands the kiosk has not acknowledged (re-delivered until it does)."""
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(commands)
            .where(commands.c.kiosk_id == kiosk_id, commands.c.acked_at.is_(None))
            .order_by(commands.c.id)
        ).all()
    return [{"id": r.id, "kind": r.kind, "session_id": r.session_id, "by": r.by, "at": r.at} for r in rows]


def ack_command(engine: Engine, kiosk_id: str, command_id: int, body: Any) -> None:
    """The kiosk's answer to a command: ``done``, or ``refused`` with a reason."""
    if not isinstance(body, dict) or body.get("result") not in ("done", "refused"):
        raise WardError('the body must be {"result": "done"} or {"result": "refused", "reason": "..."}')
    reason = body.get("reason")
    with engine.begin() as connection:
        done = connection.execute(
            commands.update()
            .where(commands.c.id == command_id, commands.c.kiosk_id == kiosk_id, commands.c.acked_at.is_(None))
            .values(acked_at=db.now_iso(), result=body["result"], reason=str(reason)[:500] if reason else None)
        ).rowcount
        if (
            not done
            and connection.execute(
                sa.select(commands.c.id).where(commands.c.id == command_id, commands.c.kiosk_id == kiosk_id)
            ).first()
            is None
        ):
            raise WardError(f"no command {command_id} for this kiosk")


def recent_commands(engine: Engine, session_id: str) -> list[dict[str, Any]]:
    """The session's commands and what the kiosk answered, newest first."""
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(commands).where(commands.c.session_id == session_id).order_by(commands.c.id.desc())
        ).all()
    return [dict(r._mapping) for r in rows]
