"""JSON over HTTP(S) to the station with the standard library (``http.client``), one request per
connection, and a way for another thread to cut a request short (stopping during a long poll)."""

from __future__ import annotations

import http.client
import json
import socket
import threading
from typing import Any
from urllib.parse import urlsplit


class Unreachable(Exception):
    """No answer from the station: refused, reset, timed out, or not HTTP (the message says which)."""


class Station:
    """Requests to one station as one kiosk (``Authorization: Bearer <token>``)."""

    def __init__(self, url: str, token: str) -> None:
        parts = urlsplit(url)
        if parts.scheme not in ("http", "https") or not parts.hostname:
            raise ValueError(f"the station url {url!r} is not an http:// or https:// address")
        self.url = url
        self._https = parts.scheme == "https"
        self._host = parts.hostname
        self._port = parts.port
        self._prefix = parts.path.rstrip("/")
        self._token = token
        self._lock = threading.Lock()
        self._open: set[http.client.HTTPConnection] = set()

    def request(self, method: str, path: str, body: Any = None, timeout: float = 15.0) -> tuple[int, Any]:
        """(status, decoded JSON body or None). :class:`Unreachable` when there is no HTTP answer."""
        kind = http.client.HTTPSConnection if self._https else http.client.HTTPConnection
        connection = kind(self._host, self._port, timeout=timeout)
        headers = {"Authorization": f"Bearer {self._token}", "Accept": "application/json"}
        data = None
        if body is not None:
            data = json.dumps(body, ensure_ascii=False).encode("utf-8")
            headers["Content-Type"] = "application/json"
        with self._lock:
            self._open.add(connection)
        try:
            connection.request(method, self._prefix + path, body=data, headers=headers)
            response = connection.getresponse()
            raw = response.read()
        except (OSError, http.client.HTTPException) as exc:
            raise Unreachable(_describe(exc)) from None
        finally:
            with self._lock:
                self._open.discard(connection)
            connection.close()
        try:
            return response.status, json.loads(raw) if raw else None
        except ValueError:
            return response.status, None

    def abort(self) -> None:
        """Cut every request in flight short (they raise :class:`Unreachable`)."""
        with self._lock:
            for connection in list(self._open):
                if connection.sock is not None:
                    try:
                        connection.sock.shutdown(socket.SHUT_RDWR)
                    except OSError:
                        pass


def _describe(exc: BaseException) -> str:
    if isinstance(exc, TimeoutError | socket.timeout):
        return "no answer in time"
    if isinstance(exc, ConnectionRefusedError):
        return "connection refused"
    return str(exc) or type(exc).__name__
