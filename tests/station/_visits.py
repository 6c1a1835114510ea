"""A patient's visits stored through the station's own code, for the print and handover tests: a
walk-up Barthel, then an ordered battery (Barthel and MOOD4) started with the order's code, its
Barthel signed off by dr.lopez. Each session is a real kiosk's outbox rows (a scripted patient,
:func:`tests.station.helpers.record_patient`) taken in by :func:`station.sync.intake`."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from bench._history import clone
from kiosk.core.questionnaire import load_questionnaire
from station import auth, db, orders, sync, validation
from tests.instruments import MOOD4, MOOD4_PATIENT
from tests.station.helpers import PATIENTS, Row, record_patient

PATIENT = "NHC-0036001"
KIOSK = "ward3-bed2"
#: when the walk-up and the ordered visit began
WALK_UP_AT = datetime(2026, 10, 2, 9, 30, tzinfo=UTC)
ORDERED_AT = datetime(2026, 11, 20, 10, 15, tzinfo=UTC)


@dataclass
class Visits:
    walk_up: str
    order_id: str
    barthel: str
    mood: str


def _take(engine: Engine, rows: list[Row], session_id: str, when: datetime, first_seq: int) -> int:
    """Store ``rows`` as session ``session_id`` begun at ``when``; returns the next free seq."""
    with engine.begin() as connection:
        sync.intake(connection, KIOSK, sync.parse({"events": clone(rows, session_id, PATIENT, when, first_seq)}))
    return first_seq + len(rows)


def store_visits(engine: Engine) -> Visits:
    """Store the two visits on a ward made by :func:`tests.station.conftest.make_ward`."""
    walk_up = record_patient(PATIENTS / "barthel1.yaml", patient=PATIENT, visit="walk-up")
    seq = _take(engine, walk_up, "print-walk-up", WALK_UP_AT, 1)
    nurse = auth.User("nurse.kim", "nurse")
    order = orders.create(
        engine,
        kiosk_id=KIOSK,
        patient_id=PATIENT,
        instruments=["barthel", "mood4"],
        language="en",
        relative=False,
        by=nurse,
        known_instruments=["barthel", "mood4"],
        languages=["en"],
    )
    with engine.begin() as connection:
        assert orders.start(connection, KIOSK, order.code) is not None
    visit = f"order {order.id}"
    first = record_patient(PATIENTS / "barthel1.yaml", patient=PATIENT, visit=visit)
    seq = _take(engine, first, "print-barthel", ORDERED_AT, seq)
    second = record_patient(MOOD4_PATIENT, patient=PATIENT, questionnaire=load_questionnaire(MOOD4), visit=visit)
    _take(engine, second, "print-mood", ORDERED_AT.replace(minute=25), seq)
    validation.sign_off(engine, "print-barthel", auth.User("dr.lopez", "doctor"))
    return Visits("print-walk-up", order.id, "print-barthel", "print-mood")


def raise_alert(engine: Engine, session_id: str, seq: int, kind: str, at: datetime) -> int:
    """The kiosk reports alert ``kind`` in ``session_id`` at ``at`` (its row numbered ``seq``);
    returns the alert's id."""
    row = Row(seq, "record_event", session_id, {"t": 1.0, "kind": kind, "detail": ""}, 1.0, at.isoformat())
    with engine.begin() as connection:
        sync.intake(connection, KIOSK, sync.parse({"events": [row.event()]}))
        return int(connection.execute(sa.select(db.alerts.c.id).where(db.alerts.c.seq == seq)).scalar_one())
