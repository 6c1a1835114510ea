"""A kiosk running a site's own questionnaire (another id, three items, its own wording) syncs to
a real station: the station stores the definition the kiosk sent and describes the session with
it -- its page, FHIR and CSV -- where it once described every session with its bundled Barthel
file and answered 500 for this one."""

from __future__ import annotations

import csv
import io

import pytest

from kiosk.core.questionnaire.definition import digest
from tests.station.conftest import new_kiosk, shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient, response_in

pytestmark = pytest.mark.slow
KEPT = ("feeding", "bathing", "grooming")
OWN_TEXT = "Can you eat a meal on your own? (site wording)"


def test_a_sites_own_questionnaire_is_shown_and_exported_with_its_own_definition(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    rows = [r for r in record_patient(PATIENTS / "barthel1.yaml") if r.payload.get("item_id", KEPT[0]) in KEPT]
    create = rows[0].payload
    definition = create["definition"]
    definition["id"], definition["version"] = "site-adl", "3"
    definition["items"] = [i for i in definition["items"] if i["id"] in KEPT]
    definition["items"][0]["text"]["en"] = OWN_TEXT
    definition["title"] = {lang: "Site ADL" for lang in definition["languages"]}
    create["questionnaire_id"], create["definition_sha256"] = "site-adl", digest(definition)
    client = KioskClient(station.url, token, name)
    try:
        answer = client.sync(rows)
    finally:
        client.close()
    assert answer.status_code == 200, answer.text
    session_id = rows[0].session_id
    staff = Staff(station.url)
    page = staff.http.get(f"/sessions/{session_id}")
    assert page.status_code == 200 and OWN_TEXT in page.text and "site-adl" in page.text
    assert "Dressing" not in page.text  # a Barthel item this questionnaire does not have
    fhir = staff.http.get(f"/sessions/{session_id}/export.json")
    assert fhir.status_code == 200, fhir.text
    response = response_in(fhir.json())
    assert "site-adl" in response["questionnaire"]
    assert [i["linkId"] for i in response["item"] if i["linkId"] != "total"] == list(KEPT)
    assert response["item"][0]["text"] == OWN_TEXT
    table = staff.http.get(f"/sessions/{session_id}/export.csv")
    assert table.status_code == 200
    items = [r["item"] for r in csv.DictReader(io.StringIO(table.text)) if r["kind"] == "item"]
    assert items == list(KEPT)
    staff.http.close()
