"""The Timed Up and Go ordered at a real station (issue 34, part 3), on SQLite and PostgreSQL: the
order form offers it, the order reaches the kiosk as the instrument id ``tug`` (and the kiosk's
order intake takes it), and the TUG result filed under the order moves it on as a finished
session does: a battery waits for its questionnaire too (a TUG alone is refused: the kiosk gives it
within a visit). A TUG that
claims another kiosk's order is refused, naming the field."""

from __future__ import annotations

import pytest

from kiosk.core.visits import parse_orders
from tests.station._tug import camera_result, stopwatch_result, tug_rows
from tests.station.conftest import make_ward, new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_orders import code_of, state

pytestmark = pytest.mark.slow
PATIENT = "NHC-0034001"


def order(nurse: Staff, kiosk: str, *instruments: str) -> str:
    placed = nurse.http.post(
        "/orders",
        data={
            "csrf": nurse.csrf(nurse.http.get("/").text),
            "patient_id": PATIENT,
            "kiosk": kiosk,
            "instrument": list(instruments),
            "language": "es",
        },
    )
    assert placed.status_code == 303 and "error" not in placed.headers["location"], placed.headers["location"]
    return placed.headers["location"]


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_an_ordered_tug_reaches_the_kiosk_and_completes_its_order(database, request, station_factory, tmp_path):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    assert 'value="tug"' in nurse.http.get("/orders").text

    # the kiosk gives the TUG within a visit, beside a questionnaire: alone it is refused, in words
    refused = nurse.http.post(
        "/orders",
        data={
            "csrf": nurse.csrf(nurse.http.get("/").text),
            "patient_id": PATIENT,
            "kiosk": ward.kiosk_id,
            "instrument": ["tug"],
            "language": "es",
        },
        follow_redirects=True,
    )
    assert "the Timed Up and Go is given within a visit: choose an instrument with it" in refused.text
    assert kiosk.orders()["orders"] == []
    _, problems = parse_orders(
        {"orders": [{"id": "o-1", "patient_id": PATIENT, "instruments": ["tug"], "language": "es", "code": "123456"}]},
        ["barthel"],
        ["en", "es", "fr"],
    )
    assert problems and "the Timed Up and Go alone" in problems[0]  # nor does the kiosk take one

    both = order(nurse, ward.kiosk_id, "barthel", "tug")
    listed = kiosk.orders()
    assert [o["instruments"] for o in listed["orders"]] == [["barthel", "tug"]]
    taken, problems = parse_orders(listed, ["barthel"], ["en", "es", "fr"])  # the kiosk's intake
    assert problems == [] and taken[0].instruments == ("barthel", "tug")
    battery_id = both.rsplit("/", 1)[1]
    assert kiosk.start_order(code_of(nurse, both)).status_code == 200
    (tug,) = tug_rows(
        tmp_path / "k2", [(PATIENT, stopwatch_result(), "2026-11-28T06:00:00Z")], visit=f"order {battery_id}"
    )
    assert kiosk.sync([tug]).status_code == 200
    assert state(db_url, battery_id)[0] == "in_progress"  # the questionnaire is still to come
    barthel = record_patient(
        PATIENTS / "barthel1.yaml", first_seq=tug.seq + 1, patient=PATIENT, visit=f"order {battery_id}"
    )
    synced = kiosk.sync(barthel)
    assert synced.status_code == 200, synced.text
    assert state(db_url, battery_id)[0] == "awaiting_validation"
    visit = nurse.http.get(f"/visits/{battery_id}").text  # the visit's page: its questionnaire and its TUG
    assert 'id="tug-results"' in visit and "Barthel Index" in visit and "the site&#39;s threshold" in visit
    kiosk.close()


def test_a_tug_claiming_another_kiosks_order_is_refused(shared_station, tmp_path):
    station, ward = shared_station
    nurse = Staff(station.url, "nurse.kim", "nurse")
    other, other_token = new_kiosk(ward.db_url)
    theirs = order(nurse, other, "barthel", "tug")
    kiosk, token = new_kiosk(ward.db_url)
    (row,) = tug_rows(
        tmp_path / "k", [(PATIENT, camera_result(), "2026-11-28T05:00:00Z")], visit=f"order {theirs.rsplit('/', 1)[1]}"
    )
    client = KioskClient(station.url, token, kiosk)
    try:
        response = client.sync([row])
    finally:
        client.close()
    assert response.status_code == 422, response.text
    assert response.json()["error"].startswith(f"seq {row.seq}: record_tug.visit: no order"), response.text
