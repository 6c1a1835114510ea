"""Ctrl-C in a real `kiosk replay` (issue 22, part 4): one line, exit 130, no traceback, and nothing
half-stored: every scripted patient in the database is either finished or abandoned (never left
running or resumable), the database is intact and what waits for the station is kept."""

from __future__ import annotations

import signal
import socket
import sqlite3
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from kiosk.store.database import DB_NAME

ROOT = Path(__file__).resolve().parents[3]
PATIENTS = sorted((ROOT / "recordings/patients").glob("*.yaml"))
#: guards against a hang, not timing assertions
PATIENCE_S = 120.0
#: `python -m kiosk ARGS` with Ctrl-C doing what it does from a terminal: a shell that started the
#: tests in the background hands its children SIGINT ignored, and Python would keep it so
AS_FROM_A_TERMINAL = (
    "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
    "os.execv(sys.executable, [sys.executable, '-m', 'kiosk', *sys.argv[1:]])"
)


def _unused_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _statuses(db: Path) -> dict[str, int]:
    if not db.exists():
        return {}
    with sqlite3.connect(f"file:{db}?mode=ro", uri=True) as connection:
        try:
            return dict(connection.execute("SELECT status, COUNT(*) FROM sessions GROUP BY status").fetchall())
        except sqlite3.OperationalError:  # the replay is still creating the schema
            return {}


@pytest.mark.slow  # a subprocess
def test_ctrl_c_in_kiosk_replay_is_one_line_exit_130_and_nothing_half_stored(tmp_path):
    # a station nobody answers: once every script is stored the replay keeps trying to deliver for
    # up to --station-wait, so the Ctrl-C below always lands before the command could end
    config = tmp_path / "config.yaml"
    config.write_text(f"station: {{url: 'http://127.0.0.1:{_unused_port()}', token: abc}}\n", encoding="utf-8")
    data = tmp_path / "data"
    scripts = [str(p) for p in PATIENTS] * 3
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            AS_FROM_A_TERMINAL,
            "replay",
            *scripts,
            "--data-dir",
            str(data),
            "--config",
            str(config),
            "--station-wait",
            "600",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
        text=True,
        cwd=ROOT,
    )
    try:
        pause = threading.Event()
        waited = 0.0
        while _statuses(data / DB_NAME).get("finished", 0) < 1:  # a scripted patient is stored
            assert child.poll() is None, child.communicate()
            assert waited < PATIENCE_S, "no scripted patient was stored"
            pause.wait(0.05)
            waited += 0.05
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=PATIENCE_S)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert (child.returncode, err) == (130, "kiosk replay: interrupted\n"), (child.returncode, err)
    assert out == ""

    statuses = _statuses(data / DB_NAME)
    assert set(statuses) <= {"finished", "abandoned"} and statuses["finished"] >= 1, statuses
    with sqlite3.connect(data / DB_NAME) as db:
        assert db.execute("PRAGMA quick_check").fetchall() == [("ok",)]
        assert db.execute("SELECT COUNT(*) FROM leases").fetchone() == (0,)
        stored = db.execute("SELECT COUNT(*) FROM sessions").fetchone()[0]
        # every stored session is queued for the station, whole: its creation and its end
        queued = db.execute("SELECT COUNT(DISTINCT session_id) FROM outbox WHERE kind = 'create_session'").fetchone()
        assert queued == (stored,)
