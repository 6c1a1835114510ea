"""Health that tells the truth (issue 37, part 5): a real station process whose database cannot
be written -- SQLite on a full disk (a small tmpfs, where mounting one is allowed), PostgreSQL made
read-only -- says so on ``/healthz`` (503 with the database's reason) and shows staff a page saying
the station cannot store data, never a bare 500."""

from __future__ import annotations

import contextlib
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
import sqlalchemy as sa

from station import auth, db
from tests.station.conftest import PASSWORDS, make_ward
from tests.station.helpers import Staff

pytestmark = pytest.mark.slow


@contextlib.contextmanager
def small_disk(where: Path, size: str = "8m") -> Iterator[Path]:
    """A tmpfs of ``size`` mounted at ``where`` (skipped where this user may not mount one)."""
    where.mkdir()
    if shutil.which("mount") is None:
        pytest.skip("no mount(8) here")
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here ({done.stderr.decode().strip()})")
    try:
        yield where
    finally:
        subprocess.run(["umount", "-l", str(where)], check=False)


def fill(disk: Path) -> None:
    """Write a file until the disk has no space left."""
    with contextlib.suppress(OSError), open(disk / "filler", "wb", buffering=0) as out:
        while True:
            out.write(b"\0" * 4096)


def check_cannot_store(url: str, logged_in: Staff) -> None:
    health = httpx.get(url + "/healthz", timeout=30)
    assert health.status_code == 503, health.text
    assert health.text.startswith("database cannot be written: ")
    # a page that only reads still works for staff already in
    assert logged_in.http.get("/").status_code == 200
    # a login has to store its session: a page saying why, not a bare 500
    browser = httpx.Client(base_url=url, timeout=30)
    token = Staff.csrf(browser.get("/login").text)
    response = browser.post("/login", data={"csrf": token, "name": "nurse.kim", "password": PASSWORDS["nurse"]})
    assert response.status_code == 503
    assert "text/html" in response.headers["content-type"]
    assert "The station cannot store data: " in response.text
    assert "Traceback" not in response.text


def test_sqlite_full_disk(tmp_path: Path, station_factory) -> None:
    with small_disk(tmp_path / "disk") as disk:
        ward = make_ward(db.sqlite_url(disk / "data"))
        engine = db.make_engine(ward.db_url)
        auth.secret_key(engine)
        engine.dispose()
        station = station_factory(ward.db_url)
        doctor = Staff(station.url)
        assert httpx.get(station.url + "/healthz", timeout=30).text == "ok"
        fill(disk)
        check_cannot_store(station.url, doctor)
        (disk / "filler").unlink()  # space again: the station is healthy again, nothing to restart
        assert httpx.get(station.url + "/healthz", timeout=30).text == "ok"
        station.stop()


def test_postgres_read_only(pg_url: str, station_factory) -> None:
    make_ward(pg_url)
    engine = db.make_engine(pg_url)
    auth.secret_key(engine)
    station = station_factory(pg_url)
    doctor = Staff(station.url)
    name = engine.url.database
    with engine.connect() as connection:
        connection.execute(sa.text(f'ALTER DATABASE "{name}" SET default_transaction_read_only = on'))
        # the station's pooled connections keep their old setting: end them (the pool reconnects)
        connection.execute(
            sa.text(
                "SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = :d AND pid <> pg_backend_pid()"
            ),
            {"d": name},
        )
        connection.commit()
    check_cannot_store(station.url, doctor)
    with engine.connect() as connection:
        connection.execute(sa.text(f'ALTER DATABASE "{name}" SET default_transaction_read_only = off'))
        connection.execute(
            sa.text(
                "SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = :d AND pid <> pg_backend_pid()"
            ),
            {"d": name},
        )
        connection.commit()
    assert httpx.get(station.url + "/healthz", timeout=30).text == "ok"
    engine.dispose()
