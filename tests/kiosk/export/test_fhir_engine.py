"""What a hospital's FHIR server ends up holding when it takes, in order, the kiosk's Bundle and
the station's Bundles of one result: a real FHIR engine (the in-memory repository of
``@medplum/fhir-router``, driven by tests/kiosk/export/js/apply.mjs under node) applies the transactions
the way a server does, conditional create and conditional update included.

The scenario: a kiosk records a session (feeding and stairs "independent", total 100) and exports
it with ``kiosk results --fhir``; it syncs to a real station, a nurse corrects feeding, a doctor
signs off (station export 1), then reopens the result to amend stairs and signs again (export 2);
the kiosk's and the station's Bundles are each sent twice, as a retrying interface would."""

from __future__ import annotations

import json
import shutil
import subprocess

import pytest

from kiosk.commands.results import main as results_main
from kiosk.export import ExportSite, export_identity
from tests.station.conftest import PATIENCE_S, new_kiosk, shared_station  # noqa: F401 - the station fixture
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

from .standard import JS, check_fhir

pytestmark = pytest.mark.slow


def apply(*bundles) -> dict:
    """The Bundle files applied in order by the real engine: its responses, resources and history."""
    node = shutil.which("node")
    if node is None or not (JS / "node_modules/@medplum/fhir-router").is_dir():
        pytest.fail(f"node and @medplum/fhir-router are needed: run `npm ci` in {JS}")
    done = subprocess.run(
        [node, "apply.mjs", *map(str, bundles)], cwd=JS, capture_output=True, text=True, check=False, timeout=PATIENCE_S
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_the_hospital_ends_with_one_result_per_session_the_amended_one_with_its_history(
    shared_station, tmp_path, monkeypatch, capsys
):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    site = ExportSite(site="hosp-north", kiosk_id=name)
    rows = record_patient(PATIENTS / "barthel1.yaml", export=export_identity(site), data_dir=tmp_path / "kiosk")
    session_id = rows[0].session_id
    config = tmp_path / "config.yaml"
    config.write_text(f"site: hosp-north\nkiosk_id: {name}\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    kiosk_bundle = tmp_path / "kiosk.json"
    assert results_main(["--data-dir", str(tmp_path / "kiosk"), "--fhir", str(kiosk_bundle)]) == 0
    capsys.readouterr()
    check_fhir(json.loads(kiosk_bundle.read_text(encoding="utf-8")))

    client = KioskClient(station.url, token, name)
    try:
        assert client.sync(rows).status_code == 200
    finally:
        client.close()
    page = f"/sessions/{session_id}"
    nurse, doctor = Staff(station.url, "nurse.kim", "nurse"), Staff(station.url)
    # one code path: before any review the station's Bundle is the kiosk's, entry for entry
    assert doctor.http.get(f"{page}/export.json").json() == json.loads(kiosk_bundle.read_text(encoding="utf-8"))
    assert nurse.post(f"{page}/items/feeding", option="2", reason="needs help cutting").status_code == 303
    assert doctor.post(f"{page}/sign-off").status_code == 303
    signed = tmp_path / "station-signed.json"
    signed.write_text(doctor.http.get(f"{page}/export.json").text, encoding="utf-8")
    assert doctor.post(f"{page}/amend", reason="physio: stairs need help").status_code == 303
    assert doctor.post(f"{page}/items/stairs", option="2", reason="seen on the stairs").status_code == 303
    assert doctor.post(f"{page}/sign-off").status_code == 303
    amended = tmp_path / "station-amended.json"
    amended.write_text(doctor.http.get(f"{page}/export.json").text, encoding="utf-8")
    for path in (signed, amended):
        check_fhir(json.loads(path.read_text(encoding="utf-8")))

    held = apply(kiosk_bundle, signed, kiosk_bundle, amended, amended)
    resources, history = held["resources"], held["history"]
    (response,), (total,) = resources["QuestionnaireResponse"], resources["Observation"]
    assert response["identifier"]["value"] == f"hosp-north/{name}/{session_id}"  # the kiosk's and the station's
    assert response["status"] == "amended" and total["status"] == "amended"
    assert next(i for i in response["item"] if i["linkId"] == "total")["answer"] == [{"valueInteger": 90}]
    assert (
        total["valueQuantity"]["value"] == 90
        and total["derivedFrom"][0]["reference"] == f"QuestionnaireResponse/{response['id']}"
    )
    assert len(resources["Device"]) == len(resources["Questionnaire"]) == 1
    assert response["author"]["reference"] == f"Device/{resources['Device'][0]['id']}"
    # the kiosk's re-sent Bundle (a conditional create) changed nothing; each sign-off made a version
    # (one version per station PUT: the engine keeps a version even for an identical re-sent one)
    versions = [v["status"] for v in history[f"QuestionnaireResponse/{response['id']}"]]
    assert versions == ["completed", "amended", "amended", "amended"]
    totals = [v["status"] for v in history[f"Observation/{total['id']}"]]
    assert totals == ["preliminary", "amended", "amended", "amended"]
    kiosk_again = [e["response"]["status"] for e in held["responses"][2]["entry"]]
    assert all(status.startswith("200") for status in kiosk_again), kiosk_again  # found, not created
    provenances = resources["Provenance"]
    assert sorted(p["reason"][0]["text"] for p in provenances) == [
        "needs help cutting",
        "physio: stairs need help",
        "seen on the stairs",
    ]  # sent twice, held once
    assert {p["target"][0]["reference"] for p in provenances} == {f"QuestionnaireResponse/{response['id']}"}
