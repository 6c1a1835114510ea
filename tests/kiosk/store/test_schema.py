"""The kiosk database's schema version and migrations, and damaged files: real SQLite files.

The v1 fixture (``data/schema_v1.sql``) is the schema the kiosk shipped before it had versions; a
database written by that kiosk must upgrade with every row kept."""

from __future__ import annotations

import json
import random
import sqlite3
from pathlib import Path

import pytest

from kiosk.commands.results import main as results_main
from kiosk.store import migrations as schema
from kiosk.store.database import DB_NAME, StorageError, Store

V1_SQL = (Path(__file__).parent / "data" / "schema_v1.sql").read_text(encoding="utf-8")


def v1_database(data: Path) -> Path:
    """A database as the pre-version kiosk left it: a finished session, one interrupted by a
    power cut (still 'running'), one `kiosk replay --data-dir` stored (simulated clock epoch), and a
    real one in the simulated clock's first hour (New Year's night)."""
    data.mkdir(mode=0o700)
    path = data / DB_NAME
    db = sqlite3.connect(path)
    db.executescript(V1_SQL)
    db.execute("PRAGMA foreign_keys=ON")
    timing = json.dumps({"attempt_window_s": 30})
    for session_id, patient, started, status in [
        ("aaaa00000001", "P-FIRST1", "2026-11-20T09:00:00+00:00", "finished"),
        ("bbbb00000002", "P-CUTOFF", "2026-11-21T10:00:00+00:00", "running"),
        ("cccc00000003", "TB-0002", "2026-01-01T00:00:05+00:00", "running"),
        ("dddd00000004", "P-NEWYEAR", "2026-01-01T00:20:41.532118+00:00", "finished"),
    ]:
        db.execute("INSERT INTO patients VALUES (?, ?)", (patient, started))
        db.execute(
            "INSERT INTO sessions VALUES (?, ?, 'barthel', 'en', 'patient', ?, ?, ?, NULL, NULL, NULL, NULL)",
            (session_id, patient, timing, started, status),
        )
        db.execute(
            "INSERT INTO answers VALUES (?, 'feeding', 2, 5, 1, 'touch', 'patient', 28.0, ?, 'screen')",
            (session_id, started),
        )
        db.execute(
            "INSERT INTO contexts VALUES (?, 0, 28.0, ?, '[]')",
            (session_id, json.dumps({"FirstAttemptAnswered": True})),
        )
        db.execute(
            "INSERT INTO metric_samples VALUES (?, 0, 28.0, ?, '[]')", (session_id, json.dumps({"Performance": 0.7}))
        )
        db.execute("INSERT INTO events VALUES (?, 0, 10.0, 'start', 'answered by patient')", (session_id,))
    db.execute(
        "UPDATE sessions SET status = 'finished', finished_at = '2026-11-20T09:12:00+00:00', total = 5,"
        " complete = 0 WHERE id = 'aaaa00000001'"
    )
    db.commit()
    db.close()
    return path


def test_a_database_from_before_schema_versions_upgrades_and_keeps_every_row(tmp_path):
    path = v1_database(tmp_path / "data")
    with Store.open(tmp_path / "data") as store:
        assert schema.version(store._db) == schema.LATEST
        sessions = {s.id: s for s in store.sessions()}
        assert set(sessions) == {"aaaa00000001", "bbbb00000002", "cccc00000003", "dddd00000004"}
        finished = store.session("aaaa00000001")
        assert (finished.status, finished.finished_at, [a.option for a in finished.answers]) == (
            "finished",
            "2026-11-20T09:12:00+00:00",
            [2],
        )
        assert finished.trace == ({"t": 28.0, "set": {"FirstAttemptAnswered": True}},)
        assert finished.metrics[0].metrics == {"Performance": 0.7}
        assert [e.kind for e in finished.log] == ["start"]
        # the session a power cut left is for staff to continue, never for the next patient;
        # the scripted patient is recognised as simulated and never offered at all
        assert [s.id for s in store.unfinished_sessions()] == ["bbbb00000002"]
        assert sessions["cccc00000003"].simulated and not sessions["bbbb00000002"].simulated
        # a real patient tested in that very hour (a real clock's start has microseconds) is not
        assert not sessions["dddd00000004"].simulated
    # opening again changes nothing more
    with Store.open(tmp_path / "data") as store:
        assert len(store.sessions()) == 4
    assert path.stat().st_mode & 0o077 == 0


def test_a_fresh_database_is_created_at_the_latest_version(tmp_path):
    with Store.open(tmp_path / "data") as store:
        assert schema.version(store._db) == schema.LATEST
        tables = {r[0] for r in store._db.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
    assert {"sessions", "answers", "leases", "outbox"} <= tables


def test_a_database_newer_than_the_code_is_refused_and_left_alone(tmp_path, capsys):
    data = tmp_path / "data"
    Store.open(data).close()
    path = data / DB_NAME
    with sqlite3.connect(path) as db:
        db.execute(f"PRAGMA user_version = {schema.LATEST + 1}")
    before = path.read_bytes()
    with pytest.raises(StorageError, match=rf"schema version {schema.LATEST + 1}, newer than this kiosk"):
        Store.open(data)
    assert results_main(["--data-dir", str(data)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and str(path) in err[0] and "newer kiosk" in err[0]
    assert path.read_bytes() == before


def test_a_migration_that_fails_leaves_the_database_as_it_was(tmp_path):
    """A hand-edited v1 file with an answer pointing to no session: the upgrade stops, whole."""
    path = v1_database(tmp_path / "data")
    with sqlite3.connect(path) as db:  # foreign keys are off by default in a bare connection
        db.execute("INSERT INTO answers VALUES ('nosuchsession', 'feeding', 2, 5, 1, 'touch', 'patient', 1, 'x', '')")
    with pytest.raises(StorageError, match="pointing nowhere"):
        Store.open(tmp_path / "data")
    with sqlite3.connect(path) as db:
        assert db.execute("PRAGMA user_version").fetchone() == (0,)
        assert "leases" not in {r[0] for r in db.execute("SELECT name FROM sqlite_master")}
        assert db.execute("SELECT COUNT(*) FROM sessions").fetchone() == (4,)


def damage(path: Path) -> None:
    """Overwrite the middle of the file: a disk that lost some pages."""
    size = path.stat().st_size
    with open(path, "r+b") as file:
        file.seek(size // 2)
        file.write(random.Random(7).randbytes(min(4096, size // 2)))


@pytest.mark.parametrize("how", ["garbage", "pages", "truncated"])
def test_a_damaged_database_is_one_message_naming_the_file_and_what_to_do(tmp_path, capsys, how):
    from kiosk.commands import run as kiosk_run

    data = tmp_path / "data"
    with Store.open(data) as store:
        for n in range(300):  # enough rows for a file of several pages
            store._db.execute("INSERT INTO patients VALUES (?, ?)", (f"P-{n:06d}", "x" * 200))
        store._db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    path = data / DB_NAME
    if how == "garbage":
        path.write_bytes(random.Random(8).randbytes(8192))
    elif how == "pages":
        damage(path)
    else:
        path.write_bytes(path.read_bytes()[: path.stat().st_size // 3])
    assert results_main(["--data-dir", str(data)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"kiosk results: {path} is damaged") and "restore a backup" in err[0]
    config = tmp_path / "config.yaml"
    config.write_text(f"data_dir: {data}\n")
    assert kiosk_run.main(["--config", str(config), "--no-voice", "--no-remote"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"kiosk run: {path} is damaged"), err
