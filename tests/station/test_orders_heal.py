"""Orders that heal after their kiosk stopped mid-visit, at a real `kiosk station` process on
SQLite and PostgreSQL. The kiosk tells the station, on every orders poll, the orders it can
still go on with (``held``): an order in progress that it no longer holds goes back to ordered
when nothing of it was stored (the kiosk stopped after the code was accepted and before a session
was stored), or its finished instruments wait for validation (it stopped between two instruments
of a battery). An order held, or started within the grace, is left alone."""

from __future__ import annotations

import pytest
import sqlalchemy as sa

from kiosk.core.questionnaire import load_questionnaire
from station import db
from station.orders import orders as orders_table
from tests.instruments import MOOD4, MOOD4_PATIENT
from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_orders import code_of, state

pytestmark = pytest.mark.slow
PATIENT = "NHC-0031001"


def _order(nurse: Staff, ward, instruments: list[str]) -> tuple[str, str]:
    placed = nurse.http.post(
        "/orders",
        data={
            "csrf": nurse.csrf(nurse.http.get("/").text),
            "patient_id": PATIENT,
            "kiosk": ward.kiosk_id,
            "instrument": instruments,
            "language": "en",
        },
    )
    assert placed.status_code == 303 and "error" not in placed.headers["location"], placed.headers["location"]
    return placed.headers["location"].rsplit("/", 1)[1], code_of(nurse, placed.headers["location"])


def _poll(kiosk: KioskClient, held: list[str]) -> list[str]:
    """One orders poll telling the station what the kiosk holds: the ids of the ready orders."""
    response = kiosk.http.get("/api/v1/orders", params={"wait": 0, "held": ",".join(held)})
    assert response.status_code == 200, response.text
    return [o["id"] for o in response.json()["orders"]]


def _started_long_ago(db_url: str, order_id: str) -> None:
    """As if the order went in progress before the grace (the kiosk came back a minute later)."""
    engine = db.make_engine(db_url)
    with engine.begin() as connection:
        connection.execute(
            orders_table.update()
            .where(orders_table.c.id == order_id)
            .values(updated_at="2000-01-01T00:00:00.000+00:00")
        )
    engine.dispose()


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_an_order_whose_kiosk_stopped_after_the_code_goes_back_to_ordered(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    order_id, code = _order(nurse, ward, ["barthel"])
    assert kiosk.start_order(code).status_code == 200  # ... and the kiosk is killed: no session stored
    assert state(db_url, order_id) == ("in_progress", None)

    assert _poll(kiosk, []) == []  # just started: the kiosk may not have stored the session yet
    assert state(db_url, order_id)[0] == "in_progress"
    _started_long_ago(db_url, order_id)
    assert kiosk.http.get("/api/v1/orders", params={"wait": 0}).status_code == 200  # an older kiosk tells nothing
    assert state(db_url, order_id)[0] == "in_progress"
    assert _poll(kiosk, ["order-of-another-visit"]) == [order_id]  # the restarted kiosk: ready again
    assert state(db_url, order_id) == ("ordered", None)
    page = nurse.http.get(f"/orders/{order_id}").text
    assert "runs no session of this visit" in page and "started again with its code" in page

    # started again with its code, a session of it running at the kiosk: held, never released
    assert kiosk.start_order(code).status_code == 200
    rows = record_patient(PATIENTS / "barthel1.yaml", patient=PATIENT, visit=f"order {order_id}")
    running = [r for r in rows if r.kind != "finish_session"]
    assert kiosk.sync(running).status_code == 200
    _started_long_ago(db_url, order_id)
    assert _poll(kiosk, [order_id]) == []
    assert state(db_url, order_id) == ("in_progress", rows[0].session_id)
    kiosk.close()


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_battery_whose_kiosk_stopped_between_instruments_waits_for_validation(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    mood4 = load_questionnaire(MOOD4)
    known = record_patient(MOOD4_PATIENT, patient="NHC-0031999", questionnaire=mood4, visit="walk-up")
    assert kiosk.sync(known).status_code == 200  # the station learns the second instrument
    order_id, code = _order(nurse, ward, ["barthel", "mood4"])
    assert kiosk.start_order(code).status_code == 200
    first = record_patient(
        PATIENTS / "barthel1.yaml", first_seq=len(known) + 1, patient=PATIENT, visit=f"order {order_id}"
    )
    assert kiosk.sync(first).status_code == 200  # the Barthel finished ... and the kiosk is killed
    assert state(db_url, order_id)[0] == "in_progress"

    _started_long_ago(db_url, order_id)
    assert _poll(kiosk, []) == []
    assert state(db_url, order_id)[0] == "awaiting_validation"
    page = nurse.http.get(f"/orders/{order_id}").text
    assert "the 1 finished instrument(s) of 2 wait for validation" in page
    engine = db.make_engine(db_url)
    with engine.connect() as connection:
        status = connection.execute(sa.select(db.sessions.c.status).where(db.sessions.c.id == first[0].session_id))
        assert status.scalar_one() == "finished"
    engine.dispose()
    assert Staff(station.url).post(f"/sessions/{first[0].session_id}/sign-off").status_code == 303
    assert state(db_url, order_id)[0] == "signed_off"
    kiosk.close()
