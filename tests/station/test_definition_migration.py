"""A station database from before definitions were captured upgrades (Alembic, SQLite and
PostgreSQL): its sessions get the bundled definition, marked attached later, and a real station
process then shows and exports them; a kiosk that still sends no definition gets the same."""

from __future__ import annotations

import json

import pytest
import sqlalchemy as sa
from alembic import command
from alembic.config import Config

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.questionnaire.definition import canonical, digest
from station import auth, db
from tests.station.conftest import PASSWORDS
from tests.station.helpers import PATIENTS, KioskClient, Row, Staff, record_patient, response_in


def rows_answer(rows: list, **changes) -> dict:
    """The session's feeding answer with some fields changed (replacing it, as a later row does)."""
    answer = next(r.payload for r in rows if r.kind == "record_answer" and r.payload["item_id"] == "feeding")
    return answer | changes


pytestmark = pytest.mark.slow


def _at_0001(url: str) -> sa.Engine:
    engine = db.make_engine(url)
    config = Config()
    config.set_main_option("script_location", str(db.MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "0001")
    return engine


@pytest.mark.parametrize("engine_name", ["sqlite", "postgresql"])
def test_old_sessions_get_the_bundled_definition_marked_attached_later(engine_name, request, station_factory):
    url = request.getfixturevalue("sqlite_url" if engine_name == "sqlite" else "pg_url")
    engine = _at_0001(url)
    rows = record_patient(PATIENTS / "barthel4.yaml")
    session_id = rows[0].session_id
    # and odd rows a station stored before it checked them: option 99, an unknown item, a time as text
    rows = rows + [
        Row(900 + n, kind, session_id, payload, 0.0, "2026-01-01T00:20:00Z")
        for n, (kind, payload) in enumerate(
            [
                ("record_answer", rows_answer(rows, option=99, points=99)),
                ("record_answer", rows_answer(rows, item_id="swimming")),
                ("record_event", {"t": "soon", "kind": "note", "detail": "odd"}),
            ]
        )
    ]
    with engine.begin() as connection:  # what a station before 0003 stored: no definition anywhere
        connection.execute(
            sa.text(
                "INSERT INTO sessions (id, kiosk_id, patient_id, started_at, status, updated_at)"
                " VALUES (:id, 'old-kiosk', :patient, :started, 'finished', 0)"
            ),
            {"id": session_id, "patient": rows[0].payload["patient_id"], "started": rows[0].payload["started_at"]},
        )
        for row in rows:
            payload = {k: v for k, v in row.payload.items() if not k.startswith("definition")}
            connection.execute(
                sa.text("INSERT INTO inbox VALUES ('old-kiosk', :seq, :kind, :session, :payload, :at, 0)"),
                {"seq": row.seq, "kind": row.kind, "session": session_id, "payload": json.dumps(payload), "at": row.at},
            )
    engine.dispose()
    engine = db.open_database(url)  # upgrades to head
    bundled = canonical(load_questionnaire())
    with engine.connect() as connection:
        found = connection.execute(
            sa.select(db.sessions.c.definition_sha256, db.sessions.c.definition_attached_later)
        ).one()
        bodies = connection.execute(sa.select(db.definitions.c.sha256, db.definitions.c.body)).all()
    assert tuple(found) == (digest(bundled), True)
    assert [(sha, json.loads(body)) for sha, body in bodies] == [(digest(bundled), bundled)]
    auth.add_user(engine, "dr.lopez", "doctor", PASSWORDS["doctor"])
    token = auth.add_kiosk(engine, "old-style")
    engine.dispose()
    station = station_factory(url)
    staff = Staff(station.url)
    page = staff.http.get(f"/sessions/{session_id}")
    assert page.status_code == 200 and "attached later" in page.text
    assert "Left out" in page.text and "feeding option 99" in page.text and "swimming" in page.text
    exported = staff.http.get(f"/sessions/{session_id}/export.json")
    assert exported.status_code == 200
    answered = {i["linkId"] for i in response_in(exported.json())["item"] if i.get("answer")}
    assert "swimming" not in answered and "feeding" not in answered and "bathing" in answered
    # what did not fit can still be corrected and signed off
    assert staff.post(f"/sessions/{session_id}/items/feeding", option="2", reason="asked again").status_code == 303
    assert staff.post(f"/sessions/{session_id}/sign-off").status_code == 303
    assert staff.http.get(f"/sessions/{session_id}/export.csv").status_code == 200
    # a kiosk that sends no definition yet: the bundled one, attached later, checked against it
    newer = record_patient(PATIENTS / "barthel5.yaml")
    for row in newer:
        row.payload = {k: v for k, v in row.payload.items() if not k.startswith("definition")}
    client = KioskClient(station.url, token, "old-style")
    assert client.sync(newer).status_code == 200
    client.close()
    page = staff.http.get(f"/sessions/{newer[0].session_id}")
    assert page.status_code == 200 and "attached later" in page.text
    staff.http.close()
