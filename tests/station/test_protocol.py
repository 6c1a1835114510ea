"""The kiosk protocol (docs/station-protocol.md) against a real `kiosk station` process over HTTP,
with outbox rows recorded from a real session running a scripted patient."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from dataclasses import replace

import httpx
import pytest
import sqlalchemy as sa

from station import db, throttle
from station.sessions import load
from tests.station.conftest import ROOT, new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_login_throttle import most_checked

pytestmark = pytest.mark.slow


@pytest.fixture
def ward_station(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    client = KioskClient(station.url, token, name)
    yield replace(ward, token=token, kiosk_id=name), station, client
    client.close()


def _stored(db_url: str, session_id: str):
    engine = db.make_engine(db_url)
    try:
        with engine.connect() as connection:
            return load(connection, session_id)[1]
    finally:
        engine.dispose()


def test_a_replayed_session_arrives_whole_and_a_retry_stores_nothing_twice(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "barthel5.yaml")
    first = client.sync(rows[:40])
    assert first.status_code == 200 and first.json()["stored"] == [r.seq for r in rows[:40]]
    # the response was lost: the kiosk sends the same rows again, with the rest
    again = client.sync(rows)
    assert again.json()["stored"] == [r.seq for r in rows]
    engine = db.make_engine(ward.db_url)
    with engine.connect() as connection:
        count = connection.execute(
            sa.select(sa.func.count()).select_from(db.inbox).where(db.inbox.c.kiosk_id == ward.kiosk_id)
        ).scalar_one()
    engine.dispose()
    assert count == len(rows)
    stored = _stored(ward.db_url, rows[0].session_id)
    answers = {r.payload["item_id"]: r.payload["option"] for r in rows if r.kind == "record_answer"}
    assert {a.item_id: a.option for a in stored.answers} == answers
    assert stored.status == "finished" and stored.patient_id == "TB-0005"
    assert len(stored.metrics) == sum(r.kind == "record_metrics" for r in rows)


def test_an_alert_sent_first_is_raised_at_once_and_the_session_reads_in_order_when_the_rest_arrives(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "barthel5.yaml")
    call = next(r for r in rows if r.alert and r.payload["kind"] == "doctor_called")
    assert client.sync([call]).json()["stored"] == [call.seq]
    staff = Staff(station.url)
    page = staff.http.get("/").text
    assert "Doctor called" in page and ward.kiosk_id in page
    client.sync([r for r in rows if r.seq != call.seq])
    stored = _stored(ward.db_url, call.session_id)
    kinds = [e.kind for e in stored.log]
    assert kinds.index(call.payload["kind"]) > kinds.index("start")  # the late rows took their place before it
    assert stored.status == "finished"


def test_rows_that_would_store_a_wrong_answer_are_refused_and_named(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "barthel1.yaml")
    assert client.sync(rows[:5]).status_code == 200
    changed = rows[4]
    tampered = type(changed)(
        changed.seq, changed.kind, changed.session_id, changed.payload | {"t": 9999.0}, changed.t, changed.at
    )
    refused = client.sync([tampered])
    assert refused.status_code == 409 and f"seq {changed.seq}" in refused.json()["error"]
    named = record_patient(PATIENTS / "barthel1.yaml", first_seq=100)
    named[0].payload["patient_id"] = "Ann Smith"
    response = client.sync(named[:1])
    assert response.status_code == 422 and "pseudonymous" in response.json()["error"]
    # another kiosk may not add rows to this kiosk's session
    other_name, other_token = new_kiosk(ward.db_url)
    other = KioskClient(station.url, other_token, other_name)
    foreign = record_patient(PATIENTS / "barthel1.yaml", first_seq=1)[5:6]
    foreign[0].session_id = rows[0].session_id
    response = other.sync(foreign)
    assert response.status_code == 409 and f"belongs to kiosk {ward.kiosk_id}" in response.json()["error"]
    other.close()


def test_an_unknown_or_revoked_token_gets_401_and_nothing_is_stored(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "barthel1.yaml")
    stranger = KioskClient(station.url, "not-a-token", ward.kiosk_id)
    assert stranger.sync(rows[:3]).status_code == 401
    stranger.close()
    done = subprocess.run(
        [sys.executable, "-m", "kiosk", "station", "revoke-kiosk", ward.kiosk_id, "--db", ward.db_url],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert client.sync(rows[:3]).status_code == 401
    assert client.status().status_code == 401
    engine = db.make_engine(ward.db_url)
    with engine.connect() as connection:
        assert (
            connection.execute(
                sa.select(sa.func.count()).select_from(db.inbox).where(db.inbox.c.kiosk_id == ward.kiosk_id)
            ).scalar_one()
            == 0
        )
    engine.dispose()


def test_a_command_queued_by_staff_answers_a_waiting_long_poll_and_is_redelivered_until_acked(ward_station):
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "barthel5.yaml")
    client.sync(rows[:3])
    session_id = rows[0].session_id
    client.status(session_id=session_id, patient_id="TB-0005", phase="questions", question=4, of=10, doctor_called=True)
    got: list = []
    poll = threading.Thread(target=lambda: got.extend(client.commands(wait=25)))
    poll.start()
    staff = Staff(station.url, "nurse.kim", "nurse")
    response = staff.post(f"/kiosks/{ward.kiosk_id}/command", session_id=session_id, kind="continue")
    assert response.status_code == 303
    poll.join(timeout=60)
    assert [(c["kind"], c["session_id"], c["by"]) for c in got] == [("continue", session_id, "nurse.kim")]
    # not acknowledged: delivered again, at once
    assert [c["id"] for c in client.commands(wait=0)] == [got[0]["id"]]
    assert client.ack(got[0]["id"], "done").status_code == 200
    assert client.commands(wait=0) == []
    page = staff.http.get(f"/sessions/{session_id}").text
    assert "Continue session by nurse.kim: done" in page  # the button's words, not the protocol's


def test_status_reports_show_on_the_ward_page(ward_station):
    ward, station, client = ward_station
    assert (
        client.status(
            session_id="abc123", patient_id="P-7K3QX9", phase="questions", question=3, of=10, paused=True
        ).status_code
        == 200
    )
    page = Staff(station.url).http.get("/").text
    assert "P-7K3QX9" in page and "3 of 10" in page and "paused" in page and "online" in page
    bad = client.http.post("/api/v1/status", content=json.dumps({"question": "three"}))
    assert bad.status_code == 400 and "question" in bad.json()["error"]


def test_page_posts_need_the_csrf_token_and_logins_are_rate_limited(ward_station):
    ward, station, client = ward_station
    staff = Staff(station.url)
    forged = staff.http.post(f"/kiosks/{ward.kiosk_id}/command", data={"session_id": "x", "kind": "end"})
    assert forged.status_code == 403
    import httpx

    anonymous = httpx.Client(base_url=station.url)
    token = Staff.csrf(anonymous.get("/login").text)
    from station import auth

    engine = db.make_engine(ward.db_url)
    auth.add_user(engine, "dr.target", "doctor", "the-right-password")
    engine.dispose()
    started = time.monotonic()
    statuses = [
        anonymous.post("/login", data={"csrf": token, "name": "dr.target", "password": f"wrong{i}"}).status_code
        for i in range(8)
    ]
    # the pause grows from the 4th failure (station.throttle; tests/station/test_login_throttle.py)
    assert statuses[: throttle.FREE_FAILURES] == [401] * throttle.FREE_FAILURES and 429 in statuses
    assert statuses.count(401) <= most_checked(time.monotonic() - started)
    assert anonymous.get("/", follow_redirects=False).status_code == 303


def test_a_kiosk_silent_for_more_than_30_s_shows_offline_with_when_it_was_last_seen(ward_station):
    ward, station, client = ward_station
    client.status(session_id="abc124", patient_id="P-7K3QX8", phase="questions", question=5, of=10)
    engine = db.make_engine(ward.db_url)
    with engine.begin() as connection:  # as if its last heartbeat came two minutes ago
        connection.execute(db.kiosks.update().where(db.kiosks.c.name == ward.kiosk_id).values(last_seen=db.now() - 120))
    engine.dispose()
    page = Staff(station.url).http.get("/").text
    tile = page[page.index(f'id="kiosk-{ward.kiosk_id}"') :]
    tile = tile[: tile.index("</article>")]
    assert "offline" in tile and "last seen" in tile and "12" in tile  # "120 s ago" (or a little more)


@pytest.mark.parametrize(
    "body,status,words",
    [
        (b"[" * 100_000 + b"]" * 100_000, 400, "nested more than"),
        (b'{"kiosk_id": "a", "kiosk_id": "b", "events": []}', 400, "duplicate key"),
        (b'{"events": [{"seq": NaN}]}', 400, "not a finite number"),
        (b'{"events": [{"seq": 1' + b"0" * 5000 + b"}]}", 400, "too large"),
        (b'{"events": "\xff\xfe"}', 400, "not UTF-8"),
        (b'{"events": [' + b'"x",' * 1_500_000 + b'"x"]}', 413, "larger than"),
    ],
)
def test_a_bad_body_gets_one_clear_message_and_nothing_is_stored(ward_station, body, status, words):
    """Bytes from a broken or hostile kiosk: deep nesting (which crashed json.loads with a
    RecursionError, a 500), duplicate keys, NaN, a 5000-digit number, bad UTF-8, a body over the
    limit. Each is refused with one sentence, and the station goes on taking good reports."""
    ward, station, client = ward_station
    for path in ("/api/v1/sync", "/api/v1/status"):
        response = client.http.post(path, content=body)
        assert response.status_code == status, (path, response.text[:200])
        assert words in response.json()["error"]
    assert (
        client.status(session_id="abc123", patient_id="P-7K3QX9", phase="questions", question=3, of=10).status_code
        == 200
    )
    # without a kiosk key the body is not even read
    anonymous = httpx.post(f"{station.url}/api/v1/sync", content=body, timeout=30)
    assert anonymous.status_code == 401 and "token" in anonymous.json()["error"]


def test_the_stations_export_names_the_result_as_its_kiosk_does(ward_station, tmp_path):
    """A hospital importing from both the kiosk and the station gets one result: the station's FHIR
    export carries the identifiers of the kiosk's own (site, kiosk id and FHIR systems from the
    kiosk's config, sent with the session), not the station's defaults."""
    from kiosk.core.questionnaire import load_questionnaire
    from kiosk.export import ExportSite, export_identity, fhir_response

    ward, station, client = ward_station
    site = ExportSite(
        site="H1",
        kiosk_id="ward3-bed2",
        patient_system="https://h1.example/pseudonyms",
        identifier_system="https://h1.example/barthel-results",
        questionnaire_url="https://h1.example/Questionnaire/barthel",
        device_system="https://h1.example/devices",
    )
    rows = record_patient(PATIENTS / "barthel5.yaml", export=export_identity(site))
    assert rows[0].kind == "create_session" and rows[0].payload["export"]["site"] == "H1"
    client.sync(rows)
    session_id = rows[0].session_id
    bundle = Staff(station.url).http.get(f"/sessions/{session_id}/export.json").json()
    exported = next(e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse")
    stored = _stored(ward.db_url, session_id)
    own = fhir_response(load_questionnaire(), stored, None, site)  # what the kiosk itself exports
    for key in ("identifier", "questionnaire", "subject"):
        assert exported[key] == own[key], key
    assert exported["identifier"] == {
        "system": "https://h1.example/barthel-results",
        "value": f"H1/ward3-bed2/{session_id}",
    }


def test_an_incomplete_session_shows_no_total(ward_station):
    """Barthel #5 leaves bathing unanswered: the page says there is no total yet and why, never a
    partial sum as if it were the result (its exports leave the total out too)."""
    ward, station, client = ward_station
    rows = record_patient(PATIENTS / "barthel5.yaml")
    client.sync(rows)
    session_id = rows[0].session_id
    staff = Staff(station.url)
    page = staff.http.get(f"/sessions/{session_id}").text
    assert '<b id="total">No total</b>: 1 of 10 questions not answered' in page
    bundle = staff.http.get(f"/sessions/{session_id}/export.json").json()
    exported = next(e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse")
    assert all(i["linkId"] != "total" for i in exported["item"]) and exported["status"] != "completed"
    assert all(e["resource"]["resourceType"] != "Observation" for e in bundle["entry"])
    complete = record_patient(PATIENTS / "barthel1.yaml", first_seq=rows[-1].seq + 1)
    client.sync(complete)
    page = staff.http.get(f"/sessions/{complete[0].session_id}").text
    assert "No total" not in page and " of 100" in page
