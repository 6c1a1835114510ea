"""What the station exports: one result, or every result signed off in a period, as FHIR R4
transaction Bundles, and one result as CSV, all through the kiosk's own export code
(:mod:`kiosk.export`), so a result reads the same from the kiosk and from the station.

Each result is described with what its session captured as it started (:mod:`kiosk.export.captured`):
the questionnaire definition it ran and the identity it was recorded under (site, kiosk id, FHIR
systems), so a hospital importing the kiosk's and the station's exports gets one result, not two;
the station's review (:mod:`station.validation`) says where it stands, and the numbers staff entered
(at the kiosk or here) are the result's, in its FHIR and its CSV alike. The caller's questionnaire
only stands in for a session that captured none.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from datetime import date, timedelta

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from kiosk.core.questionnaire import Questionnaire
from kiosk.core.staff import every_entered
from kiosk.export import Described, bundle_of, result, result_rows
from kiosk.export.captured import site_of
from kiosk.store.database import StoredSession
from station import tug_exports, tugs, validation
from station.db import sessions
from station.definitions import questionnaire_for
from station.sessions import SAMPLE_KINDS, load, load_many
from station.validation import AuditEntry


class PeriodError(ValueError):
    """A period the station cannot read (message says which part and why)."""


def _described(connection: Connection, fallback: Questionnaire, session_id: str) -> Described:
    kiosk, stored = load(connection, session_id)
    return _describe(fallback, kiosk, stored, validation.trail_in(connection, session_id))


def _describe(fallback: Questionnaire, kiosk: str, stored: StoredSession, trail: list[AuditEntry]) -> Described:
    """A session as every station export states it: its review and every number staff entered
    (at the kiosk and here, :func:`kiosk.core.staff.every_entered`) from its audit trail."""
    q = questionnaire_for(stored, fallback=fallback)
    values = every_entered(q, stored.log, trail)
    return Described(q, result(q, stored, validation.review_of(trail), values), site_of(stored, kiosk))


def result_bundle(engine: Engine, q: Questionnaire, session_id: str) -> dict:
    """One result as it stands, as a transaction Bundle (NotFound if it never arrived), with the
    Timed Up and Go times of its visit (:mod:`station.tug_exports`)."""
    with engine.connect() as connection:
        bundle = bundle_of([_described(connection, q, session_id)])
        more = tug_exports.entries(tugs.of_sessions(connection, [session_id]))
    if more:
        bundle["entry"] = [*bundle.get("entry", []), *more]
    return bundle


def result_csv(engine: Engine, q: Questionnaire, session_id: str) -> str:
    """One result as the long CSV (the same review state as its FHIR)."""
    with engine.connect() as connection:
        d = _described(connection, q, session_id)
    return result_rows(d.questionnaire, [d.result], d.site)


def period(start: str, end: str) -> tuple[date, date]:
    """``from`` and ``to`` (``YYYY-MM-DD``, UTC days, both included) as dates (PeriodError)."""
    days = []
    for name, value in (("from", start), ("to", end)):
        try:
            days.append(date.fromisoformat(value))
        except ValueError:
            raise PeriodError(f"{name}={value!r}: give a day as YYYY-MM-DD") from None
    if days[1] < days[0]:
        raise PeriodError(f"to={end} is before from={start}")
    return days[0], days[1]


#: results read, described and sent at a time by the period's export
BATCH = 200


def signed_off_in(engine: Engine, first: date, last: date) -> list[str]:
    """The sessions whose result is signed off now, by a sign-off made from ``first`` to ``last``
    (UTC days, both included), oldest sign-off first. A result reopened for amendment and not
    signed again is left out: the hospital keeps its earlier signed version until then."""
    with engine.connect() as connection:
        return [sid for batch in _signed_batches(connection, first, last) for sid in batch]


def _signed_batches(connection: Connection, first: date, last: date, size: int = BATCH) -> Iterator[list[str]]:
    """:func:`signed_off_in`'s sessions, ``size`` at a time: keyset pages over the index on the
    session's stored sign-off time (Alembic ``0006_history``), so a month's export reads the
    month, never the years before it."""
    start, end = first.isoformat(), (last + timedelta(days=1)).isoformat()
    key = ("", "")
    while True:
        query = (
            sa.select(sessions.c.signed_at, sessions.c.id)
            .where(sessions.c.signed_at >= start, sessions.c.signed_at < end)
            .order_by(sessions.c.signed_at, sessions.c.id)
            .limit(size)
        )
        if key[0]:
            query = query.where(sa.tuple_(sessions.c.signed_at, sessions.c.id) > sa.tuple_(*key))
        rows = connection.execute(query).all()
        if not rows:
            return
        yield [r.id for r in rows]
        key = (rows[-1].signed_at, rows[-1].id)
        if len(rows) < size:
            return


def _described_batch(connection: Connection, fallback: Questionnaire, ids: list[str]) -> Iterator[Described]:
    loaded = load_many(connection, ids, without=SAMPLE_KINDS)
    trails = validation.trails_in(connection, ids)
    for session_id in ids:
        kiosk, stored = loaded[session_id]
        yield _describe(fallback, kiosk, stored, trails[session_id])


def period_bundle(engine: Engine, q: Questionnaire, first: date, last: date) -> dict:
    """Every result signed off from ``first`` to ``last`` (:func:`signed_off_in`), and every Timed
    Up and Go time taken then, in one transaction Bundle (no entry when there is none):
    :func:`period_chunks`, read whole."""
    return json.loads("".join(period_chunks(engine, q, first, last)))


def period_chunks(engine: Engine, q: Questionnaire, first: date, last: date) -> Iterator[str]:
    """:func:`period_bundle` as JSON text, a batch of results at a time, in constant memory:
    each result's entries (:func:`kiosk.export.bundle_of` of that one result) as it is read,
    its Questionnaire and Device the first time a result needs them, before that result's
    entries (each once per Bundle, as ``bundle_of`` gives them; fullUrls are derived from
    identifiers, so references resolve wherever they stand). The first batch is described
    before the first byte, so what cannot be exported there is an ExportError the caller can
    answer; a later one ends the stream unfinished (invalid JSON), never a Bundle silently short."""
    seen: set[str] = set()
    with engine.connect() as connection:
        timed = tug_exports.entries(tug_exports.in_period(connection, first, last))  # a few per patient
        batches = _signed_batches(connection, first, last)
        pending = list(_described_batch(connection, q, next(batches, [])))
        if not pending and not timed:
            yield json.dumps({"resourceType": "Bundle", "type": "transaction"})
            return
        yield '{"resourceType": "Bundle", "type": "transaction", "entry": [\n'
        comma = ""
        while pending:
            for described in pending:
                for entry in bundle_of([described]).get("entry", []):
                    if entry["resource"]["resourceType"] in ("Questionnaire", "Device"):
                        if entry["fullUrl"] in seen:
                            continue
                        seen.add(entry["fullUrl"])
                    yield comma + json.dumps(entry, ensure_ascii=False)
                    comma = ",\n"
            pending = list(_described_batch(connection, q, next(batches, [])))
        for entry in timed:  # the Timed Up and Go times taken in the period (staff decided them at the kiosk)
            yield comma + json.dumps(entry, ensure_ascii=False)
            comma = ",\n"
        yield "\n]}"
