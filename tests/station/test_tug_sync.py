"""A Timed Up and Go stored at a real kiosk reaches a real station (issue 34, part 5): the kiosk's
store queues a ``record_tug`` outbox row with the result, the station keeps it (SQLite and
PostgreSQL) with the staff decision and who made it, a resend stores nothing twice, and a bad row
is one 422 naming the field, with nothing of its batch stored."""

from __future__ import annotations

import copy

import pytest
import sqlalchemy as sa

from station import db, tugs
from tests.station._tug import camera_result, stopwatch_result, tug_rows
from tests.station.conftest import make_ward, new_kiosk
from tests.station.helpers import KioskClient

pytestmark = pytest.mark.slow


def stored(db_url: str) -> list[tugs.StationTug]:
    engine = db.make_engine(db_url)
    try:
        with engine.connect() as connection:
            ids = connection.execute(sa.select(db.tug_results.c.patient_id).distinct()).scalars().all()
            return [t for p in sorted(ids) for t in tugs.of_patient(connection, p)]
    finally:
        engine.dispose()


def round_trip(url: str, db_url: str, token: str, kiosk: str, tmp_path) -> None:
    camera, watch = camera_result(), stopwatch_result(15.5)
    rows = tug_rows(
        tmp_path / "kiosk",
        [("P-0042", camera, "2026-11-28T05:00:00Z"), ("P-0042", watch, "2026-11-28T05:10:00Z")],
        visit_id="visit-1",
    )
    assert [r.kind for r in rows] == ["record_tug", "record_tug"]
    assert all("landmarks" not in r.payload for r in rows)  # never pictures, never landmarks
    client = KioskClient(url, token, kiosk)
    try:
        first = client.sync(rows)
        assert first.status_code == 200, first.text
        assert first.json() == {"stored": [r.seq for r in rows]}
        again = client.sync(rows)  # a resend (the kiosk lost the answer): acknowledged, stored once
        assert again.status_code == 200 and again.json() == first.json()
    finally:
        client.close()
    found = stored(db_url)
    assert [t.id for t in found] == [r.session_id for r in rows]
    cam, sw = found
    assert (cam.kiosk_id, cam.patient_id, cam.visit_kind, cam.visit_id) == (kiosk, "P-0042", "staff", "visit-1")
    assert (cam.decision, cam.decided_by, cam.confirmed_by, cam.method) == ("accepted", "dr-lee", "nurse-7", "camera")
    assert cam.total_s == pytest.approx(camera.total_s) and cam.phases == camera.phases
    assert (cam.get_up_go, cam.walking_aid, cam.threshold_s) == (3, "stick", 13.5)
    assert cam.person_share == pytest.approx(camera.person_share) and cam.turn_seen == camera.turn_seen
    assert cam.export["site"] == "hosp-north"
    assert (sw.decision, sw.decided_by, sw.method, sw.total_s, sw.body_cut_off) == (
        "stopwatch",
        "nurse-7",
        "stopwatch",
        15.5,
        True,
    )
    assert sw.wording == "15.5 s, above the site's threshold (13.5 s)."


def test_a_stored_tug_reaches_the_station_once(shared_station, tmp_path):
    station, ward = shared_station
    kiosk, token = new_kiosk(ward.db_url)
    round_trip(station.url, ward.db_url, token, kiosk, tmp_path)


def test_a_stored_tug_reaches_a_postgresql_station_once(pg_url, station_factory, tmp_path):
    ward = make_ward(pg_url)
    station = station_factory(ward.db_url)
    round_trip(station.url, ward.db_url, ward.token, ward.kiosk_id, tmp_path)


BAD = [
    ("decision", "maybe", "record_tug.decision: must be one of accepted, stopwatch, rejected"),
    ("total_s", "fast", "record_tug.total_s: must be a number"),
    ("total_s", 0, "record_tug.total_s: must be more than 0"),
    ("method", "stopwatch", "record_tug.method: a decision 'accepted' is timed by 'camera'"),
    ("visit", "walk-up", "record_tug.visit: the Timed Up and Go is never given at a walk-up visit"),
    ("get_up_go", 9, "record_tug.get_up_go: must be a whole number from 1 to 5"),
    ("walking_aid", "skateboard", "record_tug.walking_aid: must be one of none, stick"),
    ("phases", [{"name": "dance", "start_t": 1, "end_t": 2}], "record_tug.phases[0].name: must be one of"),
    ("person_share", 2, "record_tug.person_share: must be a number from 0 to 1"),
    ("patient_id", "Maria Lopez", "record_tug.patient_id: is not pseudonymous"),
    ("decided_by", "", "record_tug.decided_by: must not be empty"),
    ("tug_id", "another", "record_tug.tug_id: 'another' in a row of"),
    ("at", "yesterday", "record_tug.at: must be an ISO 8601 date and time"),
    ("body_cut_off", "no", "record_tug.body_cut_off: must be true or false"),
    ("decided_by", None, "record_tug.decided_by: must be text"),
]


@pytest.mark.parametrize(("field", "value", "message"), BAD, ids=[f"{b[0]}={b[1]!r:.12}" for b in BAD])
def test_a_bad_tug_row_is_one_422_naming_the_field(shared_station, tmp_path, field, value, message):
    station, ward = shared_station
    kiosk, token = new_kiosk(ward.db_url)
    (good,) = tug_rows(tmp_path / "kiosk", [("P-0077", camera_result(), "2026-11-28T05:00:00Z")])
    bad = copy.deepcopy(good)
    bad.payload[field] = value
    client = KioskClient(station.url, token, kiosk)
    try:
        response = client.sync([bad])
        assert response.status_code == 422, response.text
        assert response.json()["seq"] == bad.seq
        assert response.json()["error"].startswith(f"seq {bad.seq}: "), response.text
        assert message in response.json()["error"], response.text
        assert not [t for t in stored(ward.db_url) if t.kiosk_id == kiosk]  # nothing half-stored
        assert client.sync([good]).status_code == 200  # the kiosk parks the bad row; the good one goes
    finally:
        client.close()


def test_a_tug_row_without_its_fields_is_refused(shared_station, tmp_path):
    station, ward = shared_station
    kiosk, token = new_kiosk(ward.db_url)
    (good,) = tug_rows(tmp_path / "kiosk", [("P-0078", camera_result(), "2026-11-28T05:00:00Z")])
    del good.payload["decided_by"]
    client = KioskClient(station.url, token, kiosk)
    try:
        response = client.sync([good])
    finally:
        client.close()
    assert response.status_code == 422 and "record_tug without decided_by" in response.json()["error"]


def test_the_kiosks_own_client_delivers_tugs_and_parks_a_bad_one(shared_station, tmp_path):
    """The kiosk's real sync client (kiosk.sync.client) over its real outbox: a questionnaire
    visit and its TUGs arrive; a row a kiosk could only have sent wrongly (a rating of 9, which its
    own table refuses: written into the outbox here) is parked with the station's reason, and
    nothing waits behind it."""
    import sqlite3

    from kiosk.commands.replay import load_script, run_script
    from kiosk.store.database import DB_NAME, Store
    from kiosk.sync.client import SyncClient
    from tests.station.helpers import PATIENTS

    station, ward = shared_station
    kiosk, token = new_kiosk(ward.db_url)
    data = tmp_path / "kiosk"
    with Store.open(data, outbox=True) as store:
        session = run_script(load_script(PATIENTS / "barthel5.yaml"), store=store).session.id
        good = store.tug.record("P-0090", camera_result(), visit="staff", visit_id="v-90")
        bad = store.tug.record("P-0090", stopwatch_result(), visit="staff")
    with sqlite3.connect(data / DB_NAME) as kiosk_db:
        kiosk_db.execute("UPDATE outbox SET payload = json_set(payload, '$.get_up_go', 9) WHERE session_id = ?", (bad,))
    client = SyncClient(data / DB_NAME, url=station.url, token=token, kiosk_id=kiosk, backoff=(0.02, 0.2))
    try:
        assert client.deliver_all(within_s=120) == 0
        parked = client.outbox.parked()
    finally:
        client.stop()
    assert len(parked) == 1 and "record_tug.get_up_go: must be a whole number from 1 to 5" in parked[0][1]
    found = [t for t in stored(ward.db_url) if t.kiosk_id == kiosk]
    assert [t.id for t in found] == [good] and bad not in {t.id for t in found}
    engine = db.make_engine(ward.db_url)
    try:
        with engine.connect() as connection:
            status = connection.execute(sa.select(db.sessions.c.status).where(db.sessions.c.id == session)).scalar()
            assert status == "finished"
            # the TUG's id is no session at the station
            assert connection.execute(sa.select(db.sessions.c.id).where(db.sessions.c.id == good)).first() is None
    finally:
        engine.dispose()
