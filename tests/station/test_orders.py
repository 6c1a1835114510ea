"""Orders against a real `kiosk station` process, on SQLite and on PostgreSQL: staff order a visit,
only the ordered kiosk sees it and only with the order's code does it start, the kiosk's session is
filed under the order (never under another patient), and every step is in the audit trail."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest
import sqlalchemy as sa

from station import db
from station.orders import orders as orders_table
from tests.station.conftest import PATIENCE_S, make_ward, new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

pytestmark = pytest.mark.slow
CODE = re.compile(r'id="order-code"[^>]*>(\d{4})<')


def order(staff: Staff, kiosk: str, patient: str = "NHC-0012345", **extra: str):
    return staff.post("/orders", patient_id=patient, kiosk=kiosk, instrument="barthel", language="en", **extra)


def code_of(staff: Staff, location: str) -> str:
    return CODE.search(staff.http.get(location).text).group(1)


def state(db_url: str, order_id: str) -> tuple[str, str | None]:
    engine = db.make_engine(db_url)
    try:
        with engine.connect() as connection:
            row = connection.execute(
                sa.select(orders_table.c.state, orders_table.c.session_id).where(orders_table.c.id == order_id)
            ).one()
    finally:
        engine.dispose()
    return row.state, row.session_id


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_an_order_goes_from_ordered_to_signed_off_on_its_own_kiosk_only(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    other_name, other_token = new_kiosk(db_url)
    mine = KioskClient(station.url, ward.token, ward.kiosk_id)
    other = KioskClient(station.url, other_token, other_name)
    nurse, doctor = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url)

    placed = order(nurse, ward.kiosk_id, relative="yes")  # a nurse may order
    assert placed.status_code == 303
    order_id = placed.headers["location"].rsplit("/", 1)[1]
    code = code_of(nurse, placed.headers["location"])

    listed = mine.orders()
    assert [o["patient_id"] for o in listed["orders"]] == ["NHC-0012345"]
    assert listed["orders"][0]["answered_by"] == "relative" and "code" not in listed["orders"][0]
    assert other.orders()["orders"] == []  # kiosk B never reads kiosk A's order
    assert other.start_order(code).status_code == 404  # ... nor starts it with A's code
    assert mine.start_order("0000" if code != "0000" else "1111").status_code == 404
    assert state(db_url, order_id) == ("ordered", None)

    started = mine.start_order(code)
    assert started.status_code == 200, started.text
    assert started.json()["order"]["id"] == order_id
    assert state(db_url, order_id)[0] == "in_progress"
    assert mine.orders()["orders"] == []  # started: no longer waiting on the kiosk's welcome
    assert mine.start_order(code).status_code == 404  # a code starts one visit once

    identity = {"site": "north-hospital", "kiosk_id": ward.kiosk_id}
    rows = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-0012345", visit=f"order {order_id}", export=identity)
    assert mine.sync(rows).status_code == 200
    waiting, session_id = state(db_url, order_id)
    assert waiting == "awaiting_validation" and session_id == rows[0].session_id

    assert doctor.post(f"/sessions/{session_id}/sign-off").status_code == 303
    assert state(db_url, order_id) == ("signed_off", session_id)
    # the ordered visit's result names the site and kiosk that recorded it, not the station's defaults
    bundle = doctor.http.get(f"/sessions/{session_id}/export.json").json()
    (response,) = [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse"]
    named = json.dumps(response["identifier"])
    assert "north-hospital" in named and ward.kiosk_id in named
    # reopened to amend, the order awaits validation again; signed again, it is signed off again
    assert doctor.post(f"/sessions/{session_id}/amend", reason="new information").status_code == 303
    assert state(db_url, order_id) == ("awaiting_validation", session_id)
    assert doctor.post(f"/sessions/{session_id}/sign-off").status_code == 303
    assert state(db_url, order_id) == ("signed_off", session_id)
    page = doctor.http.get(f"/orders/{order_id}").text
    for step in ("order:", "order start", "order session", "order result", "order signed", "order reopened"):
        assert step in page, step
    mine.close()
    other.close()


def test_a_name_is_never_taken_for_a_patient_identifier(shared_station):
    station, ward = shared_station
    nurse = Staff(station.url, "nurse.kim", "nurse")
    for name in ("Maria Lopez", "LOPEZ", "O'Neill", "x" * 65, "MariaLopez19450312"):
        refused = order(nurse, ward.kiosk_id, patient=name)
        assert refused.status_code == 303 and refused.headers["location"].startswith("/orders?error=")
        page = nurse.http.get(refused.headers["location"]).text
        assert "never a name" in page
    engine = db.make_engine(ward.db_url)
    with engine.connect() as connection:
        stored = connection.execute(sa.select(orders_table.c.patient_id)).scalars().all()
    engine.dispose()
    assert not any(" " in p or p in ("LOPEZ", "O'Neill") for p in stored)


def test_a_session_for_another_patient_is_not_filed_under_the_order(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    kiosk = KioskClient(station.url, token, name)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    placed = order(nurse, name, patient="NHC-777")
    order_id = placed.headers["location"].rsplit("/", 1)[1]
    assert kiosk.start_order(code_of(nurse, placed.headers["location"])).status_code == 200
    rows = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-888", visit=f"order {order_id}")
    refused = kiosk.sync(rows)
    assert refused.status_code == 422 and "is for patient NHC-777" in refused.json()["error"]
    assert state(ward.db_url, order_id) == ("in_progress", None)
    kiosk.close()


def test_guessing_codes_is_stopped_and_staff_forms_need_their_token(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    kiosk = KioskClient(station.url, token, name)
    answers = [kiosk.start_order(f"{n:04d}") for n in range(9000, 9003)]
    assert [a.status_code for a in answers] == [404, 404, 429]  # two typos are free; then a slot
    assert answers[2].headers["retry-after"] == str(answers[2].json()["retry_after_s"])
    nurse = Staff(station.url, "nurse.kim", "nurse")
    forged = nurse.http.post(
        "/orders", data={"patient_id": "NHC-1", "kiosk": name, "instrument": "barthel", "language": "en"}
    )
    assert forged.status_code == 403
    assert kiosk.orders()["orders"] == []
    kiosk.close()


def test_staff_order_at_most_thirty_visits_in_ten_minutes_and_a_nurse_never_signs_off(request, station_factory):
    ward = make_ward(request.getfixturevalue("sqlite_url"))
    station = station_factory(ward.db_url)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    # 31 patients queued on one kiosk: each confirmed past the double-booking warning
    answers = [order(nurse, ward.kiosk_id, patient=f"NHC-{n:04d}", anyway="yes").headers["location"] for n in range(31)]
    assert all(a.startswith("/orders/order-") for a in answers[:30])
    assert (
        answers[30].startswith("/orders?error=")
        and "30 visits in the last 10 minutes" in nurse.http.get(answers[30]).text
    )
    assert len(KioskClient(station.url, ward.token, ward.kiosk_id).orders()["orders"]) == 30
    rows = record_patient(PATIENTS / "barthel1.yaml")
    assert KioskClient(station.url, ward.token, ward.kiosk_id).sync(rows).status_code == 200
    asked = nurse.http.get(f"/sessions/{rows[0].session_id}/sign-off")
    assert asked.status_code == 303 and "Only%20a%20doctor" in asked.headers["location"]
    assert "only a doctor can sign off" in nurse.post(f"/sessions/{rows[0].session_id}/sign-off").headers[
        "location"
    ].replace("%20", " ")


def test_a_sites_identifier_pattern_is_the_stations_rule_and_a_pattern_taking_names_is_refused(
    tmp_path, station_factory
):
    ward = make_ward(db.sqlite_url(tmp_path / "data"))
    station = station_factory(ward.db_url, args=("--patient-id-pattern", "NHC-[0-9]{7}"))
    nurse = Staff(station.url, "nurse.kim", "nurse")
    assert order(nurse, ward.kiosk_id, patient="NHC-0012345").headers["location"].startswith("/orders/order-")
    refused = order(nurse, ward.kiosk_id, patient="12345678")
    assert "the site&#39;s identifiers match NHC-[0-9]{7}" in nurse.http.get(refused.headers["location"]).text
    started = subprocess.run(
        [sys.executable, "-m", "kiosk", "station", "--db", ward.db_url, "--patient-id-pattern", "[A-Za-z0-9]+"],
        capture_output=True,
        text=True,
        timeout=PATIENCE_S,
    )
    assert started.returncode == 2 and started.stderr.count("\n") == 1
    assert "--patient-id-pattern accepts the name 'MariaLopez19450312'" in started.stderr
