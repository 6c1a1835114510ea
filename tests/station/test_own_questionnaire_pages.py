"""A site's own questionnaire (three items, its own points and bands) on every station page that
describes its result: the inbox, the patient's course, the sign-off confirmation and, after a
correction, sign-off and amendment, the words, the badge, the CSV and the FHIR Bundle -- each
from the questionnaire the session captured, never from the station's bundled Barthel file."""

from __future__ import annotations

import csv
import io
import re

import pytest

from kiosk.core.questionnaire.definition import digest
from tests.station.conftest import new_kiosk, shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient, response_in

pytestmark = pytest.mark.slow
KEPT = ("feeding", "bathing", "grooming")
SITE_BANDS = [
    {"id": "needs-support", "min": 0, "max": 9, "label": {"en": "Needs support"}},
    {"id": "manages", "min": 10, "max": 40, "label": {"en": "Manages"}},
]
OWN_LABEL = "Eats alone (site wording)"


def _own_session(station, ward) -> tuple[str, str, list]:
    """Sync one finished session of 'site-adl' (feeding, bathing, grooming; every point doubled;
    bands 'needs-support' 0-9, 'manages' 10-40); returns (session id, patient id, its answers)."""
    name, token = new_kiosk(ward.db_url)
    rows = [r for r in record_patient(PATIENTS / "barthel1.yaml") if r.payload.get("item_id", KEPT[0]) in KEPT]
    create = rows[0].payload
    definition = create["definition"]
    definition["id"], definition["version"] = "site-adl", "3"
    definition["items"] = [i for i in definition["items"] if i["id"] in KEPT]
    for item in definition["items"]:
        for option in item["options"]:
            option["points"] *= 2
    definition["items"][0]["options"][-1]["label"]["en"] = OWN_LABEL
    for lang in definition["languages"]:
        for band in SITE_BANDS:
            band["label"].setdefault(lang, band["label"]["en"])
    definition["band_sets"] = [{"id": "site", "source": "the site's own", "bands": SITE_BANDS}]
    definition["band_set"] = "site"
    definition["title"] = {lang: "Site ADL" for lang in definition["languages"]}
    create["questionnaire_id"], create["definition_sha256"] = "site-adl", digest(definition)
    for row in rows:
        if row.kind == "record_answer":
            row.payload["points"] *= 2
    client = KioskClient(station.url, token, name)
    try:
        answer = client.sync(rows)
    finally:
        client.close()
    assert answer.status_code == 200, answer.text
    answers = [r.payload for r in rows if r.kind == "record_answer"]
    return rows[0].session_id, create["patient_id"], answers


def _badge(html: str, element_id: str) -> str:
    found = re.search(rf'id="{element_id}"[^>]*>([^<]*)<', html)
    assert found, html[:3000]
    return found.group(1).strip()


def test_every_page_of_a_result_uses_the_questionnaire_the_session_ran(shared_station):
    station, ward = shared_station
    session_id, patient_id, answers = _own_session(station, ward)
    total = sum(a["points"] for a in answers)
    band = "needs-support" if total <= 9 else "manages"
    staff = Staff(station.url)
    try:
        inbox = staff.http.get("/inbox")
        words = "Needs support" if band == "needs-support" else "Manages"  # the band's label, in words
        assert inbox.status_code == 200 and f"{total} of 40 · {words}" in inbox.text
        patient = staff.http.get(f"/patients/{patient_id}")
        assert patient.status_code == 200 and f"{total} of 40" in patient.text
        assert "<svg" in patient.text and "No complete Site ADL total" not in patient.text  # its course is plotted
        confirm = staff.http.get(f"/sessions/{session_id}/sign-off")
        assert confirm.status_code == 200
        assert _badge(confirm.text, "confirm-total").startswith(f"{total} of 40 — {band}"), confirm.text
    finally:
        staff.http.close()


def test_changes_that_come_back_to_the_kiosks_answer_are_signed_off_as_recorded(shared_station):
    """The confirmation, the page's badge, the inbox and the CSV name one state: the review-state
    function's (a change undone is no change)."""
    station, ward = shared_station
    session_id, patient_id, answers = _own_session(station, ward)
    feeding = next(a for a in answers if a["item_id"] == "feeding")["option"]
    other = 1 if feeding != 1 else 2
    staff = Staff(station.url)
    try:
        for option, reason in ((other, "misheard"), (feeding, "it was right after all")):
            changed = staff.post(f"/sessions/{session_id}/items/feeding", option=str(option), reason=reason)
            assert changed.status_code == 303, changed.text
        assert _badge(staff.http.get(f"/sessions/{session_id}").text, "sign-off") == "Accept as recorded and sign off"
        confirm = staff.http.get(f"/sessions/{session_id}/sign-off")
        assert _badge(confirm.text, "confirm-state") == "signed off"
        assert _badge(confirm.text, "confirm-sign-off") == "Sign off"
        assert staff.post(f"/sessions/{session_id}/sign-off").status_code == 303
        page = staff.http.get(f"/sessions/{session_id}")
        assert _badge(page.text, "review-state") == "signed off"
        signed = staff.http.get("/inbox?state=signed")
        assert re.search(rf"{patient_id}.*?signed off", signed.text, re.S), signed.text
        table = staff.http.get(f"/sessions/{session_id}/export.csv")
        assert {r["review_state"] for r in csv.DictReader(io.StringIO(table.text))} == {"signed_off"}
        fhir = staff.http.get(f"/sessions/{session_id}/export.json").json()
        observations = [e["resource"] for e in fhir["entry"] if e["resource"]["resourceType"] == "Observation"]
        assert [o["status"] for o in observations] == ["final"]
        assert response_in(fhir)["status"] == "completed"
    finally:
        staff.http.close()


def _row_state(html: str, session_id: str) -> str | None:
    """The review badge of ``session_id``'s row in an inbox page; None when it is not listed."""
    found = re.search(rf'data-session="{session_id}".*?class="badge review-([a-z_]+)"', html, re.S)
    return found.group(1) if found else None


def test_a_result_reopened_to_amend_waits_again_until_signed_again(shared_station):
    """Reopened, a result is ``corrected`` on its page, in CSV and FHIR: the inbox lists it as
    waiting (and counts it), not as signed; signed again it is ``amended`` everywhere."""
    station, ward = shared_station
    session_id, _, answers = _own_session(station, ward)
    feeding = next(a for a in answers if a["item_id"] == "feeding")["option"]
    staff = Staff(station.url)
    try:
        assert (
            staff.post(
                f"/sessions/{session_id}/items/feeding", option=str(1 if feeding != 1 else 2), reason="misheard"
            ).status_code
            == 303
        )
        assert staff.post(f"/sessions/{session_id}/sign-off").status_code == 303
        assert _row_state(staff.http.get("/inbox?state=signed").text, session_id) == "amended"
        waiting_before = int(_badge(staff.http.get("/inbox").text, "waiting-count"))
        reopened = staff.post(f"/sessions/{session_id}/amend", reason="physio: feeding needs help")
        assert reopened.status_code == 303 and "Reopened" in staff.http.get(reopened.headers["location"]).text
        assert _badge(staff.http.get(f"/sessions/{session_id}").text, "review-state") == "corrected"
        waiting = staff.http.get("/inbox")
        assert _row_state(waiting.text, session_id) == "corrected"
        assert int(_badge(waiting.text, "waiting-count")) == waiting_before + 1
        assert _row_state(staff.http.get("/inbox?state=signed").text, session_id) is None
        assert _row_state(staff.http.get("/fragments/inbox").text, session_id) == "corrected"
        table = staff.http.get(f"/sessions/{session_id}/export.csv")
        assert {r["review_state"] for r in csv.DictReader(io.StringIO(table.text))} == {"corrected"}
        fhir = staff.http.get(f"/sessions/{session_id}/export.json").json()
        assert [e["resource"]["status"] for e in fhir["entry"] if e["resource"]["resourceType"] == "Observation"] == [
            "preliminary"
        ]
        assert staff.post(f"/sessions/{session_id}/sign-off").status_code == 303
        assert _row_state(staff.http.get("/inbox?state=signed").text, session_id) == "amended"
        assert _row_state(staff.http.get("/inbox").text, session_id) is None
    finally:
        staff.http.close()


def test_staff_order_a_visit_of_the_sites_own_questionnaire(shared_station):
    """A site whose kiosk runs its own questionnaire can order it: the station offers every
    instrument a kiosk has run here, and the kiosk is sent an order it can take."""
    station, ward = shared_station
    _own_session(station, ward)
    name, token = new_kiosk(ward.db_url)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    kiosk = KioskClient(station.url, token, name)
    try:
        form = nurse.http.get("/orders").text
        assert 'value="site-adl"' in form and "Site ADL" in form
        placed = nurse.post("/orders", patient_id="NHC-0044001", kiosk=name, instrument="site-adl", language="en")
        assert placed.status_code == 303 and placed.headers["location"].startswith("/orders/order-"), placed.headers[
            "location"
        ]
        assert [o["instruments"] for o in kiosk.orders()["orders"]] == [["site-adl"]]
        refused = nurse.post("/orders", patient_id="NHC-0044001", kiosk=name, instrument="site-adl", language="pt")
        assert refused.headers["location"].startswith("/orders?error=")
    finally:
        nurse.http.close()
        kiosk.close()
