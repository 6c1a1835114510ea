"""A visit and a patient's course as printed for the paper chart (issue 36, part 3).

A visit is the sessions of one order (a battery: one session per instrument); a session that
no order started is a visit of its own. Each instrument shows its title, total, band, who
answered and who signed it and when; times are shown in the site's time zone
(``--time-zone``, :mod:`station.times`). Read in
one connection, scored as the session page scores (corrections and staff-entered numbers
applied, on the definition the session ran). The PDF is the browser's print of this view
(``@media print`` in ``station.css``): no PDF library on the server.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from datetime import tzinfo

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.review import review_state
from kiosk.core.staff import entered_at_station, entered_values
from kiosk.export import ExportError
from kiosk.store.database import StoredSession
from station import times, tugs
from station.db import audit, orders, sessions, visits
from station.definitions import questionnaire_for
from station.sessions import RESULT_KINDS, NotFound, load_many
from station.validation import AuditEntry, review_of

#: who answered, as staff write it on the chart
ANSWERED_WORDS = {"patient": "the patient", "relative": "a relative", "caregiver": "a caregiver", "staff": "staff"}


def shown_time(iso: str | None, zone: tzinfo | None = None) -> str:
    """A stored ISO-8601 time as staff read it: ``YYYY-MM-DD HH:MM`` and the zone's name, in
    ``zone`` (the station's local zone when None); "" for none, the text itself if unreadable."""
    return times.shown(iso, zone)


@record
class PrintedResult:
    """One instrument of a printed visit."""

    session_id: str
    title: str
    status: str
    total: int | None
    max_total: int
    band: str
    answered_by: str
    review: str
    signed_by: str
    signed_at: str
    finished_at: str

    @property
    def total_words(self) -> str:
        if self.total is not None:
            return f"{self.total} of {self.max_total}"
        return "incomplete" if self.status == "finished" else self.status.replace("_", " ")


@record
class PrintedTug:
    """A Timed Up and Go of a printed visit: the result and when, as staff read it."""

    tug: tugs.StationTug
    when: str


@record
class PrintedVisit:
    """One visit as printed: the patient, when and where, each instrument in the order run, and
    its Timed Up and Go results; ``at`` (ISO 8601) orders visits."""

    patient_id: str
    kiosk_id: str
    date: str
    order_id: str | None
    results: list[PrintedResult]
    tugs: tuple[PrintedTug, ...] = ()
    at: str = ""


def _trails(connection: Connection, ids: list[str]) -> dict[str, list[AuditEntry]]:
    found: dict[str, list[AuditEntry]] = {i: [] for i in ids}
    if ids:
        query = sa.select(audit).where(audit.c.session_id.in_(ids)).order_by(audit.c.id)
        for row in connection.execute(query):
            found[row.session_id].append(AuditEntry.of(row))
    return found


def _printed(stored: StoredSession, q: Questionnaire, trail: list[AuditEntry], zone: tzinfo | None) -> PrintedResult:
    review = review_of(trail)
    title, total, max_total, band = stored.questionnaire_id, None, 0, ""
    try:
        ran = questionnaire_for(stored, fallback=q if stored.questionnaire_id == q.id else None)
    except ExportError:
        ran = None
    if ran is not None and ran.id == stored.questionnaire_id:
        title = ran.title.get(stored.language) or ran.title.get("en") or ran.id
        items = {item.id: item for item in ran.items}
        options = review.options({a.item_id: a.option for a in stored.answers})
        fitting = {i: o for i, o in options.items() if i in items and o is not None and 1 <= o <= len(items[i].options)}
        entered = {**entered_values(ran, stored.log), **entered_at_station(ran, trail)}
        score = ran.score_answers(fitting, values=entered)
        max_total = score.max_total
        if score.complete:
            total = score.total
            if score.band is not None:
                band = score.band.label.get(stored.language) or score.band.label.get("en") or score.band.id
    state = review_state(review, {a.item_id: a.option for a in stored.answers})
    answered = getattr(stored.answered_by, "value", str(stored.answered_by))
    return PrintedResult(
        stored.id,
        title,
        stored.status,
        total,
        max_total,
        band,
        ANSWERED_WORDS.get(answered, answered),
        state.value.replace("_", " "),
        (review.signed_by or "") if review.final else "",
        shown_time(review.signed_at, zone) if review.final else "",
        shown_time(stored.finished_at, zone),
    )


def _instruments(connection: Connection, order_ids: set[str]) -> dict[str, list[str]]:
    """Each order's instruments, in the order it gave them."""
    if not order_ids:
        return {}
    rows = connection.execute(sa.select(orders.c.id, orders.c.instruments).where(orders.c.id.in_(order_ids)))
    return {r.id: list(json.loads(r.instruments)) for r in rows}


def _index(run: list[str], questionnaire_id: str) -> int:
    return run.index(questionnaire_id) if questionnaire_id in run else len(run)


def visits_of(connection: Connection, q: Questionnaire, ids: Sequence[str], zone: tzinfo | None) -> list[PrintedVisit]:
    """The visits of these sessions (grouped by order, else one each), oldest first."""
    ids = list(dict.fromkeys(ids))
    loaded = load_many(connection, ids, RESULT_KINDS)
    order_of = {
        session_id: order_id
        for session_id, order_id in connection.execute(
            sa.select(visits.c.session_id, visits.c.order_id).where(visits.c.session_id.in_(ids))
        )
        if order_id
    }
    trails = _trails(connection, ids)
    ordered = _instruments(connection, set(order_of.values()))
    grouped: dict[str, list[tuple[str, StoredSession]]] = {}
    for session_id in ids:
        if session_id in loaded:
            grouped.setdefault(order_of.get(session_id) or session_id, []).append(loaded[session_id])
    found = []
    for key, members in grouped.items():
        # in the order's own order of instruments (a battery as ordered), then as begun
        run = ordered.get(key, [])
        members.sort(key=lambda m: (_index(run, m[1].questionnaire_id), m[1].started_at or ""))
        kiosk, first = min(members, key=lambda m: m[1].started_at or "")
        timed = tugs.of_sessions(connection, [stored.id for _, stored in members])
        found.append(
            PrintedVisit(
                first.patient_id,
                kiosk,
                shown_time(first.started_at, zone),
                key if order_of.get(first.id) else None,
                [_printed(stored, q, trails[stored.id], zone) for _, stored in members],
                tuple(PrintedTug(t, shown_time(t.at, zone)) for t in timed),
                first.started_at or "",
            )
        )
    found.sort(key=lambda v: v.at)
    return found


def _tug_only(tug: tugs.StationTug, zone: tzinfo | None) -> PrintedVisit:
    """A visit of Timed Up and Go results alone (no questionnaire session of it reached the station)."""
    when = shown_time(tug.at, zone)
    return PrintedVisit(tug.patient_id, tug.kiosk_id, when, tug.order_id, [], (PrintedTug(tug, when),), tug.at)


def tug_visit(engine: Engine, q: Questionnaire, tug_id: str, zone: tzinfo | None = None) -> PrintedVisit | None:
    """The visit a Timed Up and Go belongs to: its order's sessions with it, else the result alone
    (None when it never arrived)."""
    found = tugs.get(engine, tug_id)
    if found is None:
        return None
    with engine.connect() as connection:
        ids: list[str] = []
        if found.order_id:
            ids = list(
                connection.execute(sa.select(visits.c.session_id).where(visits.c.order_id == found.order_id)).scalars()
            )
        printed = visits_of(connection, q, ids, zone) if ids else []
    return next((v for v in printed if tug_id in {t.tug.id for t in v.tugs}), None) or _tug_only(found, zone)


def visit(engine: Engine, q: Questionnaire, session_id: str, zone: tzinfo | None = None) -> PrintedVisit:
    """The visit ``session_id`` belongs to: every session of its order (NotFound if none arrived)."""
    with engine.connect() as connection:
        order_id = connection.execute(
            sa.select(visits.c.order_id).where(visits.c.session_id == session_id)
        ).scalar_one_or_none()
        ids = [session_id]
        if order_id:
            ids += connection.execute(sa.select(visits.c.session_id).where(visits.c.order_id == order_id)).scalars()
        found = visits_of(connection, q, ids, zone)
    if not found:
        raise NotFound(session_id)
    return next(v for v in found if session_id in {r.session_id for r in v.results})


def course(engine: Engine, q: Questionnaire, patient_id: str, zone: tzinfo | None = None) -> list[PrintedVisit]:
    """Every visit of one patient that reached the station, oldest first (a Timed Up and Go of no
    questionnaire session's visit as a visit of its own)."""
    with engine.connect() as connection:
        ids = connection.execute(
            sa.select(sessions.c.id)
            .where(sessions.c.patient_id == patient_id, sessions.c.status != "pending")
            .order_by(sessions.c.started_at)
        ).scalars()
        found = visits_of(connection, q, list(ids), zone)
        shown = {t.tug.id for v in found for t in v.tugs}
        found += [_tug_only(t, zone) for t in tugs.of_patient(connection, patient_id) if t.id not in shown]
    return sorted(found, key=lambda v: v.at)
