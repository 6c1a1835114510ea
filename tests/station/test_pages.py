"""The station's pages in real Chromium: an alert appears live with a sound and a notification and
stays until acknowledged (who and when recorded), staff continue a session after a doctor call
(the kiosk's long poll receives it), a clinician corrects an item and a doctor signs off. At a
phone's width and a desktop's."""

from __future__ import annotations

import json
import threading
import time
from dataclasses import replace

import pytest
import sqlalchemy as sa

from station import db
from station.sync import RAISES as RAISING
from tests.station.conftest import PASSWORDS, PATIENCE_S, new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, record_patient

pytestmark = pytest.mark.slow
PHONE = {"width": 390, "height": 844}
DESKTOP = {"width": 1366, "height": 900}
#: headless Chromium has no notification centre: record what the page asks it to show
RECORD_NOTIFICATIONS = """
window.__shown = [];
window.Notification = class { constructor(title, options) { window.__shown.push(title); }
  static get permission() { return "granted"; } static requestPermission() { return Promise.resolve("granted"); } };
"""
WAIT_MS = PATIENCE_S * 1000


@pytest.fixture
def ward(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    client = KioskClient(station.url, token, name)
    yield station, replace(ward, token=token, kiosk_id=name), client
    client.close()


def open_page(browser, station, user: str, role: str, viewport):
    context = browser.new_context(viewport=viewport)
    context.add_init_script(RECORD_NOTIFICATIONS)
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    page.goto(station.url + "/")
    page.fill("input[name=name]", user)
    page.fill("input[name=password]", PASSWORDS[role])
    page.click("button[type=submit]")
    page.wait_for_selector("#kiosks")
    return context, page


def _wait_for_beeps(page) -> None:
    """Until the page has beeped. Waits use selectors and one-off evaluations: the station's page
    forbids eval (CSP ``default-src 'self'``), and Playwright's wait_for_function re-evaluates its
    string predicate with eval once it has to poll, which failed the test whenever the state came late."""
    deadline = time.monotonic() + PATIENCE_S
    while page.evaluate("window.station.beeps") == 0:
        assert time.monotonic() < deadline, "the page never beeped"
        page.wait_for_timeout(50)  # lets the page run; bounded by PATIENCE_S


@pytest.mark.parametrize("viewport", [PHONE, DESKTOP], ids=["phone", "desktop"])
def test_an_alert_sounds_and_notifies_until_acknowledged(browser, ward, viewport):
    station, ward, kiosk = ward
    rows = record_patient(PATIENTS / "barthel6.yaml")
    alert = next(r for r in rows if r.alert and r.payload["kind"] in RAISING)
    context, page = open_page(browser, station, "nurse.kim", "nurse", viewport)
    page.click("#enable-sound")
    page.wait_for_selector("body[data-live='1']", state="attached")
    assert page.locator("#alerts li").count() == 0
    kiosk.sync([alert])
    item = page.locator(f"#alerts li:has-text('{ward.kiosk_id}')")
    item.wait_for()
    page.wait_for_selector("body[data-sounding='1']", state="attached")
    _wait_for_beeps(page)
    assert any(ward.kiosk_id in title for title in page.evaluate("window.__shown"))
    assert item.locator("button.ack").is_visible()  # reachable at this width
    item.locator("button.ack").click()
    page.wait_for_selector(f"#alerts li:has-text('{ward.kiosk_id}')", state="detached")
    page.wait_for_selector("body[data-sounding='0']", state="attached")
    engine = db.make_engine(ward.db_url)
    with engine.connect() as connection:
        row = connection.execute(
            sa.select(db.alerts.c.ack_by, db.alerts.c.ack_at).where(db.alerts.c.kiosk_id == ward.kiosk_id)
        ).one()
    engine.dispose()
    assert row.ack_by == "nurse.kim" and row.ack_at
    context.close()


def test_continue_after_a_doctor_call_reaches_the_kiosk(browser, ward):
    station, ward, kiosk = ward
    rows = record_patient(PATIENTS / "barthel5.yaml")
    call = next(r for r in rows if r.alert and r.payload["kind"] == "doctor_called")
    kiosk.sync([r for r in rows if r.seq <= call.seq])
    context, page = open_page(browser, station, "nurse.kim", "nurse", PHONE)
    page.wait_for_selector("body[data-live='1']", state="attached")
    kiosk.status(
        session_id=call.session_id, patient_id="TB-0005", phase="questions", question=4, of=10, doctor_called=True
    )
    tile = page.locator(f"#kiosk-{ward.kiosk_id}")
    tile.locator("text=doctor called").wait_for()
    got: list = []
    poll = threading.Thread(target=lambda: got.extend(kiosk.commands(wait=25)))
    poll.start()
    tile.locator("button.cmd-continue").click()
    poll.join(PATIENCE_S)
    assert [(c["kind"], c["session_id"], c["by"]) for c in got] == [("continue", call.session_id, "nurse.kim")]
    # continuing answered the doctor call: its alert is acknowledged by the same nurse
    page.wait_for_selector(f"#alerts li:has-text('{ward.kiosk_id}')", state="detached")
    context.close()


def test_a_clinician_corrects_an_item_and_only_a_doctor_signs_off(browser, ward):
    station, ward, kiosk = ward
    rows = record_patient(PATIENTS / "barthel1.yaml")
    assert kiosk.sync(rows).status_code == 200
    session = rows[0].session_id
    recorded = next(r.payload["option"] for r in rows if r.kind == "record_answer" and r.payload["item_id"] == "stairs")
    new = 1 if recorded != 1 else 2

    context, page = open_page(browser, station, "nurse.kim", "nurse", PHONE)
    page.goto(f"{station.url}/sessions/{session}")
    row = page.locator("#item-stairs")
    row.locator("summary").click()
    # on the phone the open form fits the screen and every control takes a thumb (44 px and more)
    assert page.evaluate("document.documentElement.scrollWidth") <= PHONE["width"]
    for control in ("select[name=option]", "input[name=reason]", "button[type=submit]"):
        box = row.locator(control).bounding_box()
        assert box["x"] >= 0 and box["x"] + box["width"] <= PHONE["width"] and box["height"] >= 44, (control, box)
    assert row.locator("button[type=submit]").inner_text() == "Record change"
    row.locator("select[name=option]").select_option(str(new))
    row.locator("input[name=reason]").fill("patient uses the lift; confirmed by physio")
    row.locator("button[type=submit]").click()
    page.locator("text=Change recorded.").wait_for()
    assert "only a doctor can sign off" in page.content().lower()
    assert page.locator("#sign-off").count() == 0
    context.close()

    context, page = open_page(browser, station, "dr.lopez", "doctor", DESKTOP)
    page.goto(f"{station.url}/sessions/{session}")
    changed = page.locator("#item-stairs")
    assert f"was {recorded} → {new} by nurse.kim" in changed.inner_text()
    assert "kiosk recorded" in changed.inner_text()
    total = page.locator("#total").inner_text()
    page.locator("#sign-off").click()  # asks first: the total, the change, what it will be called
    assert total in page.locator("#confirm-total").inner_text()
    assert page.locator("#confirm-state").inner_text() == "amended"
    assert f"option {recorded} → option {new}" in page.locator("#confirm-changes").inner_text()
    page.locator("#confirm-sign-off").click()
    page.locator("#review-words").wait_for()
    text = page.locator("#review-words").inner_text()
    assert text.startswith("Amended: signed off with 1 change by dr.lopez")
    assert page.locator("h1 .badge[class*=review-]").inner_text() == "amended"  # the words and the badge agree
    trail = page.locator("table.trail").inner_text()
    assert "nurse.kim" in trail and "stairs" in trail and "sign off" in trail
    assert page.locator("details summary").count() == 0  # final: nothing left to change
    context.close()


def test_a_doctor_reopens_a_signed_result_amends_it_and_signs_again(browser, ward):
    station, ward, kiosk = ward
    rows = record_patient(PATIENTS / "barthel1.yaml")
    assert kiosk.sync(rows).status_code == 200
    session = rows[0].session_id
    context, page = open_page(browser, station, "dr.lopez", "doctor", PHONE)
    page.goto(f"{station.url}/sessions/{session}")
    page.locator("#sign-off").click()
    assert page.locator("#confirm-state").inner_text() == "signed off"  # the step asks first
    page.locator("#confirm-sign-off").click()
    page.locator("#review-words").wait_for()
    assert page.locator("#review-state").inner_text() == "signed off"
    page.locator("input[name=reason]").fill("physiotherapist: needs help on stairs")
    page.locator("#amend").click()
    page.locator("#reopened").wait_for()
    assert page.locator("#review-state").inner_text() == "corrected" and page.locator("#amend").count() == 0
    row = page.locator("#item-stairs")
    row.locator("summary").click()
    row.locator("select[name=option]").select_option("2")
    row.locator("input[name=reason]").fill("seen on the stairs")
    row.locator("button[type=submit]").click()
    page.locator("text=Change recorded.").wait_for()
    page.locator("#sign-off").click()
    assert page.locator("#confirm-state").inner_text() == "amended"
    assert "95 of 100" in page.locator("#confirm-total").inner_text()
    page.locator("#confirm-sign-off").click()
    page.locator("#review-words").wait_for()
    assert page.locator("#review-state").inner_text() == "amended"
    assert page.locator("#total").inner_text() == "95"
    trail = page.locator("table.trail").inner_text()
    assert trail.count("sign off") == 2 and "physiotherapist: needs help on stairs" in trail
    assert page.locator("#amend").count() == 1  # signed again: it can be amended again
    page.goto(station.url + "/")  # the ward page's period export: today's signed-off results
    with page.expect_download() as download:
        page.locator("form.period-export button").click()
    bundle = json.loads(download.value.path().read_text(encoding="utf-8"))
    assert any(
        e["resource"]["identifier"]["value"].endswith(session)
        for e in bundle["entry"]
        if e["resource"]["resourceType"] == "QuestionnaireResponse"
    )
    context.close()
