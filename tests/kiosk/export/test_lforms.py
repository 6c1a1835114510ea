"""LHC-Forms (npm ``lforms``, served from node_modules on 127.0.0.1) in real Chromium renders each
exported response on its exported Questionnaire, in English, Spanish and French, and shows every
answer and the same total (none for an incomplete result)."""

from __future__ import annotations

import functools
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest
from playwright.sync_api import sync_playwright

from kiosk.core.review import Correction, Review, ReviewState
from kiosk.export import ExportSite, fhir_questionnaire, fhir_response, result
from tests.kiosk.core.helpers import QUESTIONNAIRE
from tests.station.conftest import shared_station  # noqa: F401 - the station fixture

from .standard import JS

CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: the longest wait for LHC-Forms to load or render a form (a bound, not a timing assertion)
PATIENCE_MS = 60_000
SITE = ExportSite(site="hosp-north", kiosk_id="ward3-bed2")

pytestmark = pytest.mark.slow

RENDER = """async ([questionnaire, response]) => {
  const element = document.getElementById('form');
  await LForms.Util.addFormToPage(questionnaire, element, {fhirVersion: 'R4', questionnaireResponse: response});
  const shown = {};
  for (const input of element.querySelectorAll('input')) shown[input.id.split('/')[0]] = input.value;
  return {shown, back: LForms.Util.getFormFHIRData('QuestionnaireResponse', 'R4', element)};
}"""


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:  # the test reports what matters
        pass


@pytest.fixture(scope="module")
def lforms_page(npm_packages: Path, chromium: str):
    """LHC-Forms loaded in a real Chromium page (the test run installs lforms itself)."""
    if not (npm_packages / "lforms/dist").is_dir():
        pytest.fail(f"lforms is missing from {npm_packages} after `npm ci`", pytrace=False)
    server = ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(JS)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=chromium, headless=True, args=CHROMIUM_ARGS)
            page = browser.new_page()
            errors: list[str] = []
            page.on("pageerror", lambda error: errors.append(str(error)))
            page.goto(f"http://127.0.0.1:{server.server_port}/lforms.html")
            page.wait_for_function("window.LForms && LForms.Util && LForms.FHIR && LForms.FHIR.R4", timeout=PATIENCE_MS)
            yield page, errors
            browser.close()
    finally:
        server.shutdown()
        server.server_close()


def _amended(stored):
    corrections = tuple(
        Correction(item, 1, None, "asked the relative again", "dr.lopez", "2026-11-23T15:00:00Z")
        for item in stored.not_answered
    )
    return Review(ReviewState.AMENDED, corrections, "dr.lopez", "2026-11-23T15:02:00Z")


@pytest.mark.parametrize(
    ("patient", "language", "amend"),
    [
        ("TB-0002", "en", False),
        ("TB-0004", "en", False),
        ("P-ES-0001", "es", False),
        ("P-FR-0003", "fr", False),
        ("P-FR-0003", "fr", True),
    ],
)
def test_lhc_forms_shows_every_answer_and_the_same_total(lforms_page, replayed, patient, language, amend):
    page, errors = lforms_page
    stored = replayed[patient]
    assert stored.language == language
    review = _amended(stored) if amend else None
    questionnaire = fhir_questionnaire(QUESTIONNAIRE, language, SITE)
    response = fhir_response(QUESTIONNAIRE, stored, review, SITE)
    page.set_default_timeout(PATIENCE_MS)
    rendered = page.evaluate(RENDER, [questionnaire, response])
    assert not errors, errors
    expected = result(QUESTIONNAIRE, stored, review)
    for item in QUESTIONNAIRE.items:
        shown = rendered["shown"][item.id]
        if item.id in expected.options:
            option = item.option(expected.options[item.id])
            # the Coding's display is LOINC's for the code (the wording is in the extension beside it)
            display = option.code.display if option.code and option.code.display else option.label_in(language)
            assert shown == f"{display} - {option.points}", (item.id, shown)
        else:
            assert shown == "", (item.id, shown)
    assert rendered["shown"]["total"] == (str(expected.score.total) if expected.complete else "")
    back = {i["linkId"]: i.get("answer") for i in rendered["back"]["item"]}
    ours = {i["linkId"]: i.get("answer") for i in response["item"]}
    assert {k: [a["valueCoding"]["code"] for a in v] for k, v in back.items() if v and k != "total"} == {
        k: [a["valueCoding"]["code"] for a in v] for k, v in ours.items() if v and k != "total"
    }
    assert back.get("total") == ours.get("total")


def test_lhc_forms_shows_a_station_bundles_corrected_and_signed_result(lforms_page, shared_station):
    """The station's own export (a real station process): the response of its Bundle, on the
    Questionnaire of that Bundle, shows the corrected answers and the corrected total."""
    from tests.station.conftest import new_kiosk
    from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    rows = record_patient(PATIENTS / "barthel4.yaml")  # grooming and bladder unanswered
    client = KioskClient(station.url, token, name)
    try:
        assert client.sync(rows).status_code == 200
    finally:
        client.close()
    session = f"/sessions/{rows[0].session_id}"
    doctor = Staff(station.url)
    for item, option, why in (
        ("grooming", "2", "asked again"),
        ("bladder", "3", "asked again"),
        ("feeding", "2", "needs help cutting"),
    ):
        assert doctor.post(f"{session}/items/{item}", option=option, reason=why).status_code == 303
    assert doctor.post(f"{session}/sign-off").status_code == 303
    bundle = doctor.http.get(f"{session}/export.json").json()
    (questionnaire,) = [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "Questionnaire"]
    (response,) = [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse"]
    page, errors = lforms_page
    rendered = page.evaluate(RENDER, [questionnaire, response])
    assert not errors, errors
    ours = {i["linkId"]: i["answer"][0] for i in response["item"]}
    assert ours["total"] == {"valueInteger": 75}  # 65 from 8 items, +5 +10 filled, feeding 10 -> 5
    assert rendered["shown"]["total"] == "75"
    for item in QUESTIONNAIRE.items:
        coding = ours[item.id]["valueCoding"]
        weight = next(o for o in item.options if o.code and o.code.code == coding["code"]).points
        assert rendered["shown"][item.id] == f"{coding['display']} - {weight}", item.id
