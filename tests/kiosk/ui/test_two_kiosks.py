"""Two (and three) real kiosk processes on one data directory (issue 10 parts 1 and 2): a session is
held by one running kiosk at a time; the others are told plainly, never with a traceback; a test
whose kiosk died is for staff to continue, never offered to the next patient.

Each kiosk is `kiosk run`'s own build_app in its own process (tests/kiosk/ui/kiosk_process.py), driven
headless through Textual's Pilot; the lease is checked with the real processes' ids."""

from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
DRIVER = Path(__file__).with_name("kiosk_process.py")
PIN = "246813"


class Kiosk:
    """One real kiosk process and its command line."""

    def __init__(self, config: Path) -> None:
        self.process = subprocess.Popen(
            [sys.executable, str(DRIVER), str(config), PIN],
            cwd=ROOT,
            text=True,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        self.ready = self.read()

    def read(self) -> dict:
        line = self.process.stdout.readline()
        if not line:
            self.process.wait(timeout=30)
            pytest.fail(f"the kiosk process ended: {self.process.stderr.read()}")
        return json.loads(line)

    def do(self, command: str) -> dict:
        self.process.stdin.write(command + "\n")
        self.process.stdin.flush()
        return self.read()

    def stop(self) -> str:
        """Quit (if still running); what it wrote to stderr."""
        if self.process.poll() is None:
            try:
                self.process.stdin.write("quit\n")
                self.process.stdin.flush()
            except BrokenPipeError:
                pass
        try:
            self.process.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        return self.process.stderr.read()


@pytest.fixture
def kiosks(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text(
        f'data_dir: {tmp_path / "data"}\nclinician_pin: "{PIN}"\nfamiliarisation: false\n'
        "timing: {between_questions_s: 0.2, attempt_window_s: 600}\n"
    )
    started: list[Kiosk] = []

    def start() -> Kiosk:
        started.append(Kiosk(config))
        return started[-1]

    yield start
    for kiosk in started:
        if kiosk.process.poll() is None:
            os.kill(kiosk.process.pid, signal.SIGCONT)
        kiosk.stop()


def backdate_leases(data: Path, seconds: float) -> None:
    """Time passing for a frozen kiosk: its lease was last renewed ``seconds`` ago."""
    with sqlite3.connect(data / "kiosk.sqlite3", timeout=30) as db:
        db.execute("UPDATE leases SET renewed_at = renewed_at - ?", (seconds,))


@pytest.mark.slow
def test_a_kiosk_that_lost_its_session_to_another_says_so_and_starts_over_without_a_traceback(kiosks, tmp_path):
    a = kiosks()
    assert a.do("start")["ok"]
    assert a.do("answer 1")["item"] == "feeding"
    assert a.do("answer 2")["item"] == "bathing"
    session = a.do("state")["session"]

    b = kiosks()
    assert b.ready["phase"] == "welcome" and b.ready["session"] != session
    listed = b.do("clinician")
    assert listed["interrupted"] == []  # kiosk A runs: its test is not anybody else's to continue
    b.do("back")

    os.kill(a.process.pid, signal.SIGSTOP)  # kiosk A freezes...
    backdate_leases(tmp_path / "data", 120)  # ...long enough for its lease to lapse
    listed = b.do("clinician")
    (row,) = listed["interrupted"]
    assert row[0] == a.ready["patient"] and row[2] == "2 of 10 answered" and "stopped answering" in row[3]
    continued = b.do("continue")
    assert continued["session"] == session and "refused" not in continued
    assert b.do("start")["ok"]
    answered = b.do("answer 1")  # grooming has two options
    assert answered["item"] == "grooming" and answered["session"] == session, answered

    os.kill(a.process.pid, signal.SIGCONT)  # A wakes up with the patient's next touch
    after = a.do("answer 1")
    assert after["session"] != session and after["phase"] == "welcome"
    # said plainly, naming no patient (the next one may be reading)
    assert any("test was stopped" in n and "another kiosk" in n for n in after["notices"]), after["notices"]
    assert not any(a.ready["patient"] in n for n in after["notices"]), after["notices"]
    assert a.process.poll() is None  # still running, for the next patient

    with sqlite3.connect(tmp_path / "data" / "kiosk.sqlite3") as db:
        rows = db.execute("SELECT item_id, option FROM answers WHERE session_id = ? ORDER BY t", (session,)).fetchall()
    assert rows == [("feeding", 1), ("bathing", 2), ("grooming", 1)]  # one answer each, none from A after
    errors = a.stop() + b.stop()
    assert "Traceback" not in errors and "IntegrityError" not in errors


@pytest.mark.slow
def test_a_dead_kiosks_test_is_for_staff_and_of_two_kiosks_continuing_it_one_is_told_plainly(kiosks, tmp_path):
    a = kiosks()
    assert a.do("start")["ok"]
    a.do("answer 2")
    session = a.do("state")["session"]
    a.process.kill()  # the power cord
    a.process.wait()

    b, c = kiosks(), kiosks()
    for kiosk in (b, c):  # the next patient sees only a fresh start
        assert kiosk.ready["phase"] == "welcome" and kiosk.ready["screen"] == "WelcomeScreen"
        assert kiosk.ready["session"] != session
        (row,) = kiosk.do("clinician")["interrupted"]
        assert (row[0], row[2], row[4]) == (a.ready["patient"], "1 of 10 answered", session)
        assert f"process {a.process.pid}) stopped" in row[3]
    assert b.do("continue")["session"] == session
    refused = c.do("continue")
    assert refused["session"] != session
    assert refused["refused"] == (
        f"Not continued: session {session} is open on another kiosk, "
        f"{os.uname().nodename} (process {b.process.pid}): one kiosk at a time records a test"
    )
    errors = b.stop() + c.stop()
    assert "Traceback" not in errors
