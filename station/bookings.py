"""Double bookings, checked when staff order a visit (issue 36): what ward staff expect of a second
open order (``ordered`` or ``in_progress``) that touches the same patient or the same kiosk.

* The same patient twice on one kiosk: refused. It is the same visit twice; cancel the first to
  order a different one.
* The same patient on another kiosk: a warning staff confirm ("Order anyway"): a patient is at
  one kiosk at a time, but moving them to a free kiosk is a real reason.
* Another patient's open visit on the kiosk: a warning staff confirm. Visits queue on a kiosk (its
  "A visit is ready" screen lists them, and each starts only with its own code), so this is
  allowed, but never unnoticed: the kiosk may be busy for a while.

Plain functions over the caller's connection (the order's own transaction), so two nurses ordering
at once see each other's orders as committed.
"""

from __future__ import annotations

from datetime import datetime
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from station.db import orders

#: the states of an order that still books its patient and kiosk (station.orders.OPEN)
OPEN = ("ordered", "in_progress")
_WORDS = {"ordered": "waiting to start", "in_progress": "running now"}


def _when(iso: str) -> str:
    """When an order was placed, as staff read it (the station's local time, hours and minutes)."""
    try:
        return datetime.fromisoformat(iso.replace("Z", "+00:00")).astimezone().strftime("%H:%M")
    except ValueError:
        return iso[:16]


def _described(row: Any) -> str:
    return f"{_WORDS.get(row.state, row.state)}, ordered {_when(row.ordered_at)} by {row.ordered_by}"


def check(connection: Connection, kiosk_id: str, patient_id: str) -> tuple[str | None, list[str]]:
    """``(refusal, warnings)`` for a new order of ``patient_id`` on ``kiosk_id``: a refusal (one
    sentence) for the same patient's open visit on that kiosk, else one warning per other open
    visit of the patient elsewhere and one for the kiosk's other patients' open visits."""
    rows = connection.execute(
        sa.select(orders.c.kiosk_id, orders.c.patient_id, orders.c.state, orders.c.ordered_at, orders.c.ordered_by)
        .where(
            orders.c.state.in_(OPEN),
            sa.or_(orders.c.kiosk_id == kiosk_id, sa.func.upper(orders.c.patient_id) == patient_id.upper()),
        )
        .order_by(orders.c.ordered_at)
    ).all()
    same = [r for r in rows if r.patient_id.upper() == patient_id.upper()]
    for row in same:
        if row.kiosk_id == kiosk_id:
            return (
                f"patient identifier: {patient_id} already has an open visit on kiosk {kiosk_id} "
                f"({_described(row)}): cancel it first to order a different one",
                [],
            )
    warnings = [
        f"{patient_id} already has an open visit on kiosk {row.kiosk_id} ({_described(row)}): "
        "a patient can be at one kiosk at a time"
        for row in same
    ]
    others = [r for r in rows if r.kiosk_id == kiosk_id]
    if others:
        running = any(r.state == "in_progress" for r in others)
        count = f"{len(others)} open visit{'s' if len(others) > 1 else ''}"
        warnings.append(
            f"kiosk {kiosk_id} already has {count} of other patients"
            f"{' (one is running now)' if running else ''}: this one waits its turn there, started with its own code"
        )
    return None, warnings
