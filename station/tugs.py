"""Timed Up and Go results at the station: stored as the kiosks send them (``record_tug`` rows,
checked by :mod:`station.tug_checks`), read back for the pages, the print view and the exports.

A result is its own record, not a session: it has no questions, no definition and nothing for a
doctor to correct or sign off -- staff decided at the kiosk (accepted the camera's time, entered a
stopwatch time, or rejected it), and who did is kept. It belongs to a visit: its order (when the
visit was ordered) and the kiosk's visit id, which the visit's questionnaire sessions name in
their ``battery`` log entry, so a session's page shows the TUG of the same visit.

The wording is the kiosk's: "above the site's threshold", never a diagnosis.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from basis import record
from kiosk.core.tug.analysis import Phase
from kiosk.export.tug import PHASE_NAMES, TugTime
from station import db
from station.db import sessions, tug_results, visits
from station.sessions import rows_of
from station.tug_checks import CheckedTug

DECISION_WORDS = {
    "accepted": "accepted the camera's time",
    "stopwatch": "entered a stopwatch time",
    "rejected": "rejected the test (no time)",
}


class TugClash(ValueError):
    """A result id already stored from another row (another kiosk, or another seq)."""


@record
class StationTug:
    """One stored Timed Up and Go, as the pages and exports read it."""

    id: str
    kiosk_id: str
    patient_id: str
    at: str
    visit_kind: str | None
    order_id: str | None
    visit_id: str | None
    confirmed_by: str
    decision: str
    decided_by: str
    total_s: float | None
    method: str | None
    camera_total_s: float | None
    threshold_s: float
    phases: tuple[Phase, ...]
    reasons: tuple[str, ...]
    person_share: float
    body_cut_off: bool
    turn_seen: bool
    get_up_go: int | None
    walking_aid: str | None
    simulated: bool
    export: Mapping[str, str]

    @property
    def above_threshold(self) -> bool | None:
        return None if self.total_s is None else self.total_s > self.threshold_s

    @property
    def wording(self) -> str:
        """The time and where it stands against the site's threshold (never a diagnosis)."""
        if self.total_s is None:
            return "No time taken (rejected)."
        side = "above" if self.above_threshold else "not above"
        return f"{self.total_s:.1f} s, {side} the site's threshold ({self.threshold_s:g} s)."

    @property
    def method_words(self) -> str:
        return {"camera": "timed by the kiosk's camera", "stopwatch": "timed by staff with a stopwatch"}.get(
            self.method or "", "no time"
        )

    @property
    def decision_words(self) -> str:
        return f"{self.decided_by} {DECISION_WORDS.get(self.decision, self.decision)}"

    @property
    def phase_rows(self) -> list[tuple[str, float]]:
        """(name in words, seconds) per phase the camera saw."""
        return [(PHASE_NAMES.get(p.name, p.name), p.duration_s) for p in self.phases]

    @property
    def flags(self) -> list[str]:
        """The camera's quality, in words: share of frames with a person, body cut off, turn seen,
        and why its analysis was not valid."""
        found = [f"a person in {self.person_share:.0%} of the frames"]
        found.append("body cut off (legs not seen)" if self.body_cut_off else "whole body seen")
        found.append("turn seen" if self.turn_seen else "turn not seen")
        return found + list(self.reasons)

    def time(self) -> TugTime | None:
        """The result for :mod:`kiosk.export.tug` (None when rejected: no time to export)."""
        if self.total_s is None or self.method is None:
            return None
        return TugTime(
            result_id=self.id,
            patient_id=self.patient_id,
            total_s=self.total_s,
            method=self.method,
            effective=self.at,
            phases=self.phases if self.method == "camera" else (),
            accepted_by=self.decided_by,
            get_up_go=self.get_up_go,
            walking_aid=self.walking_aid,
            threshold_s=self.threshold_s,
        )


def store(connection: Connection, kiosk_id: str, seq: int, tug: CheckedTug, received: float) -> None:
    """Store a checked result from ``kiosk_id``'s row ``seq`` (in the sync's transaction); the
    same row again stores nothing, the same id from another row is :class:`TugClash`."""
    if connection.execute(sa.select(sessions.c.id).where(sessions.c.id == tug.tug_id)).first() is not None:
        raise TugClash(f"seq {seq}: record_tug.tug_id: {tug.tug_id} is a session's id, not a new result's")
    known = connection.execute(
        sa.select(tug_results.c.kiosk_id, tug_results.c.seq).where(tug_results.c.id == tug.tug_id)
    ).first()
    if known is not None:
        if (known.kiosk_id, known.seq) != (kiosk_id, seq):
            raise TugClash(f"seq {seq}: Timed Up and Go {tug.tug_id} was stored already from {known.kiosk_id}")
        return
    db.insert_ignore(
        connection,
        tug_results,
        [
            {
                "id": tug.tug_id,
                "kiosk_id": kiosk_id,
                "seq": seq,
                "patient_id": tug.patient_id,
                "at": tug.at,
                "visit_kind": tug.visit_kind,
                "order_id": tug.order_id,
                "visit_id": tug.visit_id,
                "confirmed_by": tug.confirmed_by,
                "decision": tug.decision,
                "decided_by": tug.decided_by,
                "total_s": tug.total_s,
                "method": tug.method,
                "camera_total_s": tug.camera_total_s,
                "threshold_s": tug.threshold_s,
                "phases": json.dumps([[p.name, p.start_t, p.end_t] for p in tug.phases]),
                "reasons": json.dumps(list(tug.reasons)),
                "person_share": tug.person_share,
                "body_cut_off": tug.body_cut_off,
                "turn_seen": tug.turn_seen,
                "get_up_go": tug.get_up_go,
                "walking_aid": tug.walking_aid,
                "simulated": tug.simulated,
                "export": json.dumps(dict(tug.export), sort_keys=True) if tug.export else None,
                "received_at": received,
            }
        ],
        ["id"],
    )


def of_row(row: Any) -> StationTug:
    """A stored row as a :class:`StationTug`."""
    values = dict(row._mapping)
    values.pop("seq"), values.pop("received_at")
    values["phases"] = tuple(Phase(name=n, start_t=a, end_t=b) for n, a, b in json.loads(values["phases"]))
    values["reasons"] = tuple(json.loads(values["reasons"]))
    values["export"] = json.loads(values["export"]) if values["export"] else {}
    values["body_cut_off"], values["turn_seen"] = bool(values["body_cut_off"]), bool(values["turn_seen"])
    values["simulated"] = bool(values["simulated"])
    return StationTug(**values)


def get(engine: Engine, tug_id: str) -> StationTug | None:
    with engine.connect() as connection:
        row = connection.execute(sa.select(tug_results).where(tug_results.c.id == tug_id)).first()
    return of_row(row) if row is not None else None


def of_patient(connection: Connection, patient_id: str) -> list[StationTug]:
    """The patient's results, oldest first."""
    query = sa.select(tug_results).where(tug_results.c.patient_id == patient_id)
    return [of_row(r) for r in connection.execute(query.order_by(tug_results.c.at, tug_results.c.id))]


def patient_course(engine: Engine, patient_id: str) -> list[StationTug]:
    with engine.connect() as connection:
        return of_patient(connection, patient_id)


def visit_id_of(connection: Connection, session_id: str) -> str | None:
    """The kiosk's visit id a session names in its ``battery`` log entry (None: none)."""
    for row in rows_of(connection, session_id, ["record_event"]):
        if row.payload.get("kind") == "battery":
            return str(row.payload.get("detail", "")).partition(" ")[0] or None
    return None


def of_sessions(connection: Connection, session_ids: Sequence[str]) -> list[StationTug]:
    """The results of the visits these sessions belong to (their order, or their kiosk visit id),
    oldest first, each once."""
    ordered = sa.select(visits.c.order_id).where(
        visits.c.session_id.in_(list(session_ids)), visits.c.order_id.is_not(None)
    )
    orders = set(connection.execute(ordered).scalars())
    visit_ids = {v for v in (visit_id_of(connection, s) for s in session_ids) if v}
    wanted = []
    if orders:
        wanted.append(tug_results.c.order_id.in_(sorted(orders)))
    if visit_ids:
        wanted.append(tug_results.c.visit_id.in_(sorted(visit_ids)))
    if not wanted:
        return []
    query = sa.select(tug_results).where(sa.or_(*wanted)).order_by(tug_results.c.at, tug_results.c.id)
    return [of_row(r) for r in connection.execute(query)]


def of_session(engine: Engine, session_id: str) -> list[StationTug]:
    with engine.connect() as connection:
        return of_sessions(connection, [session_id])


def of_order(engine: Engine, order_id: str) -> list[StationTug]:
    with engine.connect() as connection:
        query = sa.select(tug_results).where(tug_results.c.order_id == order_id).order_by(tug_results.c.at)
        return [of_row(r) for r in connection.execute(query)]
