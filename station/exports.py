"""What the station exports: one result, or every result signed off in a period, as FHIR R4
transaction Bundles, and one result as CSV, all through the kiosk's own export code
(:mod:`kiosk.export`), so a result reads the same from the kiosk and from the station.

Each result is described with what its session captured as it started (:mod:`kiosk.export.captured`):
the questionnaire definition it ran and the identity it was recorded under (site, kiosk id, FHIR
systems), so a hospital importing the kiosk's and the station's exports gets one result, not two;
the station's review (:mod:`station.validation`) says where it stands. The caller's questionnaire
only stands in for a session that captured none.
"""

from __future__ import annotations

from datetime import date, timedelta

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from kiosk.core.questionnaire import Questionnaire
from kiosk.export import Described, bundle_of, csv_text, result
from kiosk.export.captured import questionnaire_of, site_of
from station import validation
from station.db import audit
from station.sessions import load


class PeriodError(ValueError):
    """A period the station cannot read (message says which part and why)."""


def _described(connection: Connection, fallback: Questionnaire, session_id: str) -> Described:
    kiosk, stored = load(connection, session_id)
    review = validation.review_in(connection, session_id)
    q = questionnaire_of(stored, fallback=fallback)
    return Described(q, result(q, stored, review), site_of(stored, kiosk))


def result_bundle(engine: Engine, q: Questionnaire, session_id: str) -> dict:
    """One result as it stands, as a transaction Bundle (NotFound if it never arrived)."""
    with engine.connect() as connection:
        return bundle_of([_described(connection, q, session_id)])


def result_csv(engine: Engine, q: Questionnaire, session_id: str) -> str:
    """One result as the long CSV (the same review state as its FHIR)."""
    with engine.connect() as connection:
        d = _described(connection, q, session_id)
    return csv_text(d.questionnaire, [d.result.stored], [d.result.review], d.site)


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


def signed_off_in(engine: Engine, first: date, last: date) -> list[str]:
    """The sessions whose result is signed off now, by a sign-off made from ``first`` to ``last``
    (UTC days, both included), oldest sign-off first. A result reopened for amendment and not
    signed again is left out: the hospital keeps its earlier signed version until then."""
    start, end = first.isoformat(), (last + timedelta(days=1)).isoformat()
    with engine.connect() as connection:
        candidates = list(
            dict.fromkeys(
                connection.execute(
                    sa.select(audit.c.session_id)
                    .where(audit.c.action == "sign_off", audit.c.at >= start, audit.c.at < end)
                    .order_by(audit.c.id)
                ).scalars()
            )
        )
    reviews = validation.reviews(engine, candidates)
    chosen = [s for s in candidates if reviews[s].final and start <= (reviews[s].signed_at or "") < end]
    return sorted(chosen, key=lambda s: reviews[s].signed_at or "")


def period_bundle(engine: Engine, q: Questionnaire, first: date, last: date) -> dict:
    """Every result signed off from ``first`` to ``last`` (:func:`signed_off_in`) in one
    transaction Bundle (no entry when there is none)."""
    sessions = signed_off_in(engine, first, last)
    with engine.connect() as connection:
        return bundle_of([_described(connection, q, session_id) for session_id in sessions])
