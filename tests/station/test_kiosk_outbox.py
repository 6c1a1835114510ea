"""The kiosk's real outbox (``kiosk.store.database.Store`` with a station configured) delivered to a real
station: what the station reads back is what the kiosk stored, row for row. The rows come from
the kiosk's own SQLite after real sessions ran scripted patients; they are sent the way the
protocol says (alerts first, then the rest oldest first, in batches), by this test until the
kiosk's sync client is on main."""

from __future__ import annotations

import json
import sqlite3

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.store.database import ALERT_EVENTS, Store
from station import db
from station.sessions import load
from tests.station.helpers import PATIENTS, KioskClient, Row

pytestmark = pytest.mark.slow


def outbox_rows(path) -> list[Row]:
    with sqlite3.connect(path) as connection:
        return [
            Row(seq, kind, session_id, json.loads(payload), 0.0, at)
            for seq, kind, session_id, payload, at, alert in connection.execute(
                "SELECT seq, kind, session_id, payload, at, alert FROM outbox ORDER BY seq"
            )
        ]


def test_the_station_reads_back_what_the_kiosk_stored(shared_station, tmp_path):
    from tests.station.conftest import new_kiosk

    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    kiosk_dir = tmp_path / "kiosk"
    with Store.open(kiosk_dir, outbox=True) as store:
        ids = [
            run_script(load_script(PATIENTS / script), store=store).session.id
            for script in ("barthel5.yaml", "barthel6.yaml", "relative_french.yaml")
        ]
        kiosk_copies = {session_id: store.session(session_id) for session_id in ids}
    rows = outbox_rows(store.path)
    assert rows and {r.session_id for r in rows} == set(ids)
    client = KioskClient(station.url, token, name)
    alerts = [r for r in rows if r.alert]
    assert alerts, "the scripted patients call the doctor and leave the kiosk"
    for alert in alerts:  # alerts first, each in a request of its own
        assert client.sync([alert]).status_code == 200
    rest = [r for r in rows if not r.alert]
    for start in range(0, len(rest), 100):
        response = client.sync(rest[start : start + 100])
        assert response.status_code == 200, response.text
    client.close()

    engine = db.make_engine(ward.db_url)
    renamed = {old: new for old, new in ALERT_EVENTS.items()}
    with engine.connect() as connection:
        for session_id, kiosk_copy in kiosk_copies.items():
            kiosk, station_copy = load(connection, session_id)
            assert kiosk == name
            assert station_copy.patient_id == kiosk_copy.patient_id
            assert station_copy.status == kiosk_copy.status == "finished"
            assert sorted(station_copy.answers, key=lambda a: a.item_id) == sorted(
                kiosk_copy.answers, key=lambda a: a.item_id
            )
            assert station_copy.not_answered == kiosk_copy.not_answered
            assert station_copy.trace == kiosk_copy.trace
            assert [(m.t, dict(m.metrics)) for m in station_copy.metrics] == [
                (m.t, dict(m.metrics)) for m in kiosk_copy.metrics
            ]
            assert station_copy.practice == kiosk_copy.practice
            assert [(e.t, e.kind) for e in station_copy.log] == [
                (e.t, renamed.get(e.kind, e.kind)) for e in kiosk_copy.log
            ]
    engine.dispose()
