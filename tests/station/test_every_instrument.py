"""Everything downstream of a stored result handles every instrument (issue 26, part 5): a real
kiosk store's outbox carries a Barthel result and one of a four-item mood scale (2-3 options,
totals 0-25, its own bands: tests/instruments/mood4.yaml) to a real station process, on SQLite and
on PostgreSQL; the ward list, inbox, session pages, corrections, sign-off, the patient's course
(a plot per instrument on its own scale) and the FHIR and CSV exports describe each by its own
captured definition, never the Barthel's; the pages are driven in Chromium at a phone's and a
desktop's size."""

from __future__ import annotations

import csv
import io
import re
import subprocess
import sys
import uuid

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.questionnaire.definition import digest
from tests.instruments import MOOD4, MOOD4_PATIENT
from tests.kiosk.export.standard import check_fhir
from tests.station.conftest import PASSWORDS, ROOT, make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient, response_in

pytestmark = pytest.mark.slow
MOOD_TITLE = "Mood check (4 items)"
VIEWPORTS = [{"width": 390, "height": 844}, {"width": 1366, "height": 768}]


def _two_instruments(station, ward) -> tuple[str, str, str]:
    """A patient's Barthel visit and mood-scale visit, synced from a real kiosk store's outbox:
    (patient, mood session, barthel session)."""
    patient = "NHC-" + uuid.uuid4().hex[:6]
    mood = record_patient(MOOD4_PATIENT, patient=patient, questionnaire=load_questionnaire(MOOD4))
    barthel = record_patient(PATIENTS / "barthel1.yaml", first_seq=len(mood) + 1, patient=patient)
    client = KioskClient(station.url, ward.token, ward.kiosk_id)
    try:
        answer = client.sync(mood + barthel)
    finally:
        client.close()
    assert answer.status_code == 200, answer.text
    return patient, mood[0].session_id, barthel[0].session_id


def _entries(bundle: dict, kind: str) -> list[dict]:
    return [e["resource"] for e in bundle.get("entry", []) if e["resource"]["resourceType"] == kind]


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_station_describes_each_instrument_by_its_own_definition(database, request, station_factory):
    url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(url)
    station = station_factory(ward.db_url)
    patient, mood, barthel = _two_instruments(station, ward)
    staff = Staff(station.url)
    # the lists name each instrument and give each total on its own scale
    for path in ("/", "/inbox", "/fragments/inbox", "/fragments/results"):
        page = staff.http.get(path)
        assert page.status_code == 200, (path, page.text)
        assert MOOD_TITLE in page.text and "Barthel Index" in page.text, path
    inbox = staff.http.get("/inbox").text
    assert "20 of 25 · Suggests depression" in inbox and "100 of 100 · Independent" in inbox
    page = staff.http.get(f"/sessions/{mood}")
    assert page.status_code == 200
    assert MOOD_TITLE in page.text and "How is your energy?" in page.text and "Feeding" not in page.text
    assert re.search(r'id="total">20</b> of 25 — <span id="band"', page.text)
    assert "Barthel" not in page.text
    # the correction form offers this item's own options and points
    energy = page.text[page.text.index('id="item-energy"') :]
    energy = energy[: energy.index("</tr>")]
    assert re.findall(r'<option value="(\d)"[^>]*>\d\. ([^<]+)</option>', energy) == [
        ("1", "Full of energy (0)"),
        ("2", "Some energy (5)"),
        ("3", "No energy (10)"),
    ]
    assert staff.post(f"/sessions/{mood}/items/energy", option="2", reason="asked again").status_code == 303
    confirm = staff.http.get(f"/sessions/{mood}/sign-off").text
    assert f"Sign off the {MOOD_TITLE} result of {patient}?" in confirm and "15 of 25 — suggests" in confirm
    assert staff.post(f"/sessions/{mood}/sign-off").status_code == 303
    assert staff.post(f"/sessions/{barthel}/sign-off").status_code == 303
    page = staff.http.get(f"/sessions/{mood}").text
    assert 'id="review-state">amended' in page and 'id="total">15</b> of 25' in page
    # exports: the mood scale's own items, total and Questionnaire; valid FHIR R4
    bundle = staff.http.get(f"/sessions/{mood}/export.json").json()
    check_fhir(bundle)
    response = response_in(bundle)
    assert [i["linkId"] for i in response["item"] if i["linkId"] != "total"] == [
        "satisfied",
        "bored",
        "energy",
        "hopeful",
    ]
    (total,) = _entries(bundle, "Observation")
    assert total["valueQuantity"]["value"] == 15 and total["code"]["coding"][0]["code"] == "mood4-total"
    rows = list(csv.DictReader(io.StringIO(staff.http.get(f"/sessions/{mood}/export.csv").text)))
    assert {r["questionnaire"] for r in rows} == {"mood4"}
    assert [r["item"] for r in rows if r["kind"] == "item"] == ["satisfied", "bored", "energy", "hopeful"]
    # the period's Bundle carries both results, a Questionnaire for each instrument
    period = staff.http.get("/exports/signed-off.json?from=2000-01-01&to=2999-12-31")
    assert period.status_code == 200, period.text
    check_fhir(period.json())
    urls = sorted(q["url"] for q in _entries(period.json(), "Questionnaire"))
    assert len(urls) == 2 and "mood4" in urls[1] and "barthel" in urls[0]
    totals = sorted(o["valueQuantity"]["value"] for o in _entries(period.json(), "Observation"))
    assert totals == [15, 100]
    # the patient's course: a plot per instrument, each on its own axis
    course = staff.http.get(f"/patients/{patient}").text
    plots = re.findall(r'<svg class="course-plot".*?</svg>', course, re.S)
    assert len(plots) == 2
    ticks = [re.findall(r'text-anchor="end">(\d+)</text>', svg) for svg in plots]
    assert sorted(ticks) == [["0", "12", "25"], ["0", "50", "100"]]
    staff.http.close()


def _login(browser, url: str, viewport: dict) -> object:
    context = browser.new_context(viewport=viewport)
    page = context.new_page()
    page.goto(url + "/login")
    page.fill("input[name=name]", "dr.lopez")
    page.fill("input[name=password]", PASSWORDS["doctor"])
    page.click("button[type=submit]")
    page.wait_for_selector("#kiosks")
    return page


@pytest.mark.parametrize("viewport", VIEWPORTS, ids=["phone", "desktop"])
def test_a_doctor_corrects_and_signs_off_a_non_barthel_result_in_chromium(
    viewport, browser, sqlite_url, station_factory
):
    ward = make_ward(sqlite_url)
    station = station_factory(ward.db_url)
    patient, mood, _ = _two_instruments(station, ward)
    page = _login(browser, station.url, viewport)
    page.goto(station.url + "/inbox")
    row = page.locator(f"#inbox li.result:has-text('{MOOD_TITLE}')")
    assert row.locator(".score").inner_text() == "20 of 25 · Suggests depression"
    assert page.locator("#inbox li.result:has-text('Barthel Index') .score").inner_text() == "100 of 100 · Independent"
    row.locator("a.open-result").click()  # the visit, then its result's own page
    page.locator(".visit-result a.open-session").click()
    page.wait_for_selector("#instrument")
    assert page.locator("#instrument").inner_text() == MOOD_TITLE
    page.locator("#item-energy summary").click()
    page.locator("#item-energy select[name=option]").select_option("1")
    page.locator("#item-energy input[name=reason]").fill("confirmed with the nurse")
    page.locator("#item-energy button[type=submit]").click()
    page.wait_for_selector("#item-energy .change")
    assert page.locator("#total").inner_text() == "10"
    assert page.locator("#band").inner_text() == "normal"
    page.click("#sign-off")
    page.wait_for_selector("#confirm-h")
    assert page.locator("#confirm-h").inner_text() == f"Sign off the {MOOD_TITLE} result of {patient}?"
    assert page.locator("#confirm-total").inner_text() == "10 of 25 — normal"
    page.click("#confirm-sign-off")
    page.wait_for_selector("#review-state:text-is('amended')")
    page.goto(f"{station.url}/patients/{patient}")
    page.wait_for_selector("#visits")
    assert page.locator("svg.course-plot").count() == 2
    labels = [page.locator("svg.course-plot").nth(i).get_attribute("aria-label") for i in range(2)]
    assert sorted(labels) == sorted(["Barthel Index totals over time", f"{MOOD_TITLE} totals over time"])
    mood_plot = page.locator(f"svg.course-plot[aria-label='{MOOD_TITLE} totals over time']")
    assert mood_plot.locator("circle.visit-point title").text_content().endswith(": 10/25 normal, amended")
    # the plot fits the width at both sizes (no sideways scroll)
    assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")
    page.context.close()


def test_an_instrument_whose_options_subtract_points_is_stored_shown_and_plotted(sqlite_url, station_factory):
    """Negative points (an error counted against the total) and a total below zero's reach: the
    station stores the definition, scores, plots from the lowest total and exports it."""
    ward = make_ward(sqlite_url)
    station = station_factory(ward.db_url)
    patient = "NHC-" + uuid.uuid4().hex[:6]
    rows = record_patient(MOOD4_PATIENT, patient=patient, questionnaire=load_questionnaire(MOOD4))
    create = rows[0].payload
    definition = create["definition"]
    bored = next(i for i in definition["items"] if i["id"] == "bored")
    bored["options"][0]["points"] = -5  # "Yes" now subtracts
    (band_set,) = definition["band_sets"]
    band_set["bands"][0]["min"] = -5
    definition["version"] = "negative"
    create["definition_sha256"] = digest(definition)
    for row in rows:
        if row.kind == "record_answer" and row.payload["item_id"] == "bored":
            row.payload["points"] = -5
        if row.kind == "finish_session":
            row.payload |= {"total": 10, "band": "normal"}
    client = KioskClient(station.url, ward.token, ward.kiosk_id)
    try:
        answer = client.sync(rows)
    finally:
        client.close()
    assert answer.status_code == 200 and answer.json().get("parked", []) == [], answer.text
    staff = Staff(station.url)
    page = staff.http.get(f"/sessions/{rows[0].session_id}").text
    assert re.search(r'id="total">10</b> of 20 — <span id="band"[^>]*>normal<', page)
    assert "(-5)" in page  # the correction form says what "Yes" scores
    bundle = staff.http.get(f"/sessions/{rows[0].session_id}/export.json").json()
    check_fhir(bundle)
    (total,) = _entries(bundle, "Observation")
    assert total["valueQuantity"]["value"] == 10
    course = staff.http.get(f"/patients/{patient}").text
    assert re.findall(r'text-anchor="end">(-?\d+)</text>', course) == ["-5", "7", "20"]
    staff.http.close()


def test_the_kiosks_own_sync_delivers_two_instruments_to_a_postgresql_station(pg_url, station_factory, tmp_path):
    """Real `kiosk replay --data-dir` processes, one per instrument, configured with the station:
    the kiosk's own outbox and sync client deliver both results, which the station lists and
    exports each with its own instrument."""
    ward = make_ward(pg_url)
    station = station_factory(ward.db_url)
    data = tmp_path / "data"
    link = f"station: {{url: '{station.url}', token: '{ward.token}', kiosk_id: {ward.kiosk_id}}}\n"
    for name, extra, script in (
        ("barthel", "", PATIENTS / "barthel1.yaml"),
        ("mood", f"questionnaire: {MOOD4}\n", MOOD4_PATIENT),
    ):
        config = tmp_path / f"{name}.yaml"
        config.write_text(link + extra, encoding="utf-8")
        ran = subprocess.run(
            [sys.executable, "-m", "kiosk", "replay", str(script), "--data-dir", str(data), "--config", str(config)],
            capture_output=True,
            text=True,
            cwd=ROOT,
            timeout=300,
        )
        assert ran.returncode == 0 and ran.stderr == "", ran.stderr  # delivered before it exited
    staff = Staff(station.url)
    inbox = staff.http.get("/inbox").text
    assert "20 of 25 · Suggests depression" in inbox and "100 of 100 · Independent" in inbox
    (mood,) = re.findall(r'data-visit="(\w+)">\s*<a[^>]*><b>TB-0900</b>', inbox)  # a visit of its own
    page = staff.http.get(f"/sessions/{mood}")
    assert page.status_code == 200 and MOOD_TITLE in page.text
    bundle = staff.http.get(f"/sessions/{mood}/export.json").json()
    check_fhir(bundle)
    assert response_in(bundle)["questionnaire"].split("|")[0].endswith(":questionnaire:mood4-en")
    staff.http.close()
