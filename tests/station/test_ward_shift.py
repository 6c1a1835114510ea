"""The ward page through a shift, in Chromium with a phone's audio rule (no sound before a touch on
the page): sound switched on stays on through staff's actions (sent without reloading the page) and,
after a page load, comes back with the first touch; staff's own "Patient away" raises no alert;
an alert closes by itself when its situation ends; messages are in words; a result arriving on
another page rings audibly; the ward page with a running kiosk fits a 390 px phone."""

from __future__ import annotations

from dataclasses import replace

import pytest
import sqlalchemy as sa

from station import db
from tests.station.conftest import PASSWORDS, PATIENCE_S, make_ward, new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, Row, record_patient

pytestmark = pytest.mark.slow
PHONE = {"width": 390, "height": 844}


#: Headless Chromium plays Web Audio without any gesture (it ignores --autoplay-policy), so the
#: phone's rule is applied here in the page: an AudioContext runs only once the document has had a
#: real user activation, as Chromium itself reports it (navigator.userActivation, which a
#: navigation resets). Only the gate is added; the activation and the audio are Chromium's own.
GESTURE_POLICY = """
(() => {
  const Real = window.AudioContext;
  window.AudioContext = class extends Real {
    constructor(...args) { super(...args); if (!navigator.userActivation.hasBeenActive) super.suspend(); }
    resume() { return navigator.userActivation.hasBeenActive ? super.resume() : Promise.resolve(); }
  };
})();
"""


def event(seq: int, session_id: str, kind: str, t: float) -> Row:
    return Row(seq, "record_event", session_id, {"t": t, "kind": kind, "detail": ""}, t, "2026-11-26T09:00:00Z")


def alert_rows(db_url: str, kiosk: str) -> list:
    engine = db.make_engine(db_url)
    with engine.connect() as connection:
        rows = connection.execute(
            sa.select(db.alerts.c.kind, db.alerts.c.ack_by)
            .where(db.alerts.c.kiosk_id == kiosk)
            .order_by(db.alerts.c.id)
        ).all()
    engine.dispose()
    return [tuple(r) for r in rows]


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_sound_stays_on_own_actions_are_quiet_and_alerts_close_themselves(browser, request, station_factory, database):
    ward = make_ward(request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url"))
    station = station_factory(ward.db_url)
    name, token = new_kiosk(ward.db_url)
    kiosk = KioskClient(station.url, token, name)
    rows = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-5150")
    finish = next(r for r in rows if r.kind == "finish_session")
    before = [r for r in rows if r.seq < finish.seq]
    session = rows[0].session_id
    assert kiosk.sync(before).status_code == 200
    kiosk.status(session_id=session, patient_id="NHC-5150", phase="questions", question=4, of=10)

    context = browser.new_context(viewport=PHONE)
    context.add_init_script(GESTURE_POLICY)
    page = context.new_page()
    page.set_default_timeout(PATIENCE_S * 1000)
    page.goto(station.url + "/login")
    page.fill("input[name=name]", "nurse.kim")
    page.fill("input[name=password]", PASSWORDS["nurse"])
    page.click("button[type=submit]")
    tile = page.locator(f"#kiosk-{name}")
    tile.locator("button.cmd-person_away").wait_for()
    assert page.evaluate("document.documentElement.scrollWidth") <= PHONE["width"]
    page.click("#enable-sound")
    page.wait_for_selector("body[data-sound='on']", state="attached")
    page.wait_for_selector("body[data-live='1']", state="attached")
    page.evaluate("window.__same_page = true")

    # staff's own action: sent without leaving the page, said in words, and raises no alert
    tile.locator("button.cmd-person_away").click()
    page.wait_for_selector("#action-message:has-text('Told')", state="attached")
    assert page.locator("#action-message").inner_text() == f"Told {name} the patient is away from it."
    (command,) = kiosk.commands()
    assert command["kind"] == "person_away"
    kiosk.ack(command["id"])
    assert kiosk.sync([event(finish.seq + 1, session, "person_lost", 300.0)]).status_code == 200
    kiosk.status(session_id=session, patient_id="NHC-5150", phase="questions", question=4, of=10, person_away=True)
    tile.locator(".badge:has-text('patient away')").wait_for()
    assert alert_rows(ward.db_url, name) == []  # leaving alerts no one until away as long as the site says
    away = replace(
        event(finish.seq + 2, session, "away_alert", 360.0), payload={"t": 360.0, "kind": "away_alert", "detail": "60"}
    )
    assert kiosk.sync([away]).status_code == 200
    assert alert_rows(ward.db_url, name) == [("person_lost", "nurse.kim")]  # stored, closed by its sender
    assert page.locator("#alerts li").count() == 0
    assert page.evaluate("window.__same_page") is True  # no reload: the audio stayed on
    assert page.get_attribute("body", "data-sound") == "on"

    # a doctor call rings; it closes by itself when the doctor's call is answered at the kiosk
    assert kiosk.sync([event(finish.seq + 3, session, "doctor_called", 370.0)]).status_code == 200
    page.locator(f"#alerts li:has-text('{name}')").wait_for()
    page.wait_for_selector("body[data-audible]", state="attached")
    assert kiosk.sync([event(finish.seq + 4, session, "doctor_continued", 390.0)]).status_code == 200
    page.wait_for_selector(f"#alerts li:has-text('{name}')", state="detached")
    page.wait_for_selector("body[data-sounding='0']", state="attached")
    assert alert_rows(ward.db_url, name)[1] == ("doctor_called", "closed: situation ended")

    # another page: its audio waits for a touch there (the button says so); the first touch
    # anywhere brings it back, without pressing the button again
    page.goto(station.url + "/inbox")
    page.wait_for_selector("body[data-sound='paused']", state="attached")
    assert page.locator("#enable-sound").inner_text() == "Sound paused: tap anywhere to resume"
    page.wait_for_selector("body[data-live='1']", state="attached")
    page.mouse.click(200, 600)  # a touch anywhere on the page
    page.wait_for_selector("body[data-sound='on']", state="attached")
    assert kiosk.sync([replace(finish, seq=finish.seq + 5)]).status_code == 200
    page.wait_for_selector("body[data-audible]", state="attached")
    page.wait_for_selector("#inbox li.result:has-text('NHC-5150')")
    context.close()
    kiosk.close()
