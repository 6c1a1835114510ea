"""A patient's battery of three instruments stored through the station's own code, for the visit
tests: an order of Barthel, MOOD4 and a walking instrument with two staff items (a weight and a
choice, :data:`tests.kiosk.ui.test_six_options.SIX`), each a real kiosk's outbox rows (a scripted
patient) taken in by :func:`station.sync.intake`, after a walk-up Barthel weeks before
(:func:`tests.station._visits.store_visits`'s first visit)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from sqlalchemy.engine import Engine

from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from station import auth, orders
from tests.instruments import MOOD4, MOOD4_PATIENT
from tests.kiosk.ui.test_six_options import SIX
from tests.station._visits import KIOSK, ORDERED_AT, PATIENT, WALK_UP_AT, _take
from tests.station.helpers import PATIENTS, record_patient
from tests.station.test_staff_items import SCRIPT

NURSE, DOCTOR = auth.User("nurse.kim", "nurse"), auth.User("dr.lopez", "doctor")


@dataclass
class Battery:
    walk_up: str
    order_id: str
    barthel: str
    mood: str
    walking: str
    q: Questionnaire  # the walking instrument (its staff items)


def store_battery(engine: Engine, tmp_path: Path) -> Battery:
    """The walk-up, then the ordered battery (Barthel, MOOD4, walking), none signed off; the
    walking result waits for its weight and its aid (staff items)."""
    seq = _take(
        engine, record_patient(PATIENTS / "barthel1.yaml", patient=PATIENT, visit="walk-up"), "v-walk-up", WALK_UP_AT, 1
    )
    (tmp_path / "walking.yaml").write_text(SIX, encoding="utf-8")
    (tmp_path / "walking_patient.yaml").write_text(SCRIPT, encoding="utf-8")
    walking = load_questionnaire(tmp_path / "walking.yaml")
    order = orders.create(
        engine,
        kiosk_id=KIOSK,
        patient_id=PATIENT,
        instruments=["barthel", "mood4", "walking"],
        language="en",
        relative=False,
        by=NURSE,
        known_instruments=["barthel", "mood4", "walking"],
        languages=["en"],
    )
    with engine.begin() as connection:
        assert orders.start(connection, KIOSK, order.code) is not None
    visit = f"order {order.id}"
    runs = [
        ("v-barthel", record_patient(PATIENTS / "barthel1.yaml", patient=PATIENT, visit=visit)),
        (
            "v-mood",
            record_patient(MOOD4_PATIENT, patient=PATIENT, questionnaire=load_questionnaire(MOOD4), visit=visit),
        ),
        (
            "v-walking",
            record_patient(tmp_path / "walking_patient.yaml", patient=PATIENT, questionnaire=walking, visit=visit),
        ),
    ]
    for minutes, (session_id, rows) in zip((15, 25, 35), runs, strict=True):
        seq = _take(engine, rows, session_id, ORDERED_AT.replace(minute=minutes), seq)
    return Battery("v-walk-up", order.id, "v-barthel", "v-mood", "v-walking", walking)
