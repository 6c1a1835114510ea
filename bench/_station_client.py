"""A kiosk's side of the station protocol, for the station's tests and benchmark.

:class:`RecordingStore` runs under a real :class:`kiosk.session.Session` (a scripted patient
replayed by :func:`kiosk.replay.run_script`) and turns every store call into the outbox row the
protocol defines: ``kind`` the ``Store`` method's name, ``payload`` its keyword arguments.
:class:`KioskClient` speaks protocol v1 over HTTP. The kiosk's own sync client lives in
``kiosk/sync/``; this one exists so the station can be tested and measured on its own.
"""

from __future__ import annotations

import contextlib
import itertools
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any

import httpx

ALERT_KINDS = {"doctor_called", "call_doctor", "doctor_continued", "clinician_continue", "person_lost", "person_back"}
PATIENTS = Path(__file__).resolve().parent.parent / "recordings" / "patients"


@dataclass
class Row:
    seq: int
    kind: str
    session_id: str
    payload: dict[str, Any]
    #: the session time it was written at (for pacing a replay)
    t: float
    at: str

    def event(self) -> dict[str, Any]:
        return {"seq": self.seq, "kind": self.kind, "session_id": self.session_id, "at": self.at,
                "payload": self.payload}

    @property
    def alert(self) -> bool:
        return self.kind == "record_event" and self.payload.get("kind") in ALERT_KINDS


@dataclass
class RecordingStore:
    """Implements kiosk.session.SessionStore by recording outbox rows (seq from ``first_seq``)."""

    first_seq: int = 1
    rows: list[Row] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._seq = itertools.count(self.first_seq)
        self._t = 0.0
        self._start = datetime(1970, 1, 1, tzinfo=UTC)

    def _add(self, kind: str, session_id: str, payload: Mapping[str, Any]) -> None:
        payload = {k: (dict(v) if isinstance(v, Mapping) else list(v) if isinstance(v, tuple) else v)
                   for k, v in payload.items()}
        self._t = float(payload.get("t", self._t))
        if kind == "create_session":
            self._start = datetime.fromisoformat(payload["started_at"]) - timedelta(seconds=self._t)
        at = (self._start + timedelta(seconds=self._t)).isoformat()
        self.rows.append(Row(next(self._seq), kind, session_id, payload, self._t, at))

    @contextlib.contextmanager
    def transaction(self) -> Iterator[None]:
        yield

    def create_session(self, **kw: Any) -> None:
        self._add("create_session", kw["session_id"], kw)

    def finish_session(self, session_id: str, **kw: Any) -> None:
        self._add("finish_session", session_id, kw)

    def abandon(self, session_id: str) -> None:
        self._add("abandon", session_id, {})

    def __getattr__(self, name: str) -> Any:
        if not name.startswith("record_"):
            raise AttributeError(name)
        return lambda session_id, **kw: self._add(name, session_id, kw)


def record_patient(script: str | Path, first_seq: int = 1, patient: str | None = None) -> list[Row]:
    """The outbox rows a kiosk writes while a scripted patient runs (real session, real QoS)."""
    from dataclasses import replace

    from kiosk.replay import load_script, run_script

    loaded = load_script(script)
    if patient is not None:
        loaded = replace(loaded, patient=patient)
    store = RecordingStore(first_seq)
    run_script(loaded, store=store)
    return store.rows


class KioskClient:
    """Protocol v1 over HTTP with one kiosk's token."""

    def __init__(self, url: str, token: str, kiosk_id: str, timeout: float = 30.0) -> None:
        self.kiosk_id = kiosk_id
        self.http = httpx.Client(base_url=url, headers={"Authorization": f"Bearer {token}"}, timeout=timeout)

    def close(self) -> None:
        self.http.close()

    def sync(self, rows: list[Row]) -> httpx.Response:
        return self.http.post("/api/v1/sync", json={"kiosk_id": self.kiosk_id, "events": [r.event() for r in rows]})

    def status(self, **fields: Any) -> httpx.Response:
        body = {"kiosk_id": self.kiosk_id, "at": None, "session_id": None, "patient_id": None, "phase": None,
                "question": None, "of": None, "paused": False, "person_away": False, "doctor_called": False,
                "simulated": True} | fields
        return self.http.post("/api/v1/status", json=body)

    def commands(self, wait: float = 0.0) -> list[dict[str, Any]]:
        response = self.http.get("/api/v1/commands", params={"wait": wait}, timeout=wait + 30)
        response.raise_for_status()
        return response.json()["commands"]

    def ack(self, command_id: int, result: str = "done", reason: str | None = None) -> httpx.Response:
        body = {"result": result} | ({"reason": reason} if reason else {})
        return self.http.post(f"/api/v1/commands/{command_id}/ack", json=body)
