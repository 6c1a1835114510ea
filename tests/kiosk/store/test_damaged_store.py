"""A session database edited by hand or by a broken tool, through the real `kiosk results`: a dropped
table, or a row holding a value no kiosk writes (an unknown channel, a timing that is not JSON), is
one line naming the database and what is wrong, exit 2, no traceback, and the file is left as it
was (issue 22, part 4)."""

from __future__ import annotations

import hashlib
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.store.database import _TABLES, DB_NAME, Store

ROOT = Path(__file__).resolve().parents[3]
#: a guard against a hang, not a timing assertion
HANG_S = 120


@pytest.fixture
def data_dir(tmp_path: Path) -> Path:
    """A data directory holding one real replayed session."""
    data = tmp_path / "data"
    with Store.open(data) as store:
        run_script(load_script(ROOT / "recordings/patients/barthel6.yaml"), store=store)
    return data


def results(data: Path, *args: str) -> subprocess.CompletedProcess:
    """A real `kiosk results` process on ``data``, with no user configuration."""
    return subprocess.run(
        [sys.executable, "-m", "kiosk", "results", "--data-dir", str(data), *args],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=HANG_S,
        check=False,
        env={"PATH": "/usr/bin:/bin", "HOME": str(data.parent)},
    )


def edit(data: Path, *statements: str) -> tuple[str, str]:
    """Run SQL on the database as a broken tool would; returns (the session id, the file's hash)."""
    db = sqlite3.connect(data / DB_NAME, isolation_level=None)  # autocommit: each statement stands
    try:
        session_id = db.execute("SELECT id FROM sessions").fetchone()[0]
        for statement in statements:
            db.execute(statement)
        db.execute("PRAGMA wal_checkpoint(TRUNCATE)")  # all of it in the main file, hashed below
    finally:
        db.close()
    return session_id, hashlib.sha256((data / DB_NAME).read_bytes()).hexdigest()


def refused(done: subprocess.CompletedProcess, *words: str) -> None:
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    assert "Traceback" not in done.stderr and done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith("kiosk results: ") and all(w in done.stderr for w in words), done.stderr


@pytest.mark.slow  # a subprocess
@pytest.mark.parametrize("table", _TABLES)
def test_a_dropped_table_is_named_with_the_database(data_dir, table):
    _, before = edit(data_dir, "PRAGMA foreign_keys=OFF", f"DROP TABLE {table}")
    for args in ((), ("--csv", str(data_dir.parent / "out.csv"))):
        refused(results(data_dir, *args), str(data_dir / DB_NAME), f"the table {table} is missing")
    assert hashlib.sha256((data_dir / DB_NAME).read_bytes()).hexdigest() == before
    assert not (data_dir.parent / "out.csv").exists()


@pytest.mark.slow  # a subprocess
@pytest.mark.parametrize(
    ("statement", "what"),
    [
        (
            "UPDATE answers SET channel = 'smoke' WHERE rowid = (SELECT min(rowid) FROM answers)",
            "'smoke' is not a valid Channel",
        ),
        ("UPDATE answers SET channel = 7 WHERE rowid = (SELECT min(rowid) FROM answers)", "'7' is not a valid Channel"),
        (
            "UPDATE answers SET answered_by = 'robot' WHERE rowid = (SELECT min(rowid) FROM answers)",
            "'robot' is not a valid AnsweredBy",
        ),
        ("UPDATE sessions SET timing = '{not json'", "Expecting property name"),
        ("UPDATE metric_samples SET fired = '3'", "'int' object is not iterable"),
    ],
)
def test_a_row_no_kiosk_writes_is_one_line_naming_the_database(data_dir, statement, what):
    session_id, before = edit(data_dir, statement)
    listed = results(data_dir)  # the list reads none of those values: it still works
    assert listed.returncode == 0 and session_id in listed.stdout, listed.stderr
    for args in ((session_id,), ("--fhir", str(data_dir.parent / "out.json"))):
        refused(results(data_dir, *args), str(data_dir / DB_NAME), "cannot read", what)
    assert hashlib.sha256((data_dir / DB_NAME).read_bytes()).hexdigest() == before
    assert not (data_dir.parent / "out.json").exists()
