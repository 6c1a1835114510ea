"""A walk-up result given the patient's hospital identifier at the station (issue 36).

A walk-up session is recorded under a pseudonym the kiosk made up (``P-7K3Q-X9M4-TB2H``): nobody
typed who the patient was. Staff who know give it the identifier the hospital uses, checked
against the site's identifier rule (``--patient-id-pattern``), before a doctor signs it off: a
signed result is final, and who it is about is part of what was signed. Each change is a row of
the append-only audit trail (who, when, the old and the new identifier, why); the session's row
then carries the new identifier, which every page, list and export reads
(:func:`station.sessions.load_many`), and the kiosk's later rows never put the old one back
(:func:`kept_in`).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from kiosk.core.visits import WALK_UP
from kiosk.core.visits import check_patient_id as identifier_problem
from station import db
from station.db import audit, sessions, visits

#: the audit action of a change of identifier (its reason: "OLD -> NEW", then why)
ACTION = "identify"
#: who may give a result its identifier (the staff who order visits)
ROLES = ("nurse", "doctor")


class IdentifyError(ValueError):
    """The identifier cannot be given (one sentence naming what and why)."""


def _signed_ever(connection: Connection, session_id: str) -> bool:
    """Signed off now, or once (a result reopened to amend was signed under its identifier)."""
    return (
        connection.execute(
            sa.select(audit.c.id).where(audit.c.session_id == session_id, audit.c.action == "sign_off").limit(1)
        ).first()
        is not None
    )


def identify(engine: Engine, session_id: str, patient_id: str, by: Any, pattern: str, reason: str = "") -> str:
    """Give the walk-up result ``session_id`` the hospital identifier ``patient_id`` (matching the
    site's ``pattern``); returns the identifier it had. :class:`IdentifyError` for a result that is
    not a walk-up, was signed off, or for an identifier the rule refuses."""
    if by.role not in ROLES:
        raise IdentifyError("only nurses and doctors may give a result its patient identifier")
    patient_id = patient_id.strip()
    if (problem := identifier_problem(patient_id, pattern)) is not None:
        raise IdentifyError(f"patient identifier: {problem}")
    with engine.begin() as connection:
        row = connection.execute(
            sa.select(sessions.c.patient_id, sessions.c.status).where(sessions.c.id == session_id).with_for_update()
        ).first()
        if row is None or row.status == "pending":
            raise IdentifyError(f"no session {session_id} has reached this station")
        kind = connection.execute(sa.select(visits.c.kind).where(visits.c.session_id == session_id)).scalar()
        if kind != WALK_UP:
            how = {"order": "an ordered visit", "staff": "a visit staff started for an identifier"}.get(kind or "")
            raise IdentifyError(
                f"only a walk-up result is given an identifier here: this is {how or 'not recorded as a walk-up'}"
            )
        if _signed_ever(connection, session_id):
            raise IdentifyError(
                "the result was signed off: its patient identifier can no longer change "
                "(ask the doctor who signed it; the signed record stays as it is)"
            )
        old = row.patient_id or ""
        if old == patient_id:
            raise IdentifyError(f"the result already has the identifier {patient_id}")
        connection.execute(sessions.update().where(sessions.c.id == session_id).values(patient_id=patient_id))
        why = reason.strip()[:500]
        connection.execute(
            audit.insert().values(
                session_id=session_id,
                at=db.now_iso(),
                author=by.name[:64],
                action=ACTION,
                reason=f"patient identifier {old} -> {patient_id}" + (f": {why}" if why else ""),
            )
        )
    return old


def kept_in(connection: Connection, session_ids: Iterable[str]) -> set[str]:
    """The sessions staff gave an identifier: their row's ``patient_id`` is staff's, never the
    kiosk's ``create_session`` one again (the sync leaves it as it is)."""
    ids = list(session_ids)
    if not ids:
        return set()
    return set(
        connection.execute(
            sa.select(audit.c.session_id).where(audit.c.session_id.in_(ids), audit.c.action == ACTION)
        ).scalars()
    )
