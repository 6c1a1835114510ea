"""The ward station's export of a result a clinician reviewed, through a real `kiosk station`
process: a kiosk syncs a replayed session, a nurse fills the unanswered items, a doctor signs off,
and the export says so in valid R4, with the identifier the kiosk itself would give the result."""

from __future__ import annotations

import pytest

from tests.station.conftest import new_kiosk, shared_station  # noqa: F401,F811 - the station fixture
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

from .standard import check_fhir

pytestmark = pytest.mark.slow


def test_a_result_completed_and_signed_off_at_the_station_exports_amended_and_final(shared_station):  # noqa: F811
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    rows = record_patient(PATIENTS / "barthel4.yaml")  # grooming and bladder unanswered: 65 from 8 items
    client = KioskClient(station.url, token, name)
    try:
        assert client.sync(rows).status_code == 200
    finally:
        client.close()
    session_id = rows[0].session_id
    doctor = Staff(station.url)
    before = doctor.http.get(f"/sessions/{session_id}/export.json").json()
    check_fhir(before)
    assert before["status"] == "in-progress" and before["identifier"]["value"] == f"local/{name}/{session_id}"
    for item, option in (("grooming", 2), ("bladder", 3)):
        assert doctor.post(f"/sessions/{session_id}/items/{item}", option=str(option),
                           reason="asked the patient again").status_code == 303
    assert doctor.post(f"/sessions/{session_id}/sign-off").status_code == 303
    after = doctor.http.get(f"/sessions/{session_id}/export.json").json()
    check_fhir(after)
    assert after["status"] == "amended" and after["author"]["display"] == "dr.lopez"
    assert next(i for i in after["item"] if i["linkId"] == "total")["answer"] == [{"valueInteger": 80}]
    signature = after["extension"][0]["valueSignature"]
    assert signature["who"]["display"] == "dr.lopez" and signature["when"]
    table = doctor.http.get(f"/sessions/{session_id}/export.csv").text
    assert f"K:{name}" in table and ",amended," in table
