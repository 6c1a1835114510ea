"""A battery reaching the real ward station: a `kiosk station` process (SQLite) on 127.0.0.1 and
a real `kiosk replay --data-dir` process configured with a battery (the Barthel, then a short
instrument) and the station's URL. The station holds one finished session per instrument, each
with its own definition, answers, total and FHIR Observation."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import sqlalchemy as sa

from kiosk.export.bundle import transaction_bundle
from kiosk.export.captured import questionnaire_of
from tests.kiosk.battery_instruments import write_mini
from tests.kiosk.sync.test_station_e2e import PATIENCE_S, ROOT, free_port, start_station

SCRIPT = ROOT / "tests/kiosk/commands/data/battery_visit.yaml"


@pytest.mark.slow  # two processes
def test_a_battery_reaches_the_station_as_one_result_per_instrument(tmp_path):
    from station import auth, db
    from station.sessions import load

    db_url = db.sqlite_url(tmp_path / "station")
    engine = db.open_database(db_url)
    token = auth.add_kiosk(engine, "ward3-bed2")
    port = free_port()
    write_mini(tmp_path)
    config = tmp_path / "config.yaml"
    config.write_text(
        "instruments: [barthel, mini.yaml]\n"
        f"station: {{url: 'http://127.0.0.1:{port}', token: '{token}', kiosk_id: ward3-bed2}}\n"
    )
    script = Path(shutil.copy(SCRIPT, tmp_path / "visit.yaml"))
    station = start_station(db_url, port, tmp_path / "station.log")
    try:
        replayed = subprocess.run(
            [sys.executable, "-m", "kiosk", "replay", str(script), "--data-dir", str(tmp_path / "data")]
            + ["--config", str(config)],
            capture_output=True,
            text=True,
            cwd=ROOT,
            timeout=300,
        )
        assert replayed.returncode == 0 and replayed.stderr == "", replayed.stderr
    finally:
        station.terminate()
        station.wait(timeout=PATIENCE_S)
    with engine.connect() as connection:
        ids = list(connection.execute(sa.select(db.sessions.c.id)).scalars())
        stored = [load(connection, i)[1] for i in ids]
    by_instrument = {s.questionnaire_id: s for s in stored}
    assert sorted(by_instrument) == ["barthel", "mini"] and len(stored) == 2
    assert {s.status for s in stored} == {"finished"} and {s.patient_id for s in stored} == {"P-0100"}
    totals = {}
    for instrument, session in by_instrument.items():
        q = questionnaire_of(session)  # the definition the kiosk ran, as the station received it
        assert q.id == instrument
        score = q.score({a.item_id: a.points for a in session.answers})
        totals[instrument] = (score.total, score.complete)
        bundle = transaction_bundle(q, [session])
        observations = [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "Observation"]
        assert [o["valueQuantity"]["value"] for o in observations] == [score.total]  # its own total
    assert totals == {"barthel": (100, True), "mini": (5, True)}
