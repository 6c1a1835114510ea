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

from kiosk.export import ExportSite, result
from kiosk.export import fhir_questionnaire, fhir_response
from kiosk.review import Correction, Review, ReviewState
from tests.session.helpers import QUESTIONNAIRE

from .standard import JS

CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
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
            page.wait_for_function("window.LForms && LForms.Util && LForms.FHIR && LForms.FHIR.R4",
                                   timeout=PATIENCE_MS)
            yield page, errors
            browser.close()
    finally:
        server.shutdown()
        server.server_close()


def _amended(stored):
    corrections = tuple(Correction(item, 1, None, "asked the relative again", "dr.lopez", "2026-11-23T15:00:00Z")
                        for item in stored.not_answered)
    return Review(ReviewState.AMENDED, corrections, "dr.lopez", "2026-11-23T15:02:00Z")


@pytest.mark.parametrize(("patient", "language", "amend"), [
    ("TB-0002", "en", False), ("TB-0004", "en", False), ("P-ES-0001", "es", False),
    ("P-FR-0003", "fr", False), ("P-FR-0003", "fr", True),
])
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
            assert shown == f"{option.label_in(language)} - {option.points}", (item.id, shown)
        else:
            assert shown == "", (item.id, shown)
    assert rendered["shown"]["total"] == (str(expected.score.total) if expected.complete else "")
    back = {i["linkId"]: i.get("answer") for i in rendered["back"]["item"]}
    ours = {i["linkId"]: i.get("answer") for i in response["item"]}
    assert {k: [a["valueCoding"]["code"] for a in v] for k, v in back.items() if v and k != "total"} == \
           {k: [a["valueCoding"]["code"] for a in v] for k, v in ours.items() if v and k != "total"}
    assert back.get("total") == ours.get("total")
