"""A kiosk's side of the station protocol, for the station's tests and benchmark.

:func:`record_patient` gives the outbox rows the kiosk's own store writes while a scripted
patient runs; :class:`KioskClient` speaks protocol v1 over HTTP. The kiosk's own sync client lives in
``kiosk/sync/``; this one exists so the station can be tested and measured on its own.
"""

from __future__ import annotations

import json
import sqlite3
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx

from kiosk.store.transactions import ALERT_EVENTS

#: the protocol's names of the rows a kiosk sends first (kiosk.store.transactions.ALERT_EVENTS)
ALERT_KINDS = set(ALERT_EVENTS.values())
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
        return {
            "seq": self.seq,
            "kind": self.kind,
            "session_id": self.session_id,
            "at": self.at,
            "payload": self.payload,
        }

    @property
    def alert(self) -> bool:
        return self.kind == "record_event" and self.payload.get("kind") in ALERT_KINDS


def record_patient(
    script: str | Path,
    first_seq: int = 1,
    patient: str | None = None,
    export: dict[str, str] | None = None,
    data_dir: Path | None = None,
    visit: str | None = None,
    questionnaire: Any = None,
) -> list[Row]:
    """The outbox rows a kiosk writes while a scripted patient runs: a real session and QoS engine
    on the kiosk's real :class:`kiosk.store.database.Store` with a station configured, its outbox read
    back and numbered from ``first_seq``; ``export`` is the kiosk's export identity, ``visit`` the
    session's ``visit`` log entry (``order ID`` for an ordered visit). The store is thrown away,
    unless ``data_dir`` names where to keep it (for the kiosk's own exports)."""
    import contextlib
    from dataclasses import replace

    from kiosk.commands.replay import load_script, run_script
    from kiosk.store.database import DB_NAME, Store

    loaded = load_script(script, questionnaire)
    if patient is not None:
        loaded = replace(loaded, patient=patient)
    kept = contextlib.nullcontext(str(data_dir)) if data_dir is not None else tempfile.TemporaryDirectory()
    with kept as directory:
        with Store.open(directory, outbox=True, export=export) as store:
            run_script(loaded, questionnaire, store=store, visit=visit)
        with sqlite3.connect(Path(directory) / DB_NAME) as connection:
            stored = connection.execute("SELECT kind, session_id, payload, at FROM outbox ORDER BY seq").fetchall()
    rows, t = [], 0.0
    for seq, (kind, session_id, payload, at) in enumerate(stored, first_seq):
        body = json.loads(payload)
        t = float(body.get("t", t))  # when the session wrote it (rows without a t follow the last one)
        rows.append(Row(seq, kind, session_id, body, t, at))
    return rows


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
        body = {
            "kiosk_id": self.kiosk_id,
            "at": None,
            "session_id": None,
            "patient_id": None,
            "phase": None,
            "question": None,
            "of": None,
            "paused": False,
            "person_away": False,
            "doctor_called": False,
            "simulated": True,
        } | fields
        return self.http.post("/api/v1/status", json=body)

    def commands(self, wait: float = 0.0) -> list[dict[str, Any]]:
        response = self.http.get("/api/v1/commands", params={"wait": wait}, timeout=wait + 30)
        response.raise_for_status()
        return response.json()["commands"]

    def orders(self, wait: float = 0.0, version: str | None = None) -> dict[str, Any]:
        params: dict[str, Any] = {"wait": wait} | ({"version": version} if version else {})
        response = self.http.get("/api/v1/orders", params=params, timeout=wait + 30)
        response.raise_for_status()
        return response.json()

    def start_order(self, code: str) -> httpx.Response:
        return self.http.post("/api/v1/orders/start", json={"code": code})

    def ack(self, command_id: int, result: str = "done", reason: str | None = None) -> httpx.Response:
        body = {"result": result} | ({"reason": reason} if reason else {})
        return self.http.post(f"/api/v1/commands/{command_id}/ack", json=body)
