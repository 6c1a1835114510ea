"""Every station page at a phone's 390 px width, with the longest things staff and kiosks may
put on it: a 64-character patient identifier, a site's questionnaire whose wording has long
unbroken words, a long correction reason, a cancelled order with a long reason. No page scrolls
sideways (real station process, real Chromium)."""

from __future__ import annotations

import re
from urllib.parse import quote

import pytest

from kiosk.core.questionnaire.definition import digest
from tests.station.conftest import new_kiosk, shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient
from tests.station.test_visit_e2e import PHONE, fits, login

pytestmark = pytest.mark.slow
PATIENT = "NHC" + "7" * 61  # the longest identifier a hospital may give (64)
LONG_WORD = "Selbstversorgungsfähigkeitseinschätzungsfrage" * 2
REASON = "Rückmeldung-der-Physiotherapie:" + "x" * 200


def _sync_long_session(station, ward) -> tuple[str, str]:
    name, token = new_kiosk(ward.db_url)
    rows = record_patient(PATIENTS / "barthel1.yaml")
    create = rows[0].payload
    definition = create["definition"]
    definition["id"] = "site-adl-" + "w" * 40
    for item in definition["items"]:
        item["text"]["en"] = LONG_WORD
        item["options"][0]["label"]["en"] = LONG_WORD
    definition["title"] = {lang: LONG_WORD for lang in definition["languages"]}
    create["questionnaire_id"], create["definition_sha256"] = definition["id"], digest(definition)
    create["patient_id"] = PATIENT
    client = KioskClient(station.url, token, name)
    try:
        answer = client.sync(rows)
    finally:
        client.close()
    assert answer.status_code == 200, answer.text
    return rows[0].session_id, name


def test_no_station_page_scrolls_sideways_on_a_phone(browser, shared_station):
    station, ward = shared_station
    session_id, kiosk = _sync_long_session(station, ward)
    staff = Staff(station.url)
    try:
        changed = staff.post(f"/sessions/{session_id}/items/feeding", option="1", reason=REASON)
        assert changed.status_code == 303, changed.text
        placed = staff.post("/orders", patient_id=PATIENT, kiosk=kiosk, instrument="barthel", language="en")
        order_path = placed.headers["location"]
        assert re.fullmatch(r"/orders/[^/?]+", order_path), order_path
        assert staff.post(order_path + "/cancel", reason=REASON).status_code == 303
    finally:
        staff.http.close()
    context, page = login(browser, station.url, "dr.lopez", "doctor", PHONE)
    try:
        fits(page, PHONE)
        for path in (
            "/inbox",
            "/inbox?state=all",
            f"/patients?q={PATIENT[:6]}",
            f"/patients/{quote(PATIENT)}",
            f"/sessions/{session_id}",
            f"/sessions/{session_id}/sign-off",
            f"/sessions/{session_id}/print",
            f"/visits/{session_id}",
            f"/visits/{session_id}/sign-off",
            f"/patients/{quote(PATIENT)}/print",
            "/handover",
            "/orders",
            "/orders?state=",
            "/orders?state=cancelled",
            order_path,
        ):
            page.goto(station.url + path)
            page.wait_for_selector("main")
            fits(page, PHONE)
    finally:
        context.close()
