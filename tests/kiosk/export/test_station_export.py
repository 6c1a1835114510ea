"""The ward station's exports of results clinicians reviewed, through a real `kiosk station`
process: a kiosk syncs a replayed session, staff correct or fill items, a doctor signs off (and may
reopen a signed result to amend it), and the station exports one result, or every result signed
off in a period, as a valid R4 transaction Bundle that says what the CSV says, with the identifier
the kiosk itself gives the result."""

from __future__ import annotations

import csv
import io
from datetime import UTC, datetime

import pytest

from kiosk.export import REPLACED_ANSWER
from tests.station.conftest import new_kiosk, shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

from .standard import check_fhir

pytestmark = pytest.mark.slow
STAFF = "urn:barthel-kiosk:station:staff"


def synced(station, ward, script: str) -> str:
    """A new kiosk sends the replayed session of ``script``; its session id."""
    name, token = new_kiosk(ward.db_url)
    rows = record_patient(PATIENTS / script)
    client = KioskClient(station.url, token, name)
    try:
        assert client.sync(rows).status_code == 200
    finally:
        client.close()
    return rows[0].session_id


def bundle(staff: Staff, session_id: str) -> dict:
    response = staff.http.get(f"/sessions/{session_id}/export.json")
    assert response.status_code == 200 and response.headers["content-type"].startswith("application/fhir+json")
    found = response.json()
    check_fhir(found)  # the official R4 JSON schema and fhir.resources, every entry
    assert found["type"] == "transaction"
    return found


def of(found: dict, kind: str) -> list[dict]:
    return [e for e in found.get("entry", []) if e["resource"]["resourceType"] == kind]


def total_of(response: dict) -> list | None:
    return next((i["answer"] for i in response.get("item", []) if i["linkId"] == "total"), None)


def csv_state(staff: Staff, session_id: str) -> set[str]:
    rows = csv.DictReader(io.StringIO(staff.http.get(f"/sessions/{session_id}/export.csv").text))
    return {row["review_state"] for row in rows}


def test_a_result_completed_and_signed_off_at_the_station_exports_amended_and_final(shared_station):
    station, ward = shared_station
    session_id = synced(station, ward, "barthel4.yaml")  # grooming and bladder unanswered: 65 from 8 items
    doctor = Staff(station.url)
    before = bundle(doctor, session_id)
    (response,) = of(before, "QuestionnaireResponse")
    assert response["resource"]["status"] == "in-progress" and total_of(response["resource"]) is None
    assert response["resource"]["identifier"]["value"].endswith(f"/{session_id}") and not of(before, "Observation")
    assert response["request"]["method"] == "POST" and csv_state(doctor, session_id) == {"unreviewed"}
    for item, option in (("grooming", 2), ("bladder", 3)):
        assert (
            doctor.post(
                f"/sessions/{session_id}/items/{item}", option=str(option), reason="asked the patient again"
            ).status_code
            == 303
        )
    assert doctor.post(f"/sessions/{session_id}/sign-off").status_code == 303
    after = bundle(doctor, session_id)
    (response,), (total,) = of(after, "QuestionnaireResponse"), of(after, "Observation")
    assert response["resource"]["status"] == "amended" and total_of(response["resource"]) == [{"valueInteger": 80}]
    assert total["resource"]["status"] == "amended" and total["resource"]["valueQuantity"]["value"] == 80
    assert response["request"]["method"] == total["request"]["method"] == "PUT"
    assert response["request"]["url"].startswith("QuestionnaireResponse?identifier=")
    assert response["resource"]["author"]["type"] == "Device"  # the kiosk gave the other 8 answers
    signature = response["resource"]["extension"][0]["valueSignature"]
    assert signature["who"]["identifier"] == {"system": STAFF, "value": "dr.lopez"} and signature["when"]
    provenances = [p["resource"] for p in of(after, "Provenance")]
    assert [p["target"][0]["extension"][0]["valueUri"] for p in provenances] == ["grooming", "bladder"]
    assert all(p["activity"]["coding"][0]["code"] == "CREATE" and "entity" not in p for p in provenances)
    assert {entry["resourceType"] for entry in (e["resource"] for e in after["entry"])} == {
        "Questionnaire",
        "Device",
        "QuestionnaireResponse",
        "Observation",
        "Provenance",
    }
    assert csv_state(doctor, session_id) == {"amended"}


def test_a_corrected_result_says_the_same_in_csv_and_fhir_and_keeps_the_kiosks_answer(shared_station):
    station, ward = shared_station
    session_id = synced(station, ward, "barthel1.yaml")  # 100: feeding independent (10)
    nurse, doctor = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url)
    assert (
        nurse.post(
            f"/sessions/{session_id}/items/feeding", option="2", reason="needs help cutting; seen at lunch"
        ).status_code
        == 303
    )
    in_review = bundle(nurse, session_id)
    (response,), (total,) = of(in_review, "QuestionnaireResponse"), of(in_review, "Observation")
    # corrected, not signed off: the CSV and the FHIR tell the same story
    assert response["resource"]["status"] == "amended" and total["resource"]["status"] == "preliminary"
    assert csv_state(nurse, session_id) == {"corrected"}
    assert "extension" not in response["resource"] and response["request"]["method"] == "POST"
    assert doctor.post(f"/sessions/{session_id}/sign-off").status_code == 303
    signed = bundle(doctor, session_id)
    (response,), (total,) = of(signed, "QuestionnaireResponse"), of(signed, "Observation")
    assert response["resource"]["status"] == "amended" and total_of(response["resource"]) == [{"valueInteger": 95}]
    assert total["resource"]["status"] == "amended" and total["resource"]["valueQuantity"]["value"] == 95
    assert csv_state(doctor, session_id) == {"amended"}
    feeding = next(i for i in response["resource"]["item"] if i["linkId"] == "feeding")
    assert feeding["answer"][0]["valueCoding"]["code"] == "LA31630-9"
    (provenance,) = [p["resource"] for p in of(signed, "Provenance")]
    assert provenance["agent"][0]["who"]["identifier"] == {"system": STAFF, "value": "nurse.kim"}
    assert provenance["reason"] == [{"text": "needs help cutting; seen at lunch"}]
    assert provenance["target"][0]["reference"] == of(signed, "QuestionnaireResponse")[0]["fullUrl"]
    (entity,) = provenance["entity"]
    assert entity["role"] == "revision"
    assert entity["extension"] == [
        {
            "url": REPLACED_ANSWER,
            "valueCoding": {"system": "http://loinc.org", "code": "LA12302-8", "display": "Independent"},
        }
    ]
    assert entity["agent"][0]["who"]["reference"] == of(signed, "Device")[0]["fullUrl"]  # the kiosk's answer


def test_a_doctor_amends_a_signed_result_and_signs_it_again(shared_station):
    station, ward = shared_station
    session_id = synced(station, ward, "barthel1.yaml")
    page = f"/sessions/{session_id}"
    nurse, doctor = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url)
    assert doctor.post(f"{page}/sign-off").status_code == 303
    signed = bundle(doctor, session_id)
    assert of(signed, "Observation")[0]["resource"]["status"] == "final" and not of(signed, "Provenance")
    assert of(signed, "QuestionnaireResponse")[0]["resource"]["status"] == "completed"
    assert csv_state(doctor, session_id) == {"signed_off"}
    refused = nurse.post(f"{page}/amend", reason="more news")
    assert "only a doctor can amend" in nurse.http.get(refused.headers["location"]).text
    refused = doctor.post(f"{page}/amend", reason="  ")
    assert "needs a reason" in doctor.http.get(refused.headers["location"]).text
    refused = doctor.post(f"{page}/items/stairs", option="2", reason="uses the lift")
    assert "a doctor can amend it" in doctor.http.get(refused.headers["location"]).text
    assert doctor.post(f"{page}/amend", reason="physio reports stairs need help").status_code == 303
    reopened = doctor.http.get(page).text
    assert 'id="reopened"' in reopened and "physio reports stairs need help" in reopened
    assert csv_state(doctor, session_id) == {"corrected"}  # reopened, not final: no longer signed off
    # while reopened the hospital keeps the signed version: nothing is replaced
    while_open = bundle(doctor, session_id)
    assert [
        e["request"]["method"]
        for e in while_open["entry"]
        if e["resource"]["resourceType"] in ("QuestionnaireResponse", "Observation")
    ] == ["POST", "POST"]
    assert doctor.post(f"{page}/items/stairs", option="2", reason="needs help on stairs").status_code == 303
    assert doctor.post(f"{page}/sign-off").status_code == 303
    amended = bundle(doctor, session_id)
    (response,), (total,) = of(amended, "QuestionnaireResponse"), of(amended, "Observation")
    assert response["resource"]["status"] == total["resource"]["status"] == "amended"
    assert total_of(response["resource"]) == [{"valueInteger": 95}] and response["request"]["method"] == "PUT"
    reasons = [p["resource"]["reason"][0]["text"] for p in of(amended, "Provenance")]
    assert reasons == ["physio reports stairs need help", "needs help on stairs"]
    trail = doctor.http.get(page).text.split('class="trail"')[1]
    assert [word in trail for word in ("sign off", "amend", "stairs", "needs help on stairs")] == [True] * 4
    assert csv_state(doctor, session_id) == {"amended"}
    today = datetime.now(UTC).date().isoformat()
    period = doctor.http.get(f"/exports/signed-off.json?from={today}&to={today}")
    assert period.status_code == 200
    check_fhir(period.json())
    values = [e["resource"]["identifier"]["value"] for e in of(period.json(), "QuestionnaireResponse")]
    assert any(v.endswith(f"/{session_id}") for v in values)
    assert (
        doctor.http.get("/exports/signed-off.json?from=2026-13-01&to=2026-12-01").text
        == "from='2026-13-01': give a day as YYYY-MM-DD"
    )
