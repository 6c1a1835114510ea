"""A battery's order at a real `kiosk station` process, on SQLite and on PostgreSQL: the order runs
a session per instrument, stays in progress until the last instrument's result arrives, then
awaits validation, and is signed off only when every result of it is."""

from __future__ import annotations

import re

import pytest

from kiosk.core.questionnaire import load_questionnaire
from tests.instruments import MOOD4, MOOD4_PATIENT
from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_orders import code_of, state

pytestmark = pytest.mark.slow
PATIENT = "NHC-0020001"


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_battery_order_waits_for_every_instrument_and_every_sign_off(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse, doctor = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url)
    mood4 = load_questionnaire(MOOD4)
    # the station learns the second instrument from a walk-up result, as a ward's would
    known = record_patient(MOOD4_PATIENT, patient="NHC-0020999", questionnaire=mood4, visit="walk-up")
    assert kiosk.sync(known).status_code == 200
    seq = len(known) + 1

    placed = nurse.http.post(
        "/orders",
        data={
            "csrf": nurse.csrf(nurse.http.get("/").text),
            "patient_id": PATIENT,
            "kiosk": ward.kiosk_id,
            "instrument": ["barthel", "mood4"],
            "language": "en",
        },
    )
    assert placed.status_code == 303 and "error" not in placed.headers["location"], placed.headers["location"]
    order_id = placed.headers["location"].rsplit("/", 1)[1]
    assert kiosk.start_order(code_of(nurse, placed.headers["location"])).status_code == 200

    visit = f"order {order_id}"
    first = record_patient(PATIENTS / "barthel1.yaml", first_seq=seq, patient=PATIENT, visit=visit)
    assert kiosk.sync(first).status_code == 200
    # one instrument of two done: the order is still in progress, nothing waits yet
    assert state(db_url, order_id)[0] == "in_progress"
    second = record_patient(
        MOOD4_PATIENT, first_seq=seq + len(first), patient=PATIENT, questionnaire=mood4, visit=visit
    )
    synced = kiosk.sync(second)
    assert synced.status_code == 200, synced.text
    assert state(db_url, order_id)[0] == "awaiting_validation"

    barthel_id, mood_id = first[0].session_id, second[0].session_id
    assert doctor.post(f"/sessions/{barthel_id}/sign-off").status_code == 303
    assert state(db_url, order_id)[0] == "awaiting_validation"  # the mood result is not signed yet
    assert doctor.post(f"/sessions/{mood_id}/sign-off").status_code == 303
    assert state(db_url, order_id)[0] == "signed_off"
    page = doctor.http.get(f"/orders/{order_id}").text
    assert re.search(r"1 of 2 instruments done", page), "the first instrument's step is in the audit trail"
    kiosk.close()
