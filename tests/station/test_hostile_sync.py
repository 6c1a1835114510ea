"""Generated sync bodies, hostile but plausible, thrown at a real `kiosk station` process over
HTTP on 127.0.0.1, on SQLite and on PostgreSQL: each body is either stored, and then the
session's page, its FHIR export and its CSV answer 200, or refused with a 4xx naming the row --
never a 500. The bodies start from a real replayed session (the kiosk's own outbox rows, with
its captured definition) and change a few fields the way a site's own questionnaire, a kiosk
bug or an attacker would: a language the questionnaire lacks, option 99, unknown items and
channels, times as text, other questionnaires (with and without their own definition), long
strings, unicode."""

from __future__ import annotations

import copy
import itertools
import json
import uuid
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote

import httpx
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from bench._postgres import create_database
from kiosk.core.questionnaire.definition import digest
from station import db
from tests.station.conftest import make_ward, start_station
from tests.station.helpers import PATIENTS, Staff, record_patient

pytestmark = pytest.mark.slow

#: a real session: a patient who leaves two items unanswered (finished, English, no practice)
BASE = record_patient(PATIENTS / "barthel4.yaml")
SEQ = itertools.count(1)

LONG = "ẞ" * 70
TEXTS = st.one_of(
    st.sampled_from(["", "x" * 65, "x" * 5000, "اختبار", "e\u0301", "\ud800", "\x00", LONG, "🙂" * 30]),
    st.text(max_size=80),
)
TIMES = st.sampled_from(
    [
        "yesterday",
        "2026-13-45T99:99:99Z",
        "2026-01-01T00:00:02.000000000000000+00:00:00Z",
        "1026-01-01T00:00:00Z",
        "2026-01-01",
        "",
        "2026-01-01T00:00:00+05:30",
        12,
    ]
)
VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-5, 120), st.sampled_from([99, 2.5, 1e308, "2", [], {}]), TEXTS
)

#: (where, strategy of the new value); "answer.*" is a record_answer's field, "create.*" create_session's
FIELDS = {
    "create.language": st.sampled_from(["de", "en", "es", "fr", "EN", "", "xx-YY"]),
    "create.questionnaire_id": st.sampled_from(["katz", "barthel", "", "x" * 80]),
    "create.answered_by": st.sampled_from(["patient", "nurse", "", 3]),
    "create.started_at": TIMES,
    "create.patient_id": st.sampled_from(["P-1", "Ann Smith", "P-" + "9" * 70, "P-ÄÖÜ"]),
    "create.timing": st.sampled_from([{}, {"attempt_window_s": -1}, {"nope": 1}, "fast"]),
    "create.export": st.sampled_from(
        [
            {"site": "other site"},
            {"kiosk_id": "k/1"},
            {"patient_system": "no uri"},
            {"site": "x" * 300},
            "nope",
            {"site": "north", "kiosk_id": "k1"},
        ]
    ),
    "answer.option": st.sampled_from([0, 1, 2, 3, 4, 99, -1, "2", None, 2.5, True]),
    "answer.points": VALUES,
    "answer.item_id": st.sampled_from(["feeding", "nonexistent", "", "x" * 100, "bathing", "total"]),
    "answer.channel": st.sampled_from(["voice", "touch", "remote", "carrier-pigeon", "", None]),
    "answer.attempt": VALUES,
    "answer.t": st.sampled_from(["soon", -1, 1e12, float("inf"), 3.5, None]),
    "answer.at": TIMES,
    "answer.detail": TEXTS,
    "event.kind": TEXTS,
    "event.detail": TEXTS,
    "event.t": VALUES,
    "finish.finished_at": TIMES,
    "finish.band": VALUES,
    "row.at": TIMES,
    "row.kind": st.sampled_from(["record_sneeze", "mark_interrupted", "continue_session", "abandon", "ü" * 70]),
    "row.session_id": st.sampled_from(["", "s" * 65, "other-session"]),
    "context.set": st.sampled_from([{"PersonDetected": "yes"}, {"": 1}, {"x": [1]}, {"x" * 70: 1}, []]),
    "metrics.metrics": st.sampled_from([{"Performance": "high"}, {"Performance": 1e300}, {}, []]),
}
#: whole-definition changes: a site's own questionnaire (consistent, so it must be stored and shown),
#: an old kiosk that sends none, and definitions that do not fit
DEFINITIONS = st.sampled_from(
    ["own questionnaire", "none sent", "language dropped", "wrong hash", "no items", "German added", "as recorded"]
)


def _retarget(rows: list, session_id: str) -> list:
    """The base session as a new one: its own session id, patient and seqs."""
    patient = "P-" + uuid.uuid4().hex[:8].upper()
    fresh = []
    for row in rows:
        payload = copy.deepcopy(row.payload)
        if row.kind == "create_session":
            payload.update(session_id=session_id, patient_id=patient)
        fresh.append({"seq": next(SEQ), "kind": row.kind, "session_id": session_id, "at": row.at, "payload": payload})
    return fresh


def _definition(create: dict, how: str) -> None:
    payload = create["payload"]
    definition = payload["definition"]
    if how == "own questionnaire":
        definition |= {"id": "site-adl", "title": {lang: f"Site ADL ({lang})" for lang in definition["languages"]}}
        definition["items"][0]["text"] = {lang: "¿Come solo? 🍽" for lang in definition["languages"]}
        definition["items"][1]["options"][0]["label"]["en"] = "Needs help (site wording)"
        payload["questionnaire_id"] = "site-adl"
    elif how == "none sent":
        del payload["definition"], payload["definition_sha256"]
        return
    elif how == "language dropped":
        del definition["items"][2]["text"]["fr"]
    elif how == "no items":
        definition["items"] = []
    elif how == "German added":
        definition["languages"] = [*definition["languages"], "de"]
    if how != "wrong hash":
        payload["definition_sha256"] = digest(definition)


def _mutate(rows: list, field: str, value, pick: int) -> None:
    part, name = field.split(".")
    kinds = {
        "create": "create_session",
        "answer": "record_answer",
        "event": "record_event",
        "finish": "finish_session",
        "context": "record_context",
        "metrics": "record_metrics",
    }
    targets = rows if part == "row" else [r for r in rows if r["kind"] == kinds[part]]
    if not targets:  # an earlier change renamed the only row of that kind
        return
    target = targets[pick % len(targets)]
    if part == "row":
        target[name] = value
    else:
        target["payload"][name] = value


@st.composite
def bodies(draw) -> tuple[str, dict]:
    session_id = uuid.uuid4().hex[:12]
    rows = _retarget(BASE, session_id)
    _definition(rows[0], draw(DEFINITIONS))
    for field in draw(st.lists(st.sampled_from(sorted(FIELDS)), max_size=3)):
        _mutate(rows, field, draw(FIELDS[field]), draw(st.integers(0, 60)))
    cut = draw(st.sampled_from([len(rows), len(rows), 1, len(rows) // 2]))  # whole session, or its start
    return session_id, {"kiosk_id": "ward3-bed2", "events": rows[:cut]}


@pytest.fixture(scope="module", params=["sqlite", "postgresql"])
def ward_station(request, tmp_path_factory) -> Iterator[tuple[str, str, Staff]]:
    base: Path = tmp_path_factory.mktemp("hostile")
    if request.param == "sqlite":
        db_url = db.sqlite_url(base / "data")
    else:
        db_url = create_database(request.getfixturevalue("postgres"), "h_" + uuid.uuid4().hex[:12])
    ward = make_ward(db_url)
    station = start_station(db_url, base / "station.log")
    staff = Staff(station.url)
    try:
        yield station.url, ward.token, staff
    finally:
        staff.http.close()
        station.stop()
        assert "Traceback" not in (base / "station.log").read_text(), (base / "station.log").read_text()


@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture, HealthCheck.data_too_large],
)
@given(body=bodies())
def test_a_sync_body_is_stored_and_shown_or_refused_never_a_500(ward_station, body):
    url, token, staff = ward_station
    session_id, payload = body
    answer = httpx.post(
        url + "/api/v1/sync",
        content=json.dumps(payload),
        timeout=60,  # ASCII: lone surrogates too
        headers={"Authorization": f"Bearer {token}", "content-type": "application/json"},
    )
    assert answer.status_code == 200 or 400 <= answer.status_code < 500, answer.text
    event(f"answered {answer.status_code}")
    if answer.status_code != 200:
        assert answer.json()["error"].startswith(  # it names the row, or what of the body is wrong
            ("seq ", "events[", "the body", "the request body", "a seq", "at most")
        ), answer.text
        return
    created = any(e["kind"] == "create_session" for e in payload["events"])
    page = staff.http.get(f"/sessions/{session_id}")
    assert page.status_code == 200, page.text[:2000]
    for fmt in ("json", "csv"):
        export = staff.http.get(f"/sessions/{session_id}/export.{fmt}")
        assert export.status_code == 200 or (not created and export.status_code == 409), export.text[:2000]
    # the pages that list or follow it: the ward, the inbox, its patient's course, the sign-off step
    patient = next((e["payload"].get("patient_id") for e in payload["events"] if e["kind"] == "create_session"), None)
    pages = [
        "/",
        "/fragments/results",
        "/inbox?state=all",
        "/fragments/inbox?state=all",
        "/orders",
        f"/sessions/{session_id}/sign-off",
        "/exports/signed-off.json?from=2000-01-01&to=2100-12-31",
    ]
    if isinstance(patient, str) and patient:
        pages += [f"/patients?q={quote(patient)}", f"/patients/{quote(patient, safe='')}"]
    for path in pages:
        shown = staff.http.get(path)
        assert shown.status_code in (200, 303, 404), (path, shown.status_code, shown.text[:2000])
    # signed off (where it can be), it still renders and exports, alone and in the period's Bundle
    signed = staff.post(f"/sessions/{session_id}/sign-off")
    assert signed.status_code == 303, signed.text[:2000]
    event("signed off" if "Signed%20off." in signed.headers["location"] else "not signed off")
    for path in [*pages, f"/sessions/{session_id}", f"/sessions/{session_id}/export.json"]:
        shown = staff.http.get(path)
        assert shown.status_code in (200, 303, 404) or (not created and shown.status_code == 409), (
            path,
            shown.status_code,
            shown.text[:2000],
        )
