"""A validation study's visits stored through the station's own code: four patients' Barthel
results from a real kiosk's outbox (scripted patients, :func:`tests.station.helpers.record_patient`,
taken in by :func:`station.sync.intake`), three complete and one with two items unanswered; an
earlier result of the first patient and one outside the study's days, and the answers
:data:`CLINICIAN` a clinician gets for each."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime

from sqlalchemy.engine import Engine

from bench._history import clone
from station import sync
from tests.station.helpers import PATIENTS, record_patient

KIOSK = "ward3-bed2"
FIRST_DAY = datetime(2026, 11, 2, 9, 0, tzinfo=UTC)
#: patient, the scripted kiosk patient, the day of the month the kiosk result was taken
RESULTS = [
    ("NHC-0081001", "barthel1.yaml", 10),
    ("NHC-0081002", "barthel2.yaml", 11),
    ("NHC-0081003", "barthel3.yaml", 12),
    ("NHC-0081004", "barthel4.yaml", 13),  # the kiosk's result lacks grooming and bladder
    ("NHC-0081001", "barthel3.yaml", 3),  # the first patient's earlier result: not in the study
    ("NHC-0081005", "barthel2.yaml", 25),  # after the study's last day
]
#: where each clinician's answer differs from the kiosk's (session index -> item -> option)
DIFFERENT = {0: {"transfers": 3}, 1: {"bathing": 1, "stairs": 3}, 3: {"grooming": 1, "bladder": 3}, 4: {"feeding": 1}}


@dataclass
class StudyVisits:
    session_ids: list[str]
    #: what the kiosk recorded, per session
    kiosk: list[dict[str, int]]
    #: what the clinician answered, per session
    clinician: list[dict[str, int]]


def store_study_visits(engine: Engine) -> StudyVisits:
    """Store the results of :data:`RESULTS` (the clinician's answers are the test's to enter)."""
    seq, ids, kiosk, clinician = 1, [], [], []
    for n, (patient, script, day) in enumerate(RESULTS):
        rows = record_patient(PATIENTS / script, patient=patient)
        session_id = f"study-{n}"
        when = FIRST_DAY.replace(day=day)
        with engine.begin() as connection:
            sync.intake(connection, KIOSK, sync.parse({"events": clone(rows, session_id, patient, when, seq)}))
        seq += len(rows)
        recorded = {r.payload["item_id"]: r.payload["option"] for r in rows if r.kind == "record_answer"}
        ids.append(session_id)
        kiosk.append(recorded)
        every = {**recorded, "grooming": recorded.get("grooming", 2), "bladder": recorded.get("bladder", 2)}
        clinician.append({**every, **DIFFERENT.get(n, {})})
    return StudyVisits(ids, kiosk, clinician)
