"""Login throttling on a real station: a forged ``X-Forwarded-For`` from a peer that is not a
named proxy changes nothing, the pause grows with one name's failures from one address, the real
doctor logs in from their own address while an attacker hammers their name from another, and
every failure is in the security log. Addresses are real: the test's clients connect from
127.0.0.1 and 127.0.0.2, or through a proxy named with ``--trusted-proxy``."""

from __future__ import annotations

import ipaddress
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import httpx
import pytest
import sqlalchemy as sa

from station import db, throttle
from tests.station.conftest import PASSWORDS, PATIENCE_S, make_ward
from tests.station.helpers import Staff
from tests.station.test_cli import kiosk_station

pytestmark = pytest.mark.slow
ATTEMPTS = 300  # the attacker's tries at most (it stops once the doctor is in)


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request, tmp_path):
    return db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")


def most_checked(elapsed: float, free: int = throttle.FREE_FAILURES) -> int:
    """The most tries whose password the schedule lets the station check within ``elapsed``
    seconds: the free ones, then one per pause (each starts at the previous failure)."""
    checked, spent = free, 0.0
    while spent + throttle.pause_after(checked, free) <= elapsed:
        spent += throttle.pause_after(checked, free)
        checked += 1
    return checked


class Browser:
    """A login form user from one source address (``local``), optionally with forged headers."""

    def __init__(self, url: str, local: str = "127.0.0.1") -> None:
        self.http = httpx.Client(base_url=url, timeout=PATIENCE_S, transport=httpx.HTTPTransport(local_address=local))
        self.token = Staff.csrf(self.http.get("/login").text)

    def login(self, name: str, password: str, forwarded: str | None = None) -> httpx.Response:
        headers = {"x-forwarded-for": forwarded} if forwarded else {}
        return self.http.post(
            "/login", data={"csrf": self.token, "name": name, "password": password, "next": "/"}, headers=headers
        )


def hammer(browser: Browser, name: str, forwarded, stop: threading.Event, paused: threading.Event) -> list[int]:
    """Wrong passwords for ``name`` until ``stop`` (or :data:`ATTEMPTS`); ``paused`` is set at the
    first 429. Returns every status."""
    statuses = []
    for attempt in range(ATTEMPTS):
        if stop.is_set():
            break
        response = browser.login(name, f"guess-{attempt}", forwarded(attempt))
        statuses.append(response.status_code)
        if response.status_code == 429:
            assert "try again in" in response.text and int(response.headers["retry-after"]) >= 1
            paused.set()
    paused.set()
    return statuses


def attack_while_doctor_logs_in(
    station_url: str, attacker: Browser, forwarded, doctor: Browser, doctor_forwarded: str | None = None
) -> tuple[list[int], float]:
    stop, paused, statuses = threading.Event(), threading.Event(), []
    started = time.monotonic()
    thread = threading.Thread(target=lambda: statuses.extend(hammer(attacker, "dr.lopez", forwarded, stop, paused)))
    thread.start()
    try:
        assert paused.wait(PATIENCE_S * 2), "the attacker was never paused"
        response = doctor.login("dr.lopez", PASSWORDS["doctor"], doctor_forwarded)
        assert response.status_code == 303, response.text
        assert 'id="kiosks"' in doctor.http.get("/").text  # the ward page, during the attack
    finally:
        stop.set()
        thread.join(PATIENCE_S * 2)
    return statuses, time.monotonic() - started


def failure_addresses(db_url: str) -> set[str]:
    engine = db.make_engine(db_url)
    with engine.connect() as connection:
        found = set(connection.execute(sa.select(db.login_failures.c.address)).scalars())
    engine.dispose()
    return found


def test_forged_forwarded_for_from_an_untrusted_peer_does_not_bypass_the_limit(db_url, station_factory):
    make_ward(db_url)
    station = station_factory(db_url)
    attacker, doctor = Browser(station.url, "127.0.0.1"), Browser(station.url, "127.0.0.2")
    statuses, elapsed = attack_while_doctor_logs_in(
        station.url, attacker, lambda attempt: f"198.51.100.{attempt % 250}, 10.0.0.{attempt % 250}", doctor
    )
    checked = statuses.count(401)
    assert set(statuses) <= {401, 429} and len(statuses) >= throttle.FREE_FAILURES + 1
    assert throttle.FREE_FAILURES <= checked <= most_checked(elapsed), (checked, len(statuses), elapsed)
    assert failure_addresses(db_url) == {"127.0.0.1"}  # the forged addresses were never believed
    log = station.log.read_text()
    assert log.count("login failed: name 'dr.lopez' from 127.0.0.1 ") == checked
    assert log.count("login refused: name 'dr.lopez' from 127.0.0.1 ") == statuses.count(429)
    assert "198.51.100." not in log and "Traceback" not in log


def test_parallel_tries_cannot_slip_through_together(db_url, station_factory):
    make_ward(db_url)
    station = station_factory(db_url)
    browsers = [Browser(station.url) for _ in range(24)]
    ready = threading.Barrier(len(browsers))

    def guess(browser: Browser) -> int:
        ready.wait(PATIENCE_S)
        return browser.login("dr.lopez", "a-parallel-guess").status_code

    started = time.monotonic()
    with ThreadPoolExecutor(len(browsers)) as pool:
        statuses = list(pool.map(guess, browsers))
    assert set(statuses) <= {401, 429}
    assert throttle.FREE_FAILURES <= statuses.count(401) <= most_checked(time.monotonic() - started), statuses


def test_behind_a_named_proxy_each_client_address_is_throttled_alone(station_factory, tmp_path):
    ward = make_ward(db.sqlite_url(tmp_path / "data"))
    station = station_factory(ward.db_url, args=("--trusted-proxy", "127.0.0.1", "--trusted-proxy", "10.9.0.0/16"))
    proxy = Browser(station.url, "127.0.0.1")
    # the client forges the left part; the proxy (and a second trusted hop) append what they saw
    statuses, elapsed = attack_while_doctor_logs_in(
        station.url,
        proxy,
        lambda attempt: f"192.0.2.{attempt % 250}, 203.0.113.9, 10.9.1.1",
        Browser(station.url, "127.0.0.1"),
        doctor_forwarded="198.51.100.7",
    )
    assert throttle.FREE_FAILURES <= statuses.count(401) <= most_checked(elapsed)
    # a peer that is not a named proxy is its own address, whatever it forwards
    outsider = Browser(station.url, "127.0.0.2")
    assert outsider.login("nurse.kim", "wrong-password", "198.51.100.7").status_code == 401
    assert failure_addresses(ward.db_url) == {"203.0.113.9", "127.0.0.2"}
    # guessing across names from one address pauses that address, not the others
    sprayer = Browser(station.url, "127.0.0.1")
    started = time.monotonic()
    sprayed = [sprayer.login(f"user{n}", "wrong-password", "203.0.113.77").status_code for n in range(40)]
    assert sprayed.count(401) <= most_checked(time.monotonic() - started, throttle.FREE_NAMES) and 429 in sprayed
    assert proxy.login("nurse.kim", PASSWORDS["nurse"], "203.0.113.78").status_code == 303


@pytest.mark.parametrize(
    "peer, forwarded, trusted, expected",
    [
        ("127.0.0.1", ["198.51.100.1"], [], "127.0.0.1"),
        ("10.0.0.5", ["198.51.100.1"], ["10.0.0.0/8"], "198.51.100.1"),
        ("10.0.0.5", ["6.6.6.6, 198.51.100.1, 10.0.0.9"], ["10.0.0.0/8"], "198.51.100.1"),
        ("10.0.0.5", ["6.6.6.6", "198.51.100.1"], ["10.0.0.0/8"], "198.51.100.1"),
        ("10.0.0.5", ["not-an-address"], ["10.0.0.0/8"], "10.0.0.5"),
        ("10.0.0.5", [], ["10.0.0.0/8"], "10.0.0.5"),
        ("::1", [" 2001:db8::7 "], ["::1"], "2001:db8::7"),
    ],
)
def test_client_address(peer, forwarded, trusted, expected):
    assert throttle.client_address(peer, forwarded, [ipaddress.ip_network(t) for t in trusted]) == expected


def test_a_wrong_trusted_proxy_is_one_line(tmp_path):
    done = kiosk_station("--trusted-proxy", "proxy.example", "--db", db.sqlite_url(tmp_path / "d"))
    assert done.returncode == 2 and "--trusted-proxy 'proxy.example'" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
