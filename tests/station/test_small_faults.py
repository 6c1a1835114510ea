"""Small faults found by trying the station as an attacker would (issue 32), on a real station
process over HTTP: a huge field is never echoed into a ``Location`` header, and a client that
leaves in the middle of its body leaves no traceback in the station's log."""

from __future__ import annotations

import socket

import pytest

from station import db
from tests.station.conftest import PATIENCE_S, make_ward
from tests.station.helpers import Staff

pytestmark = pytest.mark.slow
#: what a redirect may carry: far below the 8 KiB many proxies allow for a whole header block
LOCATION_BOUND = 1024
HUGE = "x" * 10_000


@pytest.fixture
def station_and_staff(tmp_path, station_factory):
    ward = make_ward(db.sqlite_url(tmp_path / "data"))
    station = station_factory(ward.db_url)
    return station, Staff(station.url), ward.token


def test_a_huge_field_is_never_echoed_into_a_location_header(station_and_staff):
    station, staff, _ = station_and_staff
    for form in (
        {"kiosk": HUGE, "patient_id": "NHC-0012345", "instrument": "barthel", "language": "en"},
        {"kiosk": "ward3-bed2", "patient_id": HUGE, "instrument": "barthel", "language": "en"},
        {"kiosk": "ward3-bed2", "patient_id": "NHC-0012345", "instrument": HUGE, "language": HUGE},
    ):
        refused = staff.post("/orders", **form)
        assert refused.status_code == 303
        location = refused.headers["location"]
        assert location.startswith("/orders?error=") and len(location) <= LOCATION_BOUND, len(location)
        page = staff.http.get(location)  # the form comes back with the one sentence that says why
        assert page.status_code == 200 and HUGE not in page.text
    for path in (f"/kiosks/{HUGE[:4000]}/command", "/kiosks/ward3-bed2/command"):
        refused = staff.post(path, kind=HUGE, session_id=HUGE)
        assert refused.status_code == 303 and len(refused.headers["location"]) <= LOCATION_BOUND


def _leave_mid_body(url: str, path: str, content_type: str, token: str) -> None:
    host, port = url.removeprefix("http://").split(":")
    with socket.create_connection((host, int(port)), timeout=PATIENCE_S) as sock:
        head = (
            f"POST {path} HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Type: {content_type}\r\n"
            f"Authorization: Bearer {token}\r\nContent-Length: 4000\r\n\r\n"
        )
        sock.sendall(head.encode("ascii") + b"name=nurse.kim&password=abc")


def test_a_client_that_leaves_mid_body_leaves_no_traceback(station_and_staff):
    station, staff, token = station_and_staff
    for path, content_type in (
        ("/login", "application/x-www-form-urlencoded"),
        ("/api/v1/sync", "application/json"),
        ("/login", "multipart/form-data; boundary=x"),
    ):
        _leave_mid_body(station.url, path, content_type, token)
    assert staff.http.get("/").status_code == 200  # the station still answers
    station.stop()  # the log is whole once the process has ended
    log = station.log.read_text()
    assert "Traceback" not in log and "Exception in ASGI application" not in log, log[-3000:]
