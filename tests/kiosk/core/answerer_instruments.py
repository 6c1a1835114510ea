"""A caregiver instrument for the tests of who answers (``answered_by: caregiver``): the short
two-item instrument of the battery tests, answered by the person who looks after the patient."""

from __future__ import annotations

from pathlib import Path

from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from kiosk.core.session import Session
from tests.kiosk.battery_instruments import write_mini

TIMING = {"attempt_window_s": 30, "between_questions_s": 15, "resume_grace_s": 10, "person_back_grace_s": 5}


def caregiver_instrument(directory: Path) -> Questionnaire:
    """The two-item instrument ``carer``, its file saying ``answered_by: caregiver``."""
    path = write_mini(directory, id="carer")
    path.write_text("answered_by: caregiver\n" + path.read_text())
    return load_questionnaire(path)


def session_of(q: Questionnaire, clock: SimClock, **kwargs) -> Session:
    """A session of ``q`` on ``clock`` with no QoS engine, no practice questions and round timings."""
    return Session(q, clock=clock, engine=None, patient_id="T-0001", timing=TIMING, familiarisation=False, **kwargs)
