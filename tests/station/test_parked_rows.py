"""One row a real station refuses never holds up a kiosk's outbox: the kiosk's real sync client
delivers every other row of real replayed sessions to a real `kiosk station` process (SQLite and
PostgreSQL), parks the refused ones with the station's reason, and `kiosk results` tells staff
how many are parked. The refused rows are the issue's: an option the item does not have, and on
PostgreSQL an ``at`` of 41-64 characters that once answered 500 forever."""

from __future__ import annotations

import json
import sqlite3

import pytest
import sqlalchemy as sa

from kiosk.commands.replay import load_script, run_script
from kiosk.commands.results import main as results_main
from kiosk.store.database import Store
from kiosk.sync import SyncClient
from station import db
from tests.station.conftest import make_ward
from tests.station.helpers import PATIENTS

pytestmark = pytest.mark.slow


def _hostile(store: Store, session_id: str) -> list[int]:
    """Two rows the station must refuse, queued among the session's own (as a buggy kiosk would)."""
    seqs = []
    for payload, at in (
        (
            {
                "item_id": "feeding",
                "option": 99,
                "points": 10,
                "attempt": 1,
                "channel": "touch",
                "answered_by": "patient",
                "t": 1.0,
                "at": "2026-01-01T00:00:01Z",
            },
            "2026-01-01T00:00:01Z",
        ),
        ({"t": 2.0, "kind": "note", "detail": ""}, "2026-01-01T00:00:02.000000000000000+00:00:00Z"),
    ):
        kind = "record_answer" if "item_id" in payload else "record_event"
        cursor = store._db.execute(  # a row no real session writes
            "INSERT INTO outbox (kind, session_id, payload, at) VALUES (?, ?, ?, ?)",
            (kind, session_id, json.dumps(payload), at),
        )
        seqs.append(cursor.lastrowid)
    return seqs


@pytest.mark.parametrize("engine", ["sqlite", "postgresql"])
def test_refused_rows_are_parked_and_every_other_row_is_delivered(
    engine, request, tmp_path, station_factory, monkeypatch, capsys
):
    db_url = request.getfixturevalue("sqlite_url" if engine == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk_dir = tmp_path / "kiosk"
    with Store.open(kiosk_dir, outbox=True) as store:
        first = run_script(load_script(PATIENTS / "barthel5.yaml"), store=store).session.id
        bad = _hostile(store, first)
        second = run_script(load_script(PATIENTS / "barthel6.yaml"), store=store).session.id
        queued = store.outbox_waiting()[0]
    assert len(bad) == 2 and queued > 50
    client = SyncClient(
        kiosk_dir / "kiosk.sqlite3", url=station.url, token=ward.token, kiosk_id=ward.kiosk_id, backoff=(0.02, 0.2)
    )
    try:
        assert client.deliver_all(within_s=120) == 0  # nothing waits behind the refused rows
    finally:
        client.stop()
    with sqlite3.connect(kiosk_dir / "kiosk.sqlite3") as kiosk:
        parked = dict(kiosk.execute("SELECT seq, parked FROM outbox WHERE parked IS NOT NULL").fetchall())
    assert sorted(parked) == bad
    assert "option" in parked[bad[0]] and parked[bad[0]].startswith(f"422: seq {bad[0]}: record_answer.option")
    assert parked[bad[1]].startswith(f"422: seq {bad[1]}: at")
    station_db = db.make_engine(db_url)
    with station_db.connect() as connection:
        stored = connection.execute(sa.select(sa.func.count()).select_from(db.inbox)).scalar()
        finished = connection.execute(sa.select(db.sessions.c.id).where(db.sessions.c.status == "finished")).scalars()
        assert set(finished) == {first, second}
    station_db.dispose()
    assert stored == queued - len(bad)
    # staff see how many the station refused
    (tmp_path / "config.yaml").write_text("site: hosp-north\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(tmp_path / "config.yaml"))
    assert results_main(["--data-dir", str(kiosk_dir)]) == 0
    assert "0 stored changes waiting for the ward station, 2 refused by it" in capsys.readouterr().err
