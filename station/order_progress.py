"""How an order follows its visit (protocol §4): the rows a kiosk sends say which sessions run an
order, when its results wait for validation and when they are signed off. A battery's order
has a session per instrument; it awaits validation when every instrument has a finished
session, and is signed off when every finished one is.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from datetime import UTC, datetime
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from kiosk.core.visits import TUG
from station import db
from station.db import audit, orders, sessions, tug_results, visits
from station.orders import LinkRefused, audit_order
from station.sessions import LIFECYCLE


def visit_of(detail: str) -> tuple[str, str | None]:
    """The kind of visit and its order from a ``visit`` log entry's detail ("order order-…",
    "staff", "walk-up")."""
    kind, _, order_id = detail.partition(" ")
    return (kind, order_id or None) if kind in ("order", "staff", "walk-up") else ("unknown", None)


def on_rows(connection: Connection, kiosk_id: str, new: Sequence[Any]) -> list[dict[str, Any]]:
    """What the kiosk's new rows (``station.sync.Event``) mean for visits and orders, in the sync's
    transaction: a session's ``visit`` entry records how it began and links its order (refused
    when the order is another kiosk's or another patient's); a finished session is a result
    waiting (its order awaits validation); an abandoned one puts its order back to ordered.
    Returns the bus messages to publish."""
    messages: list[dict[str, Any]] = []
    if any(e.kind in LIFECYCLE for e in new):  # the Results lists show statuses: they follow live
        messages.append({"type": "sessions", "kiosk": kiosk_id})
    for event in sorted(new, key=lambda e: e.seq):
        p = event.payload
        if event.kind == "record_event" and p.get("kind") == "visit":
            kind, order_id = visit_of(str(p.get("detail", "")))
            if kind == "order":
                _link(connection, kiosk_id, event, order_id)
                messages.append({"type": "order", "kiosk": kiosk_id})
            db.insert_ignore(
                connection,
                visits,
                [{"session_id": event.session_id, "kind": kind, "order_id": order_id}],
                ["session_id"],
            )
        elif event.kind == "finish_session":
            messages.append({"type": "result", "kiosk": kiosk_id, "session": event.session_id, "finished": True})
            _finished(connection, kiosk_id, event.session_id)
        elif event.kind == "abandon":
            if _abandoned(connection, kiosk_id, event.session_id):
                messages.append({"type": "order", "kiosk": kiosk_id})
        elif event.kind == "create_session":
            linked = connection.execute(
                sa.select(orders.c.id, orders.c.patient_id).where(orders.c.session_id == event.session_id)
            ).first()
            if linked is not None and linked.patient_id != p.get("patient_id"):
                raise LinkRefused(
                    f"seq {event.seq}: order {linked.id} is for patient {linked.patient_id}, "
                    f"not {p.get('patient_id')}: the result is not filed under it"
                )
    return messages


def _link(connection: Connection, kiosk_id: str, event: Any, order_id: str | None) -> None:
    row = connection.execute(sa.select(orders).where(orders.c.id == (order_id or ""))).first()
    if row is None or row.kiosk_id != kiosk_id:
        raise LinkRefused(f"seq {event.seq}: no order {order_id} for kiosk {kiosk_id}")
    patient = connection.execute(
        sa.select(db.sessions.c.patient_id).where(db.sessions.c.id == event.session_id)
    ).scalar()
    if patient is not None and patient != row.patient_id:
        raise LinkRefused(
            f"seq {event.seq}: order {order_id} is for patient {row.patient_id}, "
            f"not {patient}: the result is not filed under it"
        )
    if row.state == "ordered":
        raise LinkRefused(f"seq {event.seq}: order {order_id} was not started with its code at the kiosk")
    if row.state != "in_progress":
        return  # cancelled (or done) meanwhile: the session is kept, the order stays as it is
    if row.session_id not in (None, event.session_id) and not _is_finished(connection, row.session_id):
        # the next instrument of a battery follows a finished one; two running at once never do
        raise LinkRefused(f"seq {event.seq}: order {order_id} is running as session {row.session_id}")
    connection.execute(
        orders.update().where(orders.c.id == row.id).values(session_id=event.session_id, updated_at=db.now_iso())
    )
    audit_order(
        connection,
        row.id,
        f"kiosk {kiosk_id}",
        "order_session",
        f"session {event.session_id} started for {row.patient_id} on {kiosk_id}",
    )


def _order_of(connection: Connection, session_id: str) -> Any:
    """The order a session belongs to: through its visit entry (every instrument of a battery is
    one session of the order), else the order's own link; None for a session of no order."""
    order_id = connection.execute(sa.select(visits.c.order_id).where(visits.c.session_id == session_id)).scalar()
    where = orders.c.id == order_id if order_id else orders.c.session_id == session_id
    return connection.execute(sa.select(orders).where(where)).first()


def _sessions_of(connection: Connection, order: Any) -> list[str]:
    """The sessions of an order: one per instrument run so far, in the order they began."""
    linked = connection.execute(sa.select(visits.c.session_id).where(visits.c.order_id == order.id)).scalars().all()
    return list(dict.fromkeys([*linked, *([order.session_id] if order.session_id else [])]))


def _done(connection: Connection, order: Any) -> int:
    """The order's instruments done: its finished sessions, and its Timed Up and Go results (as
    many as it names ``tug``; staff decided each at the kiosk, a rejection included)."""
    finished = sum(_is_finished(connection, s) for s in _sessions_of(connection, order))
    tugs = connection.execute(
        sa.select(sa.func.count()).select_from(tug_results).where(tug_results.c.order_id == order.id)
    ).scalar_one()
    return finished + min(int(tugs), list(json.loads(order.instruments)).count(TUG))


def on_tug(connection: Connection, kiosk_id: str, seq: int, order_id: str, patient_id: str) -> list[dict[str, Any]]:
    """A Timed Up and Go of an ordered visit arrived (stored in the sync's transaction): refused
    (LinkRefused) when the order is another kiosk's or patient's, or was never started with its
    code; else the order moves on as a finished session moves it (a kiosk that stopped holding
    the order meanwhile is forgiven: the result is the visit's). An order of Timed Up and Go
    tests only is complete then: staff decided each at the kiosk, nothing waits for a doctor."""
    row = connection.execute(sa.select(orders).where(orders.c.id == order_id)).first()
    if row is None or row.kiosk_id != kiosk_id:
        raise LinkRefused(f"seq {seq}: record_tug.visit: no order {order_id} for kiosk {kiosk_id}")
    if row.patient_id != patient_id:
        raise LinkRefused(
            f"seq {seq}: record_tug.patient_id: order {order_id} is for patient {row.patient_id}, not {patient_id}"
        )
    started = connection.execute(
        sa.select(audit.c.id).where(audit.c.session_id == order_id, audit.c.action == "order_start").limit(1)
    ).first()
    if started is None:
        raise LinkRefused(f"seq {seq}: record_tug.visit: order {order_id} was not started with its code at the kiosk")
    if row.state not in ("ordered", "in_progress"):
        return []  # cancelled, or its results wait already: the result is kept under it
    done, wanted = _done(connection, row), len(json.loads(row.instruments))
    if done < wanted:
        words = f"Timed Up and Go stored: {done} of {wanted} instruments done"
        audit_order(connection, row.id, f"kiosk {kiosk_id}", "order_instrument", words)
        return [{"type": "order", "kiosk": kiosk_id}]
    only_tugs = all(i == TUG for i in json.loads(row.instruments))
    target = "signed_off" if only_tugs else "awaiting_validation"
    connection.execute(orders.update().where(orders.c.id == row.id).values(state=target, updated_at=db.now_iso()))
    audit_order(
        connection,
        row.id,
        f"kiosk {kiosk_id}",
        "order_signed" if only_tugs else "order_result",
        "Timed Up and Go stored: decided by staff at the kiosk, nothing waits for validation"
        if only_tugs
        else f"Timed Up and Go stored: the results wait for validation ({wanted} instruments)",
    )
    return [{"type": "order", "kiosk": kiosk_id}]


def _is_finished(connection: Connection, session_id: str) -> bool:
    status = connection.execute(sa.select(db.sessions.c.status).where(db.sessions.c.id == session_id)).scalar()
    return status == "finished"


def _finished(connection: Connection, kiosk_id: str, session_id: str) -> None:
    """A session of an order finished: the order awaits validation once every instrument it
    names has a finished session (a battery's earlier instruments leave it in progress)."""
    order = _order_of(connection, session_id)
    if order is None or order.state != "in_progress":
        return
    done = _done(connection, order)
    wanted = len(json.loads(order.instruments))
    if done < wanted:
        audit_order(
            connection,
            order.id,
            f"kiosk {kiosk_id}",
            "order_instrument",
            f"session {session_id} finished on {kiosk_id}: {done} of {wanted} instruments done",
        )
        return
    _move(
        connection,
        session_id,
        "in_progress",
        "awaiting_validation",
        "order_result",
        f"session {session_id} finished on {kiosk_id}: the result waits for validation"
        + (f" ({wanted} instruments)" if wanted > 1 else ""),
    )


def _abandoned(connection: Connection, kiosk_id: str, session_id: str) -> bool:
    """A session of an order ended without a result: with nothing finished the visit can be
    started again; after some of a battery's instruments, their results wait for validation; a
    cancelled order stays so, its trail saying the kiosk ended the session."""
    order = _order_of(connection, session_id)
    if order is not None and order.state == "cancelled":  # the kiosk ended the cancelled visit
        audit_order(
            connection,
            order.id,
            f"kiosk {kiosk_id}",
            "order_ended",
            f"session {session_id} of the cancelled visit ended on {kiosk_id} (what was answered is kept)",
        )
        return True
    if order is None or order.state != "in_progress":
        return False
    done = _done(connection, order)
    if done:
        return _move(
            connection,
            session_id,
            "in_progress",
            "awaiting_validation",
            "order_result",
            f"session {session_id} ended without a result on {kiosk_id}: the {done} finished "
            f"instrument(s) of {len(json.loads(order.instruments))} wait for validation",
        )
    return _move(
        connection,
        session_id,
        "in_progress",
        "ordered",
        "order_ready",
        f"session {session_id} ended without a result: the visit can be started again",
    )


def _move(connection: Connection, session_id: str, source: str, target: str, action: str, reason: str) -> bool:
    found = _order_of(connection, session_id)
    row = found if found is not None and found.state == source else None
    if row is None:
        return False
    values: dict[str, Any] = {"state": target, "updated_at": db.now_iso()}
    if target == "ordered":
        values["session_id"] = None
    connection.execute(orders.update().where(orders.c.id == row.id).values(**values))
    audit_order(connection, row.id, f"kiosk {row.kiosk_id}", action, reason)
    return True


def signed_off(connection: Connection, session_id: str, by: Any) -> None:
    """The session's result was signed off (in the caller's transaction, the sign-off's own): its
    order (if any) is done once every result of it is (a battery's results are signed off one by
    one)."""
    order = _order_of(connection, session_id)
    others = [s for s in _sessions_of(connection, order) if s != session_id] if order is not None else []
    if any(_is_finished(connection, s) and not _is_signed(connection, s) for s in others):
        return
    _move(
        connection,
        session_id,
        "awaiting_validation",
        "signed_off",
        "order_signed",
        f"result of session {session_id} signed off by {by.name}",
    )


def _is_signed(connection: Connection, session_id: str) -> bool:
    """The session's result is final: signed off, and not reopened since (the review state the
    sign-off and the amend store on the session, in their own transactions)."""
    signed = connection.execute(sa.select(sessions.c.signed_at).where(sessions.c.id == session_id)).scalar()
    return signed is not None


def reopened(connection: Connection, session_id: str, by: Any) -> None:
    """A doctor reopened the session's signed-off result to amend it (in the caller's
    transaction): its order (if any) awaits validation again, so the order never says "signed
    off" of a result that is not."""
    _move(
        connection,
        session_id,
        "signed_off",
        "awaiting_validation",
        "order_reopened",
        f"result of session {session_id} reopened to amend by {by.name}",
    )


def visit_kinds(engine: Engine, session_ids: Sequence[str]) -> dict[str, tuple[str, str | None]]:
    """How each session began: (kind, order id); sessions without a ``visit`` entry are absent
    (kiosks older than orders)."""
    if not session_ids:
        return {}
    with engine.connect() as connection:
        rows = connection.execute(sa.select(visits).where(visits.c.session_id.in_(list(session_ids))))
        return {r.session_id: (r.kind, r.order_id) for r in rows}


#: an order that went in progress this recently is never released: its kiosk may not have stored
#: the session yet (the code's answer and the session's first row are moments apart, but a held
#: report can be on its way meanwhile, from this process or another tab on the same kiosk)
RELEASE_GRACE_S = 60.0


def release_unheld(connection: Connection, kiosk_id: str, held: set[str]) -> list[str]:
    """The kiosk reports the orders it holds (a running or interrupted session of them, or rows of
    one still to send): its other orders in progress have nothing left to finish them (it stopped
    after the code was accepted and before a session was stored, or between two instruments of a
    battery), so each heals as an abandoned visit does: back to ordered, or, with some
    instruments finished, their results wait for validation. Returns the orders released."""
    since = datetime.fromtimestamp(db.now() - RELEASE_GRACE_S, UTC).isoformat(timespec="milliseconds")
    stuck = connection.execute(
        sa.select(orders).where(
            orders.c.kiosk_id == kiosk_id, orders.c.state == "in_progress", orders.c.updated_at < since
        )
    ).all()
    released = []
    for order in stuck:
        if order.id in held:
            continue
        done = _done(connection, order)
        wanted = len(json.loads(order.instruments))
        target = "awaiting_validation" if done else "ordered"
        values: dict[str, Any] = {"state": target, "updated_at": db.now_iso()}
        if target == "ordered":
            values["session_id"] = None
        moved = connection.execute(
            orders.update().where(orders.c.id == order.id, orders.c.state == "in_progress").values(**values)
        ).rowcount
        if not moved:
            continue
        why = f"kiosk {kiosk_id} runs no session of this visit (it stopped before the visit could go on)"
        audit_order(
            connection,
            order.id,
            f"kiosk {kiosk_id}",
            "order_result" if done else "order_ready",
            f"{why}: the {done} finished instrument(s) of {wanted} wait for validation"
            if done
            else f"{why}: the visit can be started again with its code",
        )
        released.append(order.id)
    return released
