"""What the station accepts of a kiosk's Timed Up and Go (a ``record_tug`` row, protocol:
docs/station-protocol.md, "Timed Up and Go"): every field checked before anything of its batch is
stored, so a bad row is one 422 naming the row and the field, never a 500 nor half a result.

The rules are the kiosk's own (:mod:`kiosk.core.tug.step`): a decision of accepted, stopwatch or
rejected; a time in (0, 600) s taken by the camera (accepted) or a stopwatch, none when rejected;
the Get Up & Go rating 1-5, the walking aid one of the kiosk's; a staffed visit only (an order or
staff), never a walk-up. Pure functions: no database, no web.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from basis import record
from kiosk.core.tug.analysis import PHASES, Phase
from kiosk.core.tug.step import DECISIONS, GET_UP_GO, WALKING_AIDS
from kiosk.store.database import PATIENT_ID
from station.checks import ID_MAX, RowRefused, check_identity, flag, integer, iso_time, number, one_of, text

REQUIRED = (
    "tug_id",
    "patient_id",
    "at",
    "confirmed_by",
    "decision",
    "decided_by",
    "total_s",
    "method",
    "phases",
    "reasons",
    "person_share",
    "body_cut_off",
    "turn_seen",
    "threshold_s",
)
#: the longest course a time may say (the kiosk's stopwatch rule: under 600 s)
MOST_S = 600.0
_ORDER = re.compile(r"^order [A-Za-z0-9_-]{1,32}\Z")
REASONS_MAX, REASON_MAX = 20, 500


@record
class CheckedTug:
    """A ``record_tug`` row's payload, checked."""

    tug_id: str
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
    export: Mapping[str, str] | None


def _fail(where: str, message: str) -> RowRefused:
    return RowRefused(f"{where}: {message}")


def _visit(value: Any, where: str) -> tuple[str | None, str | None]:
    """(kind, order id) from the visit entry: "order <id>", "staff", or None (not said)."""
    if value is None:
        return None, None
    text(value, where, ID_MAX + 6)
    if value == "staff":
        return "staff", None
    if _ORDER.match(value):
        return "order", value.partition(" ")[2]
    if value == "walk-up":
        raise _fail(where, "the Timed Up and Go is never given at a walk-up visit: it needs staff beside the patient")
    raise _fail(where, f"must be 'order <id>' or 'staff', got {value!r:.40}")


def _phases(value: Any, where: str) -> tuple[Phase, ...]:
    if not isinstance(value, list) or len(value) > len(PHASES):
        raise _fail(where, f"must be a list of at most {len(PHASES)} phases")
    phases = []
    for i, raw in enumerate(value):
        at = f"{where}[{i}]"
        if not isinstance(raw, dict):
            raise _fail(at, "must be an object with name, start_t and end_t")
        name = one_of(raw.get("name"), f"{at}.name", PHASES)
        start = number(raw.get("start_t"), f"{at}.start_t", -MOST_S, 86400.0)
        end = number(raw.get("end_t"), f"{at}.end_t", -MOST_S, 86400.0)
        if end < start:
            raise _fail(f"{at}.end_t", f"ends before it starts ({end:g} < {start:g})")
        phases.append(Phase(name=name, start_t=start, end_t=end))
    return tuple(phases)


def _time(p: Mapping[str, Any], where: str) -> tuple[str, float | None, str | None]:
    """The decision and the time it leaves: accepted is the camera's, stopwatch staff's, rejected none."""
    decision = one_of(p["decision"], f"{where}.decision", DECISIONS)
    if decision == "rejected":
        if p["total_s"] is not None or p["method"] is not None:
            raise _fail(f"{where}.total_s", "a rejected test has no time (total_s and method null)")
        return decision, None, None
    total = number(p["total_s"], f"{where}.total_s", 0.0, MOST_S)
    if not 0 < total < MOST_S:
        raise _fail(f"{where}.total_s", f"must be more than 0 and under {MOST_S:g} s, got {total:g}")
    method = {"accepted": "camera", "stopwatch": "stopwatch"}[decision]
    if p["method"] != method:
        raise _fail(f"{where}.method", f"a decision {decision!r} is timed by {method!r}, got {p['method']!r:.40}")
    return decision, total, method


def check_tug(payload: Mapping[str, Any], where: str, row_id: str) -> CheckedTug:
    """The row's payload checked (``where``: ``seq N: record_tug``; ``row_id`` the row's
    ``session_id``, which must be the result's ``tug_id``); RowRefused naming the field."""
    p = payload
    missing = [k for k in REQUIRED if k not in p]
    if missing:
        raise RowRefused(f"{where} without {', '.join(missing)}")
    tug_id = text(p["tug_id"], f"{where}.tug_id", ID_MAX, empty=False)
    if tug_id != row_id:
        raise _fail(f"{where}.tug_id", f"{tug_id!r:.70} in a row of {row_id!r:.70} (the row's session_id is its id)")
    if not isinstance(p["patient_id"], str) or not PATIENT_ID.match(p["patient_id"]):
        raise _fail(f"{where}.patient_id", "is not pseudonymous (2-64 letters, digits, '-' or '_')")
    visit_kind, order_id = _visit(p.get("visit"), f"{where}.visit")
    visit_id = p.get("visit_id")
    if visit_id is not None:
        text(visit_id, f"{where}.visit_id", ID_MAX, empty=False)
    decision, total, method = _time(p, where)
    camera = p.get("camera_total_s")
    if camera is not None:
        camera = number(camera, f"{where}.camera_total_s", 0.0, MOST_S)
    reasons = p["reasons"]
    if not isinstance(reasons, list) or len(reasons) > REASONS_MAX:
        raise _fail(f"{where}.reasons", f"must be a list of at most {REASONS_MAX} sentences")
    for name in ("confirmed_t", "go_t"):
        if p.get(name) is not None:
            number(p[name], f"{where}.{name}", 0.0, 365 * 86400.0)
    get_up_go = p.get("get_up_go")
    if get_up_go is not None:
        integer(get_up_go, f"{where}.get_up_go", min(GET_UP_GO), max(GET_UP_GO))
    aid = p.get("walking_aid")
    if aid is not None:
        one_of(aid, f"{where}.walking_aid", WALKING_AIDS)
    if "export" in p:
        check_identity(p["export"], f"{where}.export")
    threshold = number(p["threshold_s"], f"{where}.threshold_s", 0.0, MOST_S)
    if threshold <= 0:
        raise _fail(f"{where}.threshold_s", "must be more than 0 s")
    return CheckedTug(
        tug_id=tug_id,
        patient_id=p["patient_id"],
        at=iso_time(p["at"], f"{where}.at"),
        visit_kind=visit_kind,
        order_id=order_id,
        visit_id=visit_id,
        confirmed_by=text(p["confirmed_by"], f"{where}.confirmed_by", ID_MAX, empty=False),
        decision=decision,
        decided_by=text(p["decided_by"], f"{where}.decided_by", ID_MAX, empty=False),
        total_s=total,
        method=method,
        camera_total_s=camera,
        threshold_s=threshold,
        phases=_phases(p["phases"], f"{where}.phases"),
        reasons=tuple(text(r, f"{where}.reasons[{i}]", REASON_MAX) for i, r in enumerate(reasons)),
        person_share=number(p["person_share"], f"{where}.person_share", 0.0, 1.0),
        body_cut_off=flag(p["body_cut_off"], f"{where}.body_cut_off"),
        turn_seen=flag(p["turn_seen"], f"{where}.turn_seen"),
        get_up_go=get_up_go,
        walking_aid=aid,
        simulated=flag(p.get("simulated", False), f"{where}.simulated"),
        export=p.get("export"),
    )
