"""Shared fixtures of the station tests: a real PostgreSQL (Debian's binaries, started in a
temporary directory once per test session), real station processes on free 127.0.0.1 ports, and
one headless Chromium for the page tests."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import httpx
import pytest

from bench._postgres import create_database, free_port, pg_bin, start_postgres
from station import auth, db
from tests.prerequisites import require_debian

ROOT = Path(__file__).resolve().parents[2]
#: how long a real process may take to start or answer on a loaded 2-core CI machine
PATIENCE_S = 60.0
PASSWORDS = {"nurse": "nurse-password-1", "doctor": "doctor-password-1"}


@pytest.fixture(scope="session")
def postgres() -> Iterator[str]:
    """A PostgreSQL server for this test session; yields its URL (superuser, trust on 127.0.0.1)."""
    bin_dir = pg_bin()
    if bin_dir is None:
        require_debian("postgresql", path="/usr/lib/postgresql/*/bin/initdb")
    url, stop = start_postgres(bin_dir)
    try:
        yield url
    finally:
        stop()


@pytest.fixture
def pg_url(postgres: str) -> str:
    """A fresh, empty database on the shared server for one test."""
    return create_database(postgres, "t_" + uuid.uuid4().hex[:12])


@pytest.fixture
def sqlite_url(tmp_path: Path) -> str:
    return db.sqlite_url(tmp_path / "station")


@dataclass
class Station:
    """A running `kiosk station` process."""

    url: str
    db_url: str
    process: subprocess.Popen[bytes]
    log: Path

    def kill(self) -> None:
        """SIGKILL: no shutdown, as in a power cut."""
        self.process.send_signal(signal.SIGKILL)
        self.process.wait(timeout=PATIENCE_S)

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.kill()


def start_station(db_url: str, log: Path, port: int | None = None, args: tuple[str, ...] = ()) -> Station:
    """Start `kiosk station` on ``db_url`` (with more command-line ``args``) and wait until it answers."""
    port = port or free_port()
    env = os.environ | {"PYTHONUNBUFFERED": "1"}
    with open(log, "ab") as out:
        process = subprocess.Popen(
            [sys.executable, "-m", "kiosk", "station", "--db", db_url, "--port", str(port), *args],
            stdout=out,
            stderr=subprocess.STDOUT,
            cwd=ROOT,
            env=env,
        )
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + PATIENCE_S
    while True:
        if process.poll() is not None:
            raise AssertionError(f"the station exited with {process.returncode}:\n{log.read_text()}")
        try:
            if httpx.get(url + "/healthz", timeout=2).status_code == 200:
                return Station(url, db_url, process, log)
        except httpx.TransportError:
            pass
        if time.monotonic() > deadline:
            process.kill()
            raise AssertionError(f"the station did not answer within {PATIENCE_S} s:\n{log.read_text()}")
        time.sleep(0.1)  # polling for readiness, bounded by PATIENCE_S; nothing is timed


@dataclass
class Ward:
    """A station database with staff and one kiosk, and the kiosk's token."""

    db_url: str
    token: str
    kiosk_id: str = "ward3-bed2"


def make_ward(db_url: str, kiosk_id: str = "ward3-bed2") -> Ward:
    engine = db.open_database(db_url)
    auth.add_user(engine, "nurse.kim", "nurse", PASSWORDS["nurse"])
    auth.add_user(engine, "dr.lopez", "doctor", PASSWORDS["doctor"])
    token = auth.add_kiosk(engine, kiosk_id)
    engine.dispose()
    return Ward(db_url, token, kiosk_id)


@pytest.fixture
def station_factory(tmp_path: Path) -> Iterator:
    """Start stations; all are stopped at the end of the test."""
    started: list[Station] = []

    def start(db_url: str, port: int | None = None, args: tuple[str, ...] = ()) -> Station:
        station = start_station(db_url, tmp_path / f"station{len(started)}.log", port, args)
        started.append(station)
        return station

    yield start
    for station in started:
        station.stop()


@pytest.fixture(scope="module")
def shared_station(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Station, Ward]]:
    """One station on SQLite for a test module (starting a process is the slow part); each test
    adds its own kiosk with :func:`new_kiosk`."""
    base = tmp_path_factory.mktemp("station")
    ward = make_ward(db.sqlite_url(base / "data"))
    station = start_station(ward.db_url, base / "station.log")
    yield station, ward
    station.stop()


def new_kiosk(db_url: str) -> tuple[str, str]:
    """A new kiosk on the station's database: (name, token)."""
    name = "kiosk-" + uuid.uuid4().hex[:8]
    engine = db.make_engine(db_url)
    try:
        return name, auth.add_kiosk(engine, name)
    finally:
        engine.dispose()


@pytest.fixture(scope="package")
def browser(chromium: str) -> Iterator:
    """One headless Chromium (Debian's) for every page test of this package.

    Package scope, not session: Playwright's sync API keeps an event loop running in the main
    thread while it is open, and every async (Textual Pilot) test after the station's would fail
    with "Runner.run() cannot be called from a running event loop"."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(
            executable_path=chromium,
            args=[
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
            ],
        )
        yield chromium
        chromium.close()
