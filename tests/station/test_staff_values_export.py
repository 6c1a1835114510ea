"""Numbers staff enter at the station leave it as entered (issue 36, "nothing lost on the way out"):
a session of an instrument with a staff-measured weight arrives from a real kiosk store's outbox;
a nurse enters the weight at the station, fills the staff choice, a doctor signs off; the result's
FHIR Bundle (checked by the R4 schema and fhir.resources), the period's Bundle and the long and
wide CSV all carry the weight exactly as typed and the total, on SQLite and PostgreSQL."""

from __future__ import annotations

import csv
import io
from datetime import UTC, datetime

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.staff import entered_at_station, entry_text
from kiosk.export import wide_rows
from station import db, exports, staff_items, sync, validation
from station.auth import User
from station.validation import AuditEntry
from tests.kiosk.export.standard import check_fhir
from tests.kiosk.ui.test_six_options import SIX
from tests.station.test_staff_items import _rows

pytestmark = pytest.mark.slow

NURSE, DOCTOR = User("nurse.kim", "nurse"), User("dr.lopez", "doctor")


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request, tmp_path):
    url = db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _resources(bundle: dict, kind: str) -> list[dict]:
    return [e["resource"] for e in bundle.get("entry", []) if e["resource"]["resourceType"] == kind]


def test_a_weight_entered_at_the_station_is_in_every_export_as_typed(engine, tmp_path):
    rows = _rows(tmp_path, kiosk_weight=None)
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": [r.event() for r in rows]}))
    session_id = rows[0].session_id
    q = load_questionnaire(tmp_path / "walking.yaml")
    staff_items.enter_value(engine, q, session_id, "weight", " 72,123456 ", NURSE)
    validation.change_item(engine, q, session_id, "aid", 1, "no aid seen on the ward", NURSE)
    validation.sign_off(engine, session_id, DOCTOR)
    assert [e.reason for e in validation.trail(engine, session_id) if e.action == "enter"] == ["72.123456"]

    bundle = exports.result_bundle(engine, q, session_id)
    check_fhir(bundle)
    (response,) = _resources(bundle, "QuestionnaireResponse")
    answers = {i["linkId"]: i["answer"][0] for i in response["item"]}
    assert answers["weight"] == {"valueDecimal": 72.123456}
    assert answers["total"] == {"valueInteger": 5}  # steps 2 + stairs 3 + aid 0
    assert response["status"] == "amended"  # the aid was filled at the station: not the kiosk's answers
    (total,) = _resources(bundle, "Observation")
    assert total["valueQuantity"]["value"] == 5 and total["status"] == "amended"

    today = datetime.now(UTC).date()
    period = exports.period_bundle(engine, q, today, today)
    check_fhir(period)
    (again,) = _resources(period, "QuestionnaireResponse")
    assert {i["linkId"]: i["answer"][0] for i in again["item"]}["weight"] == {"valueDecimal": 72.123456}
    assert len(_resources(period, "Observation")) == 1

    long = {row["item"]: row for row in csv.DictReader(io.StringIO(exports.result_csv(engine, q, session_id)))}
    assert (long["weight"]["value"], long["weight"]["unit"], long["weight"]["label"]) == (
        "72.123456",
        "kg",
        "72.123456 kg",
    )
    assert long["total"]["points"] == "5" and long["total"]["complete"] == "true"

    with engine.connect() as connection:
        described = exports._described(connection, q, session_id)
    (wide,) = csv.DictReader(io.StringIO(wide_rows(q, [described.result], described.site)))
    assert (wide["weight_value"], wide["total"], wide["band"]) == ("72.123456", "5", "high")


def test_a_large_whole_number_is_kept_whole_and_an_exponent_is_refused(tmp_path):
    (tmp_path / "grams.yaml").write_text(
        SIX.replace(
            "input: {type: decimal, min: 20, max: 250, unit: kg}",
            "input: {type: integer, min: 0, max: 9999999, unit: g}",
        ),
        encoding="utf-8",
    )
    q = load_questionnaire(tmp_path / "grams.yaml")
    weight = q.item("weight")
    assert entry_text(weight, "1234567") == "1234567"  # once stored as %g: 1.23457e+06, then ignored
    step = AuditEntry("2026-01-01T00:00:00Z", "nurse.kim", "enter", "weight", None, None, "1234567")
    assert entered_at_station(q, [step]) == {"weight": 1234567}
    for typed, why in (("1e6", "is not a whole number from 0 to 9999999 g"), ("12.5", "is not a whole number")):
        with pytest.raises(ValueError, match=why):
            entry_text(weight, typed)
