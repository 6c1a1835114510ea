"""End to end with the real ward station: a `kiosk station` process (SQLite) on 127.0.0.1 and real
`kiosk replay --data-dir` processes configured with its URL and a token it issued. A replay
delivers its outbox before it exits; with the station unreachable it says so, keeps the rows, and
a later run delivers them -- each row stored once."""

from __future__ import annotations

import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
import sqlalchemy as sa

from kiosk.store.database import Store

ROOT = Path(__file__).resolve().parents[3]
PATIENCE_S = 60.0


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def start_station(db_url: str, port: int, log: Path) -> subprocess.Popen:
    with open(log, "ab") as out:
        process = subprocess.Popen(
            [sys.executable, "-m", "kiosk", "station", "--db", db_url, "--port", str(port)],
            stdout=out,
            stderr=subprocess.STDOUT,
            cwd=ROOT,
        )
    deadline = time.monotonic() + PATIENCE_S
    while True:  # readiness, bounded by PATIENCE_S; nothing is timed
        assert process.poll() is None, log.read_text()
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/healthz", timeout=2) as answer:
                if answer.status == 200:
                    return process
        except OSError:
            pass
        assert time.monotonic() < deadline, f"the station did not start:\n{log.read_text()}"
        time.sleep(0.1)


def replay(script: str, data: Path, config: Path, *options: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "kiosk",
            "replay",
            str(ROOT / "recordings/patients" / script),
            "--data-dir",
            str(data),
            "--config",
            str(config),
            *options,
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )


@pytest.mark.slow
def test_replays_reach_the_real_station_even_after_it_was_down(tmp_path):
    from station import auth, db

    db_url = db.sqlite_url(tmp_path / "station")
    engine = db.open_database(db_url)
    token = auth.add_kiosk(engine, "ward3-bed2")
    port = free_port()
    data = tmp_path / "data"
    config = tmp_path / "config.yaml"
    config.write_text(f"station: {{url: 'http://127.0.0.1:{port}', token: '{token}', kiosk_id: ward3-bed2}}\n")

    down = replay("barthel1.yaml", data, config, "--station-wait", "2")  # no station listening yet
    assert down.returncode == 0, down.stderr
    (message,) = down.stderr.strip().splitlines()
    assert message.startswith(f"kiosk replay: the station at http://127.0.0.1:{port} did not take ")
    assert "within 2 s" in message
    assert "kept in" in message and "connection refused" in message
    with Store.open(data) as store:
        kept = store._db.execute("SELECT COUNT(*) FROM outbox").fetchone()[0]
    assert kept > 0

    station = start_station(db_url, port, tmp_path / "station.log")
    try:
        up = replay("barthel2.yaml", data, config)
        assert up.returncode == 0 and up.stderr == "", up.stderr
    finally:
        station.terminate()
        station.wait(timeout=PATIENCE_S)
    with Store.open(data) as store:
        assert store._db.execute("SELECT COUNT(*) FROM outbox").fetchone() == (0,)
        sessions = {s.id: s for s in store.sessions()}
    with engine.connect() as connection:
        seqs = [r.seq for r in connection.execute(sa.select(db.inbox.c.seq).where(db.inbox.c.kiosk_id == "ward3-bed2"))]
        at_station = set(connection.execute(sa.select(db.sessions.c.id)).scalars())
        statuses = dict(connection.execute(sa.select(db.sessions.c.id, db.sessions.c.status)).all())
    assert len(seqs) == len(set(seqs)) and len(seqs) > kept  # both replays' rows, each once
    assert at_station == set(sessions)
    assert all(statuses[s] == "finished" for s in sessions)


@pytest.mark.slow
async def test_a_doctor_call_reaches_the_real_station_and_its_continue_reaches_the_kiosk(tmp_path):
    """The kiosk as `kiosk run` builds it, reporting to a `kiosk station` process: the patient's
    doctor call becomes the station's alert; staff's continue (queued in the station's database)
    is long-polled, applied to the running session and acknowledged."""
    from kiosk.commands.run import build_app
    from kiosk.ui.app import KIOSK_SIZE
    from station import auth, db, ward
    from tests.kiosk.ui.helpers import until_thread

    db_url = db.sqlite_url(tmp_path / "station")
    engine = db.open_database(db_url)
    token = auth.add_kiosk(engine, "ward3-bed2")
    port = free_port()
    config = tmp_path / "config.yaml"
    config.write_text(
        f"data_dir: {tmp_path / 'data'}\nfamiliarisation: false\ntiming: {{between_questions_s: 0.1}}\n"
        f"station: {{url: 'http://127.0.0.1:{port}', token: '{token}', kiosk_id: ward3-bed2}}\n"
    )
    station = start_station(db_url, port, tmp_path / "station.log")
    app, close = build_app(config_path=config, voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await pilot.press("1", "1")
            await until_thread(lambda: app.session.current_attempt == 1, "the first question", PATIENCE_S)
            session = app.session
            await pilot.press("d")
            await until_thread(
                lambda: any(a.session_id == session.id for a in ward.open_alerts(engine, "ward3-bed2")),
                "the doctor call at the station",
                PATIENCE_S,
            )
            command = ward.queue_command(engine, "ward3-bed2", session.id, "continue", "dr.lopez")
            await until_thread(lambda: not session.halted, "the kiosk continuing", PATIENCE_S)
            await until_thread(
                lambda: ward.recent_commands(engine, session.id)[0].get("result") == "done",
                f"the ack of command {command}",
                PATIENCE_S,
            )
    finally:
        close()
        station.terminate()
        station.wait(timeout=PATIENCE_S)
