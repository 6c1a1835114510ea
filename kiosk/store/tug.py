"""Timed Up and Go results in the kiosk's database (table ``tug_results``, schema version 4).

One row per test a visit gave: the time staff took (camera or stopwatch) or none (rejected), the
camera's own time, phases, quality flags, who confirmed being beside the patient and who decided,
the staff items, the site's threshold then. Never a picture; the landmarks (pose-landmarks/1
text) only when the site keeps them. Why a table of its own: a TUG has no questions, so it fits
none of a questionnaire session's rows.

With a station configured each result is queued in the same transaction as one outbox row of
kind ``record_tug`` (its ``session_id`` is the result's id; docs/station-protocol.md, "Timed Up
and Go"): the visit it belongs to, the time, phases, flags and decisions; never the landmarks.
"""

from __future__ import annotations

import json
import sqlite3
import uuid
from collections.abc import Mapping
from typing import Any

from basis import record
from kiosk.core.tug.analysis import Phase
from kiosk.core.tug.landmarks import dump_pose_lines
from kiosk.core.tug.step import TugResult
from kiosk.store.transactions import Transactions

COLUMNS = (
    "id",
    "patient_id",
    "visit_id",
    "at",
    "confirmed_by",
    "confirmed_t",
    "go_t",
    "decision",
    "decided_by",
    "total_s",
    "method",
    "camera_total_s",
    "phases",
    "reasons",
    "person_share",
    "body_cut_off",
    "turn_seen",
    "threshold_s",
    "get_up_go",
    "walking_aid",
    "landmarks",
)


@record
class StoredTug:
    """One stored Timed Up and Go: ``result`` as the step gave it (landmarks as their file text)."""

    id: str
    patient_id: str
    visit_id: str | None
    at: str
    result: TugResult
    landmarks_text: str | None = None


class TugResults:
    """Writes and reads ``tug_results`` (``store.tug``); ``export`` and ``simulated`` are the
    store's identity and test-data mark, sent to the station with each result."""

    def __init__(
        self,
        tx: Transactions,
        db: sqlite3.Connection,
        *,
        export: Mapping[str, str] | None = None,
        simulated: bool = False,
    ) -> None:
        self._tx, self._db = tx, db
        self._export, self._simulated = dict(export or {}), simulated

    def record(
        self,
        patient_id: str,
        result: TugResult,
        *,
        visit_id: str | None = None,
        at: str | None = None,
        visit: str | None = None,
    ) -> str:
        """Store ``result`` for ``patient_id`` (``at``: when, ISO 8601; None: now); returns its id.

        ``visit_id`` is the kiosk's visit (a battery's); ``visit`` how the visit began, as the
        session log's ``visit`` entry says (``order <id>`` or ``staff``; kiosk.core.visits): the
        station files the result under that order. Queues the ``record_tug`` outbox row."""
        at = at or self._tx.iso_now()
        tug_id = str(uuid.uuid4())
        phases = json.dumps([[p.name, p.start_t, p.end_t] for p in result.phases])
        landmarks = "\n".join(dump_pose_lines(result.landmarks)) + "\n" if result.landmarks is not None else None
        row = (
            tug_id,
            patient_id,
            visit_id,
            at,
            result.confirmed_by,
            result.confirmed_t,
            result.go_t,
            result.decision,
            result.decided_by,
            result.total_s,
            result.method,
            result.camera_total_s,
            phases,
            json.dumps(list(result.reasons)),
            result.person_share,
            int(result.body_cut_off),
            int(result.turn_seen),
            result.threshold_s,
            result.get_up_go,
            result.walking_aid,
            landmarks,
        )
        with self._tx.transaction():
            self._tx.write("INSERT OR IGNORE INTO patients (id, created_at) VALUES (?, ?)", (patient_id, at))
            self._tx.write(f"INSERT INTO tug_results VALUES ({', '.join('?' * len(COLUMNS))})", row)
            payload = tug_payload(tug_id, patient_id, result, at=at, visit_id=visit_id, visit=visit)
            payload |= {"simulated": self._simulated, **({"export": self._export} if self._export else {})}
            self._tx.queue("record_tug", tug_id, payload)
        return tug_id

    def all(self, patient_id: str | None = None) -> list[StoredTug]:
        """The stored results, oldest first (of one patient when given)."""
        where, args = ("WHERE patient_id = ?", (patient_id,)) if patient_id is not None else ("", ())
        rows = self._db.execute(f"SELECT {', '.join(COLUMNS)} FROM tug_results {where} ORDER BY at, id", args)
        return [_stored(dict(zip(COLUMNS, row, strict=True))) for row in rows.fetchall()]


def tug_payload(
    tug_id: str, patient_id: str, result: TugResult, *, at: str, visit_id: str | None, visit: str | None
) -> dict[str, Any]:
    """The ``record_tug`` row's payload (protocol: docs/station-protocol.md): everything the
    station shows and exports, never the landmarks."""
    return {
        "tug_id": tug_id,
        "patient_id": patient_id,
        "at": at,
        "visit": visit,
        "visit_id": visit_id,
        "confirmed_by": result.confirmed_by,
        "confirmed_t": result.confirmed_t,
        "go_t": result.go_t,
        "decision": result.decision,
        "decided_by": result.decided_by,
        "total_s": result.total_s,
        "method": result.method,
        "camera_total_s": result.camera_total_s,
        "phases": [{"name": p.name, "start_t": p.start_t, "end_t": p.end_t} for p in result.phases],
        "reasons": list(result.reasons),
        "person_share": result.person_share,
        "body_cut_off": result.body_cut_off,
        "turn_seen": result.turn_seen,
        "threshold_s": result.threshold_s,
        "get_up_go": result.get_up_go,
        "walking_aid": result.walking_aid,
    }


def _stored(row: dict[str, Any]) -> StoredTug:
    result = TugResult(
        confirmed_by=row["confirmed_by"],
        confirmed_t=row["confirmed_t"],
        go_t=row["go_t"],
        decision=row["decision"],
        decided_by=row["decided_by"],
        total_s=row["total_s"],
        method=row["method"],
        camera_total_s=row["camera_total_s"],
        phases=tuple(Phase(name=n, start_t=a, end_t=b) for n, a, b in json.loads(row["phases"])),
        reasons=tuple(json.loads(row["reasons"])),
        person_share=row["person_share"],
        body_cut_off=bool(row["body_cut_off"]),
        turn_seen=bool(row["turn_seen"]),
        threshold_s=row["threshold_s"],
        get_up_go=row["get_up_go"],
        walking_aid=row["walking_aid"],
    )
    return StoredTug(
        id=row["id"],
        patient_id=row["patient_id"],
        visit_id=row["visit_id"],
        at=row["at"],
        result=result,
        landmarks_text=row["landmarks"],
    )
