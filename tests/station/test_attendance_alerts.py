"""Alerts about a patient who is not there, against a real `kiosk station` process over HTTP, with
outbox rows recorded from real sessions running scripted patients (issues 34 and 36): leaving
alerts the ward only once away as long as the kiosk's site says, no answer to two questions in a
row alerts it in words, and each closes by itself when its situation ends."""

from __future__ import annotations

from dataclasses import replace

import pytest
import sqlalchemy as sa

from station import db
from tests.station.conftest import new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

pytestmark = pytest.mark.slow


@pytest.fixture
def ward_station(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    client = KioskClient(station.url, token, name)
    yield replace(ward, token=token, kiosk_id=name), station, client
    client.close()


def alert_rows(db_url: str, kiosk: str) -> list[tuple]:
    engine = db.make_engine(db_url)
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(db.alerts.c.kind, db.alerts.c.resolved_at.is_not(None), db.alerts.c.ack_by)
            .where(db.alerts.c.kiosk_id == kiosk)
            .order_by(db.alerts.c.id)
        ).all()
    engine.dispose()
    return [tuple(r) for r in rows]


def test_leaving_alerts_only_after_the_sites_time_and_closes_when_back(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "camera_away.yaml")
    kinds = [r.payload.get("kind") for r in rows if r.alert]
    assert kinds == ["person_lost", "away_alert", "person_back", "person_lost", "person_back"]
    lost = next(r for r in rows if r.alert and r.payload["kind"] == "person_lost")
    assert client.sync([lost]).status_code == 200
    assert alert_rows(ward.db_url, ward.kiosk_id) == []  # left: nobody is alerted yet
    away = next(r for r in rows if r.alert and r.payload["kind"] == "away_alert")
    assert client.sync([away]).status_code == 200
    page = Staff(station.url).http.get("/").text
    assert "Patient away from the kiosk for 1 min" in page and ward.kiosk_id in page
    assert client.sync(rows).status_code == 200
    # back: closed by itself; the 20 s absence staff marked raised nothing
    assert alert_rows(ward.db_url, ward.kiosk_id) == [("person_lost", True, "closed: situation ended")]


def test_no_answer_to_two_questions_in_a_row_alerts_in_words_and_a_touch_ends_it(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "walked_away.yaml")
    unattended = next(r for r in rows if r.alert and r.payload["kind"] == "unattended")
    assert unattended.payload["detail"] == "2"
    assert client.sync([unattended]).status_code == 200
    page = Staff(station.url).http.get("/").text
    assert "No answer to two questions in a row; the kiosk waits for a touch" in page
    assert client.sync(rows).status_code == 200
    assert alert_rows(ward.db_url, ward.kiosk_id) == [("unattended", True, "closed: situation ended")]
