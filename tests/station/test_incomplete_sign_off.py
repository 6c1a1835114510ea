"""A result with unanswered items is signed off only as incomplete, with a reason (issue 36): the
station refuses a plain sign-off naming the items, stores the doctor's reason with the sign-off,
and every export says so (the response ``stopped`` with the reason, a ``final`` total Observation
with a ``dataAbsentReason`` and no value, the CSV's ``incomplete_reason``), on SQLite and
PostgreSQL; the sign-off step asks for the reason in a required field."""

from __future__ import annotations

import csv
import io
import re

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.export import wide_rows
from kiosk.export.fhir import INCOMPLETE
from station import db, exports, sync, validation
from station.auth import User
from tests.kiosk.export.standard import check_fhir
from tests.station.conftest import shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import Staff
from tests.station.test_staff_items import _rows, _sync

pytestmark = pytest.mark.slow

NURSE, DOCTOR = User("nurse.kim", "nurse"), User("dr.lopez", "doctor")
REASON = "patient too tired to go on; not to be repeated"


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request, tmp_path):
    url = db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _resources(bundle: dict, kind: str) -> list[dict]:
    return [e["resource"] for e in bundle.get("entry", []) if e["resource"]["resourceType"] == kind]


def test_an_incomplete_result_is_signed_off_only_as_such_and_exported_so(engine, tmp_path):
    rows = _rows(tmp_path, kiosk_weight=None)
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": [r.event() for r in rows]}))
    session_id = rows[0].session_id
    q = load_questionnaire(tmp_path / "walking.yaml")
    with pytest.raises(
        validation.ValidationError, match=r"2 items not answered \(weight, aid\): sign off as incomplete"
    ):
        validation.sign_off(engine, session_id, DOCTOR, incomplete="   ")
    assert not validation.review(engine, session_id).final  # nothing stored
    assert validation.sign_off(engine, session_id, DOCTOR, incomplete=f"  {REASON} ") == REASON
    review = validation.review(engine, session_id)
    assert review.final and review.incomplete == REASON

    bundle = exports.result_bundle(engine, q, session_id)
    check_fhir(bundle)
    (response,) = _resources(bundle, "QuestionnaireResponse")
    assert response["status"] == "stopped"
    (why,) = [e["valueString"] for e in response["extension"] if e["url"] == INCOMPLETE]
    assert why == f"signed off incomplete (incomplete until staff answer weight, aid): {REASON}"
    assert "total" not in {i["linkId"] for i in response["item"]}
    (total,) = _resources(bundle, "Observation")
    assert total["status"] == "final" and "valueQuantity" not in total
    assert total["dataAbsentReason"]["text"] == why

    long = list(csv.DictReader(io.StringIO(exports.result_csv(engine, q, session_id))))
    assert {r["incomplete_reason"] for r in long} == {REASON}
    assert {r["review_state"] for r in long} == {"signed_off"} and {r["complete"] for r in long} == {"false"}
    with engine.connect() as connection:
        described = exports._described(connection, q, session_id)
    (wide,) = csv.DictReader(io.StringIO(wide_rows(q, [described.result], described.site)))
    assert (wide["incomplete_reason"], wide["total"], wide["missing"]) == (REASON, "", "weight aid")


def test_a_complete_result_is_signed_off_with_no_reason_kept(engine, tmp_path):
    rows = _rows(tmp_path, kiosk_weight=64.0)
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": [r.event() for r in rows]}))
    session_id = rows[0].session_id
    q = load_questionnaire(tmp_path / "walking.yaml")
    validation.change_item(engine, q, session_id, "aid", 2, "uses a stick", NURSE)
    assert validation.sign_off(engine, session_id, DOCTOR, incomplete="stray words") == ""
    bundle = exports.result_bundle(engine, q, session_id)
    check_fhir(bundle)
    (total,) = _resources(bundle, "Observation")
    assert total["valueQuantity"]["value"] == 6 and "dataAbsentReason" not in total


def test_the_sign_off_step_asks_for_the_reason(shared_station, tmp_path):
    station, ward = shared_station
    session_id = _sync(station, ward, _rows(tmp_path, kiosk_weight=None))
    doctor = Staff(station.url, name="dr.lopez", role="doctor")
    step = doctor.http.get(f"/sessions/{session_id}/sign-off")
    assert step.status_code == 200, step.text[:2000]
    assert re.search(r'<textarea id="incomplete-reason" name="incomplete_reason" required', step.text)
    assert "Not answered: Weight, Uses a walking aid." in step.text
    assert re.search(r'id="confirm-sign-off">Sign off as incomplete</button>', step.text)
    refused = doctor.post(f"/sessions/{session_id}/sign-off")
    back = doctor.http.get(refused.headers["location"])
    assert "2 items not answered (weight, aid): sign off as incomplete" in back.text, back.text[:3000]
    signed = doctor.post(f"/sessions/{session_id}/sign-off", incomplete_reason=REASON)
    assert "Signed off as incomplete." in doctor.http.get(signed.headers["location"]).text
    engine = db.open_database(ward.db_url)
    try:
        assert validation.review(engine, session_id).incomplete == REASON
    finally:
        engine.dispose()
