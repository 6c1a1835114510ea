"""The shift's handover (issue 36, part 7): what happened in a window of time and what is left.

For a window (by default the last :data:`DEFAULT_HOURS` hours; the station has no setting for a
site's shifts yet): the alerts raised in it and who answered them, the visits finished in it
(each visit's instruments, :mod:`station.printing`), and, as they stand now, the orders still
open and the results no doctor has signed off; beside it, today's visits per kiosk (today in the
station's local zone). One function, one connection; times are stored as ISO-8601 UTC, so a
window is a range of their text.
"""

from __future__ import annotations

from datetime import UTC, datetime, time, timedelta, tzinfo

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from station.db import alerts, inbox, orders, sessions
from station.orders import OPEN, Order
from station.printing import PrintedVisit, shown_time, visits_of
from station.ward import Alert, _alert

DEFAULT_HOURS = 8
#: the longest window one page reads (a month: a handover, not an archive)
LONGEST = timedelta(days=31)
#: the most rows of each list the page shows (the counts are whole)
MOST = 200
#: how a window's ends are typed (an ``<input type="datetime-local">``)
TYPED = "%Y-%m-%dT%H:%M"


class HandoverError(ValueError):
    """A window that cannot be read (one sentence naming the field and the problem)."""


@record
class Window:
    """From ``start`` to ``end`` (aware datetimes), as typed and as the page shows them."""

    start: datetime
    end: datetime

    def typed(self, zone: tzinfo | None = None) -> tuple[str, str]:
        """The ends as a ``datetime-local`` input shows them, in ``zone``."""
        return self.start.astimezone(zone).strftime(TYPED), self.end.astimezone(zone).strftime(TYPED)


def _typed(field: str, text: str, zone: tzinfo | None) -> datetime:
    try:
        naive = datetime.strptime(text.strip(), TYPED)
    except ValueError:
        raise HandoverError(f"{field}: {text[:40]!r} is not a date and time (YYYY-MM-DDTHH:MM)") from None
    return naive.replace(tzinfo=zone) if zone is not None else naive.astimezone()


def window(start: str, end: str, now: datetime, zone: tzinfo | None = None) -> Window:
    """The window typed on the page (``start``/``end`` in ``zone``, the local zone when None);
    an empty end is ``now``, an empty start :data:`DEFAULT_HOURS` before the end."""
    last = _typed("to", end, zone) if end.strip() else now
    first = _typed("from", start, zone) if start.strip() else last - timedelta(hours=DEFAULT_HOURS)
    if first >= last:
        raise HandoverError("from: the shift must start before it ends")
    if last - first > LONGEST:
        raise HandoverError(f"from: a handover covers at most {LONGEST.days} days")
    return Window(first, last)


def _utc(when: datetime) -> str:
    """The text every stored time at or after ``when`` sorts at or after (stored: ISO-8601 UTC)."""
    return when.astimezone(UTC).strftime("%Y-%m-%dT%H:%M:%S")


@record
class ShiftAlert:
    alert: Alert
    patient_id: str
    raised: str
    answered: str
    ended: str


@record
class Unsigned:
    session_id: str
    patient_id: str
    kiosk_id: str
    finished: str


@record
class Shift:
    window: Window
    alerts: list[ShiftAlert]
    visits_done: list[PrintedVisit]
    orders_open: list[Order]
    unsigned: list[Unsigned]
    unsigned_count: int
    #: today's visits, by kiosk (kiosks in name order, visits oldest first)
    today: dict[str, list[PrintedVisit]]


def shift(engine: Engine, q: Questionnaire, chosen: Window, now: datetime, zone: tzinfo | None = None) -> Shift:
    """The handover for ``chosen``, and today's visits (the day of ``now`` in ``zone``)."""
    start, end = _utc(chosen.start), _utc(chosen.end)
    local_now = now.astimezone(zone)
    midnight = datetime.combine(local_now.date(), time(), tzinfo=local_now.tzinfo)
    day_start, day_end = _utc(midnight), _utc(midnight + timedelta(days=1))
    raised_by = sa.and_(inbox.c.kiosk_id == alerts.c.kiosk_id, inbox.c.seq == alerts.c.seq)
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(alerts, inbox.c.payload, sessions.c.patient_id)
            .select_from(alerts.outerjoin(inbox, raised_by).outerjoin(sessions, sessions.c.id == alerts.c.session_id))
            .where(alerts.c.raised_at >= start, alerts.c.raised_at < end)
            .order_by(alerts.c.raised_at, alerts.c.id)
            .limit(MOST)
        ).all()
        shift_alerts = [
            ShiftAlert(
                _alert(r),
                r.patient_id or "",
                shown_time(r.raised_at, zone),
                shown_time(r.ack_at, zone),
                shown_time(r.resolved_at, zone),
            )
            for r in rows
        ]
        done = connection.execute(
            sa.select(sessions.c.id)
            .where(sessions.c.status == "finished", sessions.c.finished_at >= start, sessions.c.finished_at < end)
            .order_by(sessions.c.finished_at)
            .limit(MOST)
        ).scalars()
        visits_done = visits_of(connection, q, list(done), zone)
        open_orders = [
            Order.of(r)
            for r in connection.execute(
                sa.select(orders).where(orders.c.state.in_(OPEN)).order_by(orders.c.ordered_at).limit(MOST)
            )
        ]
        waiting = sa.and_(sessions.c.status == "finished", sessions.c.signed_at.is_(None))
        unsigned_count = connection.execute(
            sa.select(sa.func.count()).select_from(sessions).where(waiting)
        ).scalar_one()
        unsigned = [
            Unsigned(r.id, r.patient_id or "", r.kiosk_id, shown_time(r.finished_at, zone))
            for r in connection.execute(
                sa.select(sessions.c.id, sessions.c.patient_id, sessions.c.kiosk_id, sessions.c.finished_at)
                .where(waiting)
                .order_by(sessions.c.finished_at)
                .limit(MOST)
            )
        ]
        started_today = connection.execute(
            sa.select(sessions.c.id)
            .where(sessions.c.status != "pending", sessions.c.started_at >= day_start, sessions.c.started_at < day_end)
            .order_by(sessions.c.started_at)
            .limit(MOST)
        ).scalars()
        today: dict[str, list[PrintedVisit]] = {}
        for v in visits_of(connection, q, list(started_today), zone):
            today.setdefault(v.kiosk_id, []).append(v)
    return Shift(
        chosen,
        shift_alerts,
        visits_done,
        open_orders,
        unsigned,
        int(unsigned_count),
        dict(sorted(today.items())),
    )
