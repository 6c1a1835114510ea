"""A small ward station for the sync client's tests: a real HTTP server on 127.0.0.1 (a thread)
that speaks the protocol of docs/station-protocol.md -- idempotent on (kiosk_id, seq), long-polled
commands with acks, live status -- and can be told to misbehave: drop the connection after it
stored a batch but before replying, answer 500, refuse one row with 422, or be down.

The real `kiosk station` is tested end to end in test_station_e2e.py; this one exists for the
faults a real station cannot be made to produce on cue."""

from __future__ import annotations

import json
import select
import socket
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import parse_qs, urlsplit

TOKEN = "kiosk-token-1"


class Ward:
    """The station's state and its faults (read and set from the test's thread)."""

    def __init__(self) -> None:
        self.lock = threading.Condition()
        #: (kiosk_id, seq) -> event, each stored once
        self.stored: dict[tuple[str, int], dict[str, Any]] = {}
        #: every sync request's seqs, in arrival order (duplicates show retries)
        self.requests: list[list[int]] = []
        self.statuses: list[dict[str, Any]] = []
        self.commands: list[dict[str, Any]] = []
        self.acks: dict[int, dict[str, Any]] = {}
        #: faults: how many sync requests to store-then-drop, to answer 500, and seqs to refuse
        self.drop_after_store = 0
        self.fail_500 = 0
        self.refuse: set[int] = set()
        #: a slow station: a batch holding a row of this kind waits until ``release`` is set
        self.hold_kind: str | None = None
        self.release = threading.Event()
        #: seqs of the batches held, and how many of them the client gave up waiting for
        self.held: list[list[int]] = []
        self.abandoned = 0

    def sync(self, body: dict[str, Any], gone: Any = lambda: False) -> tuple[int, dict[str, Any] | None]:
        if self.hold_kind is not None and any(e["kind"] == self.hold_kind for e in body["events"]):
            with self.lock:
                self.held.append([e["seq"] for e in body["events"]])
                self.lock.notify_all()
            while not self.release.wait(0.05):
                if gone():  # the client closed the connection: it gave this request up
                    with self.lock:
                        self.abandoned += 1
                        self.lock.notify_all()
                    return 0, None
        with self.lock:
            seqs = [e["seq"] for e in body["events"]]
            self.requests.append(seqs)
            if self.fail_500:
                self.fail_500 -= 1
                return 500, {"error": "the database is restarting"}
            if self.refuse & set(seqs):
                return 422, {"error": f"seq {min(self.refuse & set(seqs))}: refused"}
            for event in body["events"]:
                self.stored.setdefault((body["kiosk_id"], event["seq"]), event)
            if self.drop_after_store:
                self.drop_after_store -= 1
                return 0, None  # stored, and the connection drops before the reply
            self.lock.notify_all()
            return 200, {"stored": seqs}

    def queue(self, command: dict[str, Any]) -> None:
        with self.lock:
            self.commands.append(command)
            self.lock.notify_all()

    def pending_commands(self, wait: float) -> list[dict[str, Any]]:
        deadline = time.monotonic() + wait
        with self.lock:
            while True:
                pending = [c for c in self.commands if c["id"] not in self.acks]
                left = deadline - time.monotonic()
                if pending or left <= 0:
                    return pending
                self.lock.wait(left)


class Handler(BaseHTTPRequestHandler):
    ward: Ward

    def log_message(self, *args: Any) -> None:  # quiet
        pass

    def handle(self) -> None:
        try:
            super().handle()
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client gave up on this request (it was stopped): nothing to answer

    def _reply(self, status: int, body: Any) -> None:
        if status == 0:
            self.connection.shutdown(socket.SHUT_RDWR)
            return
        data = json.dumps(body).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def _gone(self) -> bool:
        """Whether the client closed this connection (its end read as end-of-file)."""
        ready, _, _ = select.select([self.connection], [], [], 0)
        return bool(ready) and self.connection.recv(1, socket.MSG_PEEK) == b""

    def _authorised(self) -> bool:
        if self.headers.get("Authorization") != f"Bearer {TOKEN}":
            self._reply(401, {"error": "unknown or revoked kiosk token"})
            return False
        return True

    def do_POST(self) -> None:  # http.server's name
        if not self._authorised():
            return
        body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        path = urlsplit(self.path).path
        if path == "/api/v1/sync":
            self._reply(*self.ward.sync(body, self._gone))
        elif path == "/api/v1/status":
            with self.ward.lock:
                self.ward.statuses.append(body)
                self.ward.lock.notify_all()
            self._reply(200, {})
        elif path.startswith("/api/v1/commands/") and path.endswith("/ack"):
            with self.ward.lock:
                self.ward.acks[int(path.split("/")[4])] = body
                self.ward.lock.notify_all()
            self._reply(200, {})
        else:
            self._reply(404, {"error": "no such endpoint"})

    def do_GET(self) -> None:
        if not self._authorised():
            return
        wait = float(parse_qs(urlsplit(self.path).query).get("wait", ["0"])[0])
        self._reply(200, {"commands": self.ward.pending_commands(min(wait, 2.0))})


class Server:
    """The ward on a port of 127.0.0.1; ``stop()`` takes it down, ``start()`` brings it back on the
    same port (a station restarted)."""

    def __init__(self) -> None:
        self.ward = Ward()
        probe = socket.socket()
        probe.bind(("127.0.0.1", 0))
        self.port = probe.getsockname()[1]
        probe.close()
        self.url = f"http://127.0.0.1:{self.port}"
        self._server: ThreadingHTTPServer | None = None

    def start(self) -> Server:
        handler = type("WardHandler", (Handler,), {"ward": self.ward})
        ThreadingHTTPServer.allow_reuse_address = True
        self._server = ThreadingHTTPServer(("127.0.0.1", self.port), handler)
        self._server.daemon_threads = True
        threading.Thread(target=self._server.serve_forever, daemon=True).start()
        return self

    def stop(self) -> None:
        if self._server is not None:
            self._server.shutdown()
            self._server.server_close()
            self._server = None

    def until(self, condition, what: str, patience_s: float = 30.0) -> None:
        """Wait (bounded) until ``condition(ward)`` holds; each change the server sees wakes it."""
        deadline = time.monotonic() + patience_s
        with self.ward.lock:
            while not condition(self.ward):
                left = deadline - time.monotonic()
                if left <= 0:
                    raise AssertionError(f"the station never saw {what}")
                self.ward.lock.wait(min(left, 0.2))
