"""Results as the clinician follows them: each session's result as a row (total, band, review
state), one patient's course, the count of results waiting and the patient search. The inbox
lists them by visit (:mod:`station.visit_inbox`).

Read-only views over what the kiosks sent (:mod:`station.sessions`) and the audit trail
(:mod:`station.validation`); scores are the session core's (the questionnaire scores the
corrected answers), never a stored copy.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.review import review_state
from kiosk.core.staff import every_entered
from kiosk.export import ExportError
from station import order_progress, validation
from station.db import sessions, tug_results
from station.db import visits as visit_table
from station.definitions import questionnaire_for
from station.sessions import LIFECYCLE, RESULT_KINDS, load_many

VISIT_WORDS = {"order": "ordered", "staff": "started by staff", "walk-up": "walk-up"}


@record
class Result:
    """One session's result as a row of the inbox or of a patient's course."""

    session_id: str
    kiosk_id: str
    patient_id: str
    questionnaire_id: str
    started_at: str
    finished_at: str | None
    status: str
    total: int | None
    max_total: int
    complete: bool
    band: str | None
    review: str
    simulated: bool
    visit: str
    order_id: str | None
    #: the instrument's title as the session's captured definition gives it ("" if it has none)
    title: str = ""
    #: the band's label in the session's language, as staff read it ("" without a band)
    band_label: str = ""

    @property
    def instrument(self) -> str:
        """What a clinician reads for the instrument: its title, else its id."""
        return self.title or self.questionnaire_id

    @property
    def review_words(self) -> str:
        return self.review.replace("_", " ")

    @property
    def total_words(self) -> str:
        """The total as staff read it ("5 of 14"), else why there is none."""
        if self.total is not None:
            return f"{self.total} of {self.max_total}"
        return "incomplete" if self.status == "finished" else self.status.replace("_", " ")

    @property
    def visit_words(self) -> str:
        return VISIT_WORDS.get(self.visit, "not recorded")


def waiting_count(engine: Engine) -> int:
    """Finished results no doctor has signed off yet (the count in the navigation): an index
    range over the results waiting, whatever the years of signed ones."""
    with engine.connect() as connection:
        return waiting_in(connection)


def waiting_in(connection: Connection) -> int:
    return int(
        connection.execute(
            sa.select(sa.func.count())
            .select_from(sessions)
            .where(sessions.c.status == "finished", sessions.c.signed_at.is_(None))
        ).scalar_one()
    )


def results_of(engine: Engine, q: Questionnaire, rows: Sequence[Any]) -> list[Result]:
    """The results of these session rows (anything with an ``id``), in their order: a handful of
    queries for the whole list (:func:`station.sessions.load_many`), each definition parsed once."""
    ids = [r.id for r in rows]
    kinds = order_progress.visit_kinds(engine, ids)
    found = []
    with engine.connect() as connection:
        loaded = load_many(connection, ids, RESULT_KINDS)
        trails = validation.trails_in(connection, ids)
    for session_id in ids:
        if session_id not in loaded:
            continue
        kiosk, stored = loaded[session_id]
        review = validation.review_of(trails[session_id])
        try:  # scored on the questionnaire the session ran, not the one the station bundles
            ran = questionnaire_for(stored, fallback=q)
        except ExportError:
            ran = None
        score = (
            validation.corrected(stored, ran, review, every_entered(ran, stored.log, trails[session_id]))["score"]
            if ran and stored.questionnaire_id == ran.id
            else None
        )
        state = review_state(review, {a.item_id: a.option for a in stored.answers})
        kind, order_id = kinds.get(session_id, ("", None))
        found.append(
            Result(
                session_id,
                kiosk,
                stored.patient_id,
                stored.questionnaire_id,
                stored.started_at,
                stored.finished_at,
                stored.status,
                score.total if score and score.complete else None,
                score.max_total if score else 0,
                bool(score and score.complete),
                score.band.id if score and score.band else None,
                state.value,
                stored.simulated,
                kind,
                order_id,
                (ran.title.get(stored.language) or ran.title.get("en") or "") if ran else "",
                _label(score.band.label, stored.language, score.band.id) if score and score.band else "",
            )
        )
    return found


def _label(texts: Any, language: str, fallback: str) -> str:
    return str(texts.get(language) or texts.get("en") or fallback)


def course(engine: Engine, q: Questionnaire, patient_id: str) -> list[Result]:
    """Every visit of one patient that reached this station, oldest first (running, abandoned
    and interrupted ones too: the course shows what happened, the plot only what was scored)."""
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(sessions.c.id)
            .where(sessions.c.patient_id == patient_id, sessions.c.status != "pending")
            .order_by(sessions.c.started_at)
        ).all()
    return results_of(engine, q, rows)


def instruments(engine: Engine, q: Questionnaire, visits: list[Result]) -> list[Questionnaire]:
    """The questionnaires of a patient's course, one per instrument in order of first visit: each as
    its latest visit captured it (a site's own questionnaire plots on its own scale and bands);
    ``q`` (the station's) when there is no visit, or a visit captured none."""
    latest: dict[str, str] = {}
    for visit in visits:
        latest[visit.questionnaire_id] = visit.session_id
    found: list[Questionnaire] = []
    with engine.connect() as connection:
        loaded = load_many(connection, latest.values(), LIFECYCLE)
    for questionnaire_id, session_id in latest.items():
        if session_id not in loaded:
            continue
        _, stored = loaded[session_id]
        try:
            ran = questionnaire_for(stored, fallback=q if questionnaire_id == q.id else None)
        except ExportError:  # nothing to plot it against: its rows still list the visit
            continue
        if ran.id == questionnaire_id:
            found.append(ran)
    return found or [q]


def prefix_range(text: str) -> tuple[str, str]:
    """The identifiers starting with ``text`` as a range [low, high) in code-point order: what an
    index on the identifier answers without reading the rest (a contains-search reads them all)."""
    return text, text[:-1] + chr(ord(text[-1]) + 1)


def _starts_with(text: str, postgres: bool, column: Any = sessions.c.patient_id) -> Any:
    if postgres:  # the text_pattern_ops index answers LIKE 'prefix%' (Alembic 0006_history)
        escaped = text.replace("\\", "\\\\").replace("%", "\\%").replace("_", "\\_")
        return column.like(escaped + "%", escape="\\")
    low, high = prefix_range(text)
    return sa.and_(column >= low, column < high)


def search(engine: Engine, text: str, limit: int = 50) -> list[tuple[str, int, str]]:
    """Patients whose identifier starts with ``text`` as typed or in capitals (hospital numbers
    are written in capitals, staff type in either): (id, visits, last visit), latest first. A
    visit is the sessions of one order (a battery), or a session no order started."""
    text = text.strip()
    if not text:
        return []
    postgres = engine.dialect.name == "postgresql"
    prefixes = list(dict.fromkeys((text, text.upper())))
    query = (
        sa.select(
            sessions.c.patient_id,
            sa.func.count(sa.distinct(sa.func.coalesce(visit_table.c.order_id, sessions.c.id))),
            sa.func.max(sessions.c.started_at),
        )
        .select_from(sessions.outerjoin(visit_table, visit_table.c.session_id == sessions.c.id))
        .where(sa.or_(*(_starts_with(p, postgres) for p in prefixes)), sessions.c.status != "pending")
        .group_by(sessions.c.patient_id)
        .order_by(sa.func.max(sessions.c.started_at).desc())
        .limit(limit)
    )
    # and the patients whose only visits at this station were Timed Up and Go tests
    column = tug_results.c.patient_id
    timed = (
        sa.select(column, sa.func.count(), sa.func.max(tug_results.c.at))
        .where(sa.or_(*(_starts_with(p, postgres, column) for p in prefixes)))
        .group_by(column)
        .limit(limit)
    )
    with engine.connect() as connection:
        found = {p: (int(n), last or "") for p, n, last in connection.execute(query)}
        for patient, n, last in connection.execute(timed):
            seen, latest = found.get(patient, (0, ""))
            found[patient] = (seen + int(n), max(latest, last or ""))
    ranked = sorted(found.items(), key=lambda kv: kv[1][1], reverse=True)[:limit]
    return [(p, n, last) for p, (n, last) in ranked]
