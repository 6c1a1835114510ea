"""Results as the clinician follows them: the inbox of results waiting for validation, and one
patient's course across visits (each instrument's total, band and review state per visit).

Read-only views over what the kiosks sent (:mod:`station.sessions`) and the audit trail
(:mod:`station.validation`); scores are the session core's (the questionnaire scores the
corrected answers), never a stored copy.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.review import review_state
from kiosk.export import ExportError
from kiosk.export.captured import questionnaire_of
from station import order_progress, validation
from station.db import audit, sessions
from station.sessions import load

#: inbox filters: which review states each shows
INBOX_STATES = {"waiting": ("unreviewed", "corrected"), "signed": ("signed_off", "amended"), "all": None}
INBOX_LIMIT = 100
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

    @property
    def instrument(self) -> str:
        """What a clinician reads for the instrument: its title, else its id."""
        return self.title or self.questionnaire_id

    @property
    def review_words(self) -> str:
        return self.review.replace("_", " ")

    @property
    def visit_words(self) -> str:
        return VISIT_WORDS.get(self.visit, "not recorded")


def _signed(engine: Engine) -> Any:
    """Sessions whose latest sign-off or reopening is a sign-off: a result a doctor reopened to
    amend waits for validation again, as :func:`kiosk.core.review.review_from_steps` says."""
    latest = (
        sa.select(audit.c.session_id, sa.func.max(audit.c.id).label("last"))
        .where(audit.c.action.in_(("sign_off", "amend")))
        .group_by(audit.c.session_id)
        .subquery()
    )
    return sa.select(latest.c.session_id).join(audit, audit.c.id == latest.c.last).where(audit.c.action == "sign_off")


def waiting_count(engine: Engine) -> int:
    """Finished results no doctor has signed off yet (the count in the navigation)."""
    with engine.connect() as connection:
        return int(
            connection.execute(
                sa.select(sa.func.count())
                .select_from(sessions)
                .where(sessions.c.status == "finished", sessions.c.id.not_in(_signed(engine)))
            ).scalar_one()
        )


def results_of(engine: Engine, q: Questionnaire, rows: Sequence[Any]) -> list[Result]:
    """The results of these session rows (anything with an ``id``), in their order."""
    ids = [r.id for r in rows]
    reviews = validation.reviews(engine, ids)
    kinds = order_progress.visit_kinds(engine, ids)
    found = []
    with engine.connect() as connection:
        for row in rows:
            kiosk, stored = load(connection, row.id)
            review = reviews[row.id]
            try:  # scored on the questionnaire the session ran, not the one the station bundles
                ran = questionnaire_of(stored, fallback=q)
            except ExportError:
                ran = None
            score = (
                validation.corrected(stored, ran, review)["score"]
                if ran and stored.questionnaire_id == ran.id
                else None
            )
            state = review_state(review, {a.item_id: a.option for a in stored.answers})
            kind, order_id = kinds.get(row.id, ("", None))
            found.append(
                Result(
                    row.id,
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
                )
            )
    return found


def inbox(engine: Engine, q: Questionnaire, *, state: str = "waiting", kiosk_id: str | None = None) -> list[Result]:
    """Finished results, newest first, in the review states of ``state`` (:data:`INBOX_STATES`),
    of one kiosk or all."""
    query = (
        sa.select(sessions.c.id)
        .where(sessions.c.status == "finished")
        .order_by(sessions.c.finished_at.desc())
        .limit(INBOX_LIMIT)
    )
    if kiosk_id:
        query = query.where(sessions.c.kiosk_id == kiosk_id)
    if state == "waiting":
        query = query.where(sessions.c.id.not_in(_signed(engine)))
    elif state == "signed":
        query = query.where(sessions.c.id.in_(_signed(engine)))
    with engine.connect() as connection:
        rows = connection.execute(query).all()
    return results_of(engine, q, rows)


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
        for questionnaire_id, session_id in latest.items():
            _, stored = load(connection, session_id)
            try:
                ran = questionnaire_of(stored, fallback=q if questionnaire_id == q.id else None)
            except ExportError:  # nothing to plot it against: its rows still list the visit
                continue
            if ran.id == questionnaire_id:
                found.append(ran)
    return found or [q]


def search(engine: Engine, text: str, limit: int = 50) -> list[tuple[str, int, str]]:
    """Patients whose identifier contains ``text`` (case-insensitive): (id, visits, last visit)."""
    text = text.strip()
    if not text:
        return []
    pattern = "%" + text.replace("\\", "\\\\").replace("%", "\\%").replace("_", "\\_") + "%"
    query = (
        sa.select(sessions.c.patient_id, sa.func.count(), sa.func.max(sessions.c.started_at))
        .where(sessions.c.patient_id.ilike(pattern, escape="\\"), sessions.c.status != "pending")
        .group_by(sessions.c.patient_id)
        .order_by(sa.func.max(sessions.c.started_at).desc())
        .limit(limit)
    )
    with engine.connect() as connection:
        return [(p, int(n), last or "") for p, n, last in connection.execute(query)]
