"""The station's side of cancelling a running visit (issue 36), against a real `kiosk station`
process on SQLite and PostgreSQL, the kiosk played over HTTP: the orders poll lists the cancelled
order the kiosk holds (and a just-cancelled one it could not say it holds yet), the ward's tile
and Results say "cancelled", and the kiosk's end (an abandon row) leaves the order cancelled with
its trail saying the session ended. The kiosk's own part: tests/kiosk/sync/test_order_cancel_kiosk.py."""

from __future__ import annotations

import pytest

from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, KioskClient, Row, Staff, record_patient
from tests.station.test_orders import code_of, order, state

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_cancelled_running_visit_is_told_to_its_kiosk_and_shown_cancelled(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse = Staff(station.url, "nurse.kim", "nurse")

    placed = order(nurse, ward.kiosk_id, patient="NHC-0036501")
    order_id = placed.headers["location"].rsplit("/", 1)[1]
    assert kiosk.start_order(code_of(nurse, placed.headers["location"])).status_code == 200
    before = kiosk.http.get("/api/v1/orders", params={"held": ""}).json()
    assert before["cancelled"] == []

    # cancelled before the kiosk said it holds it (its session not stored yet): still told
    assert nurse.post(f"/orders/{order_id}/cancel", reason="wrong patient").status_code == 303
    assert kiosk.http.get("/api/v1/orders", params={"held": ""}).json()["cancelled"] == [order_id]

    # a running visit: the poll that holds it lists it, the tile and Results say "cancelled"
    second = order(nurse, ward.kiosk_id, patient="NHC-0036502")
    second_id = second.headers["location"].rsplit("/", 1)[1]
    assert kiosk.start_order(code_of(nurse, second.headers["location"])).status_code == 200
    rows = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-0036502", visit=f"order {second_id}")
    first_answer = next(i for i, r in enumerate(rows) if r.kind == "record_answer")
    assert kiosk.sync(rows[: first_answer + 1]).status_code == 200
    session_id = rows[0].session_id
    kiosk.status(session_id=session_id, patient_id="NHC-0036502", phase="questions", question=2, of=10)
    assert "visit cancelled" not in nurse.http.get("/").text
    page = nurse.http.get(f"/orders/{second_id}").text
    assert f"The visit is running on kiosk {ward.kiosk_id}: cancelling ends it" in page
    assert nurse.post(f"/orders/{second_id}/cancel", reason="patient discharged").status_code == 303
    polled = kiosk.http.get("/api/v1/orders", params={"held": second_id}).json()
    assert polled["cancelled"] == sorted([order_id, second_id]) and polled["orders"] == []
    ward_page = nurse.http.get("/").text
    tile = ward_page.split(f'id="kiosk-{ward.kiosk_id}"', 1)[1].split("</article>", 1)[0]
    assert "visit cancelled: the kiosk is ending it" in tile

    # the kiosk ends it: its answers and the end reach the station, the order stays cancelled
    end = Row(len(rows) + 1, "abandon", session_id, {}, rows[first_answer].t, rows[first_answer].at)
    assert kiosk.sync([end]).status_code == 200
    kiosk.status(session_id=None, phase="welcome")
    assert state(db_url, second_id)[0] == "cancelled"
    trail = nurse.http.get(f"/orders/{second_id}").text
    assert f"session {session_id} of the cancelled visit ended on {ward.kiosk_id}" in trail
    results = nurse.http.get("/fragments/results").text
    row = results.split(f'data-session="{session_id}"', 1)[1].split("</li>", 1)[0]
    assert '<span class="badge status">cancelled</span>' in row
    session_page = nurse.http.get(f"/sessions/{session_id}").text
    answer = rows[first_answer].payload
    item_row = session_page.split(f'id="item-{answer["item_id"]}"', 1)[1].split("</tr>", 1)[0]
    assert "abandoned" in session_page and f"<b>{answer['option']}. " in item_row  # ended, its answer kept
    kiosk.close()
