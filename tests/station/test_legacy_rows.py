"""Rows an older station stored before it checked them (an answer whose option the questionnaire
lacks, an item it does not have) stay in a database that is upgraded: every page that lists or
follows such a session still answers (the ward, the inbox, the patient's course, the session and
its sign-off step), showing what fits, never a 500. Real station process, SQLite and PostgreSQL."""

from __future__ import annotations

import json
import uuid

import pytest
import sqlalchemy as sa

from bench._postgres import create_database
from station import db
from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

pytestmark = pytest.mark.slow


def _spoil(db_url: str, session_id: str) -> None:
    """What an unchecking station kept: feeding answered with option 99, and an unknown item."""
    engine = db.make_engine(db_url)
    try:
        with engine.begin() as connection:
            rows = connection.execute(
                sa.select(db.inbox.c.kiosk_id, db.inbox.c.seq, db.inbox.c.payload).where(
                    db.inbox.c.session_id == session_id, db.inbox.c.kind == "record_answer"
                )
            ).all()
            for number, row in enumerate(rows[:2]):
                payload = json.loads(row.payload)
                payload |= {"option": 99} if number == 0 else {"item_id": "nonexistent"}
                where = (db.inbox.c.kiosk_id == row.kiosk_id) & (db.inbox.c.seq == row.seq)
                connection.execute(db.inbox.update().where(where).values(payload=json.dumps(payload)))
    finally:
        engine.dispose()


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_session_with_rows_stored_before_checks_is_shown_everywhere(database, request, station_factory, tmp_path):
    db_url = (
        db.sqlite_url(tmp_path / "data")
        if database == "sqlite"
        else create_database(request.getfixturevalue("postgres"), "l_" + uuid.uuid4().hex[:12])
    )
    ward = make_ward(db_url)
    station = station_factory(db_url)
    rows = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-0099001")
    client = KioskClient(station.url, ward.token, ward.kiosk_id)
    try:
        assert client.sync(rows).status_code == 200
    finally:
        client.close()
    session_id = rows[0].session_id
    _spoil(db_url, session_id)
    staff = Staff(station.url)
    try:
        for path in (
            "/",
            "/fragments/results",
            "/inbox",
            "/inbox?state=all",
            "/fragments/inbox",
            "/patients/NHC-0099001",
            f"/sessions/{session_id}",
            f"/sessions/{session_id}/sign-off",
            f"/sessions/{session_id}/export.json",
            f"/sessions/{session_id}/export.csv",
        ):
            shown = staff.http.get(path)
            assert shown.status_code == 200, (path, shown.status_code, shown.text[:500])
        # the answers that do not fit count as none: signed off as incomplete, with a reason
        signed = staff.post(f"/sessions/{session_id}/sign-off", incomplete_reason="rows from an older station")
        assert signed.status_code == 303 and "Signed%20off" in signed.headers["location"], signed.headers
        for path in (
            f"/sessions/{session_id}",
            "/inbox?state=signed",
            f"/sessions/{session_id}/export.json",
            "/exports/signed-off.json?from=2000-01-01&to=2100-12-31",
        ):
            shown = staff.http.get(path)
            assert shown.status_code == 200, (path, shown.status_code, shown.text[:500])
    finally:
        staff.http.close()
