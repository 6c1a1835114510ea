"""Page requests carry small forms: a huge body to ``/login`` (no login needed to send one) is
refused with 413 and one sentence, whether it declares its length or streams it chunked, and the
station's memory stays where it was. Real station process, raw HTTP over a socket (a client
library would buffer or refuse to send such a body); memory read from /proc."""

from __future__ import annotations

import socket
import threading
from pathlib import Path

import pytest

from station.bodylimit import MESSAGE
from tests.station.conftest import PATIENCE_S
from tests.station.helpers import Staff

pytestmark = pytest.mark.slow
#: what the station may grow by while refusing (the body is 50-700 MB; a parsed one would show)
GROWTH_BOUND = 100 * 1024 * 1024
CHUNK = b"name=" + b"a" * (1024 * 1024 - 5)


def rss(pid: int) -> int:
    """Resident memory of a process in bytes (VmRSS in /proc/PID/status)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) * 1024
    raise AssertionError(f"no VmRSS for process {pid}")


def _open(url: str) -> socket.socket:
    host, port = url.removeprefix("http://").split(":")
    return socket.create_connection((host, int(port)), timeout=PATIENCE_S)


def _send_until_refused(sock: socket.socket, head: bytes, chunks: int, framed: bool) -> bytes:
    """Send ``head`` then up to ``chunks`` MiB of body while a reader collects the answer; stop
    sending once the station has answered or closed. Returns everything the station sent."""
    answer = bytearray()
    done = threading.Event()

    def read() -> None:
        try:
            while data := sock.recv(65536):
                answer.extend(data)
        except OSError:
            pass
        done.set()

    reader = threading.Thread(target=read)
    reader.start()
    try:
        sock.sendall(head)
        for _ in range(chunks):
            if done.is_set() or answer:
                break
            sock.sendall(b"%x\r\n%s\r\n" % (len(CHUNK), CHUNK) if framed else CHUNK)
        else:
            if framed:
                sock.sendall(b"0\r\n\r\n")
    except OSError:  # the station closed the connection on a body it will not read: expected
        pass
    reader.join(PATIENCE_S)
    sock.close()
    return bytes(answer)


@pytest.mark.parametrize("framing", ["content-length", "chunked"])
def test_a_huge_login_body_is_refused_without_growing_the_station(shared_station, framing):
    station, _ = shared_station
    pid = station.process.pid
    before = rss(pid)
    chunks = 700 if framing == "content-length" else 60
    head = (
        b"POST /login HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/x-www-form-urlencoded\r\n"
        + (
            b"Content-Length: %d\r\n" % (chunks * len(CHUNK))
            if framing == "content-length"
            else b"Transfer-Encoding: chunked\r\n"
        )
        + b"\r\n"
    )
    answer = _send_until_refused(_open(station.url), head, chunks, framed=framing == "chunked")
    status_line, _, rest = answer.partition(b"\r\n")
    assert status_line.startswith(b"HTTP/1.1 413"), answer[:300]
    assert MESSAGE.encode() in rest and b"Traceback" not in rest
    assert rss(pid) - before < GROWTH_BOUND, f"station grew from {before >> 20} to {rss(pid) >> 20} MiB"
    # the station still serves, and an ordinary login still works
    assert Staff(station.url).http.get("/").status_code == 200


def test_a_large_staff_form_is_refused_with_one_sentence(shared_station):
    station, _ = shared_station
    staff = Staff(station.url)
    response = staff.post("/sessions/none/sign-off", reason="x" * (200 * 1024))
    assert response.status_code == 413 and response.text == MESSAGE
    assert staff.http.get("/").status_code == 200  # still logged in, nothing else happened
