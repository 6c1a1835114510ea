"""Amending a signed result and exporting the results signed off in a period, on both engines
(SQLite and the real PostgreSQL of the shared fixture): the audit trail keeps every step, a
reopened result leaves the period's export until it is signed again, and the Bundles are valid R4."""

from __future__ import annotations

import csv
import io
from datetime import UTC, date, datetime, timedelta

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.review import ReviewState
from station import db, exports, sync, validation
from station.auth import User
from tests.kiosk.export.standard import check_fhir
from tests.station.helpers import PATIENTS, record_patient

NURSE, DOCTOR = User("nurse.kim", "nurse"), User("dr.lopez", "doctor")


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request, tmp_path):
    url = db.sqlite_url(tmp_path / "data") if request.param == "sqlite" else request.getfixturevalue("pg_url")
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def _ingest(engine, script: str, first_seq: int = 1) -> str:
    rows = record_patient(PATIENTS / script, first_seq=first_seq)
    with engine.begin() as connection:
        sync.intake(connection, "bed1", sync.parse({"events": [r.event() for r in rows]}))
    return rows[0].session_id


def _states(table: str) -> set[str]:
    return {row["review_state"] for row in csv.DictReader(io.StringIO(table))}


def _responses(bundle: dict) -> dict[str, dict]:
    return {
        e["resource"]["identifier"]["value"].rsplit("/", 1)[1]: e
        for e in bundle.get("entry", [])
        if e["resource"]["resourceType"] == "QuestionnaireResponse"
    }


def test_amending_keeps_every_step_and_the_period_export_follows_the_sign_offs(engine):
    q = load_questionnaire()
    today = datetime.now(UTC).date()
    signed, unsigned = _ingest(engine, "barthel1.yaml"), _ingest(engine, "barthel2.yaml", first_seq=1000)
    validation.sign_off(engine, signed, DOCTOR)
    validation.change_item(engine, q, unsigned, "feeding", 1, "checked at lunch", NURSE)
    assert set(_responses(exports.period_bundle(engine, q, today, today))) == {signed}
    assert exports.period_bundle(engine, q, today - timedelta(days=3), today - timedelta(days=1)) == {
        "resourceType": "Bundle",
        "type": "transaction",
    }  # nothing signed then: no entry at all

    with pytest.raises(validation.ValidationError, match="only a doctor"):
        validation.amend(engine, signed, "more news", NURSE)
    with pytest.raises(validation.ValidationError, match="needs a reason"):
        validation.amend(engine, signed, " ", DOCTOR)
    with pytest.raises(validation.ValidationError, match="not signed off"):
        validation.amend(engine, unsigned, "nothing to reopen", DOCTOR)
    validation.amend(engine, signed, "physio: stairs need help", DOCTOR)
    assert validation.review(engine, signed).state is ReviewState.CORRECTED  # not final any more
    assert exports.period_bundle(engine, q, today, today) == {"resourceType": "Bundle", "type": "transaction"}
    validation.change_item(engine, q, signed, "stairs", 2, "seen on the stairs", DOCTOR)
    validation.sign_off(engine, signed, DOCTOR)

    review = validation.review(engine, signed)
    assert review.state is ReviewState.AMENDED and review.reopenings[0].reason == "physio: stairs need help"
    assert [e.action for e in validation.trail(engine, signed)] == ["sign_off", "amend", "correct", "sign_off"]
    bundle = exports.period_bundle(engine, q, today, today)
    check_fhir(bundle)
    (entry,) = _responses(bundle).values()
    assert entry["resource"]["status"] == "amended" and entry["request"]["method"] == "PUT"
    assert sum(e["resource"]["resourceType"] == "Provenance" for e in bundle["entry"]) == 2  # reopening, change
    single = exports.result_bundle(engine, q, signed)
    assert _responses(single)[signed] == entry  # one result, one story: alone or in the period's Bundle
    assert _states(exports.result_csv(engine, q, signed)) == {"amended"}
    assert _states(exports.result_csv(engine, q, unsigned)) == {"corrected"}


def test_a_period_is_read_from_days_or_refused_in_words():
    assert exports.period("2026-11-01", "2026-11-30") == (date(2026, 11, 1), date(2026, 11, 30))
    with pytest.raises(exports.PeriodError, match="from='yesterday': give a day as YYYY-MM-DD"):
        exports.period("yesterday", "2026-11-30")
    with pytest.raises(exports.PeriodError, match="to=2026-10-01 is before from=2026-11-01"):
        exports.period("2026-11-01", "2026-10-01")
