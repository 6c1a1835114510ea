"""The pages of issue 36's identity and orders in real Chromium at a phone's width, against a real
station process: a second visit on a busy kiosk is warned and ordered with "Order anyway";
cancelling a running visit says it runs on the kiosk, the ward's tile and Results then say
"cancelled" and the kiosk's poll lists it; a walk-up result is given its hospital identifier
(a name refused) and the page names it."""

from __future__ import annotations

from dataclasses import replace

import pytest

from tests.station.conftest import PASSWORDS, PATIENCE_S, new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, record_patient

pytestmark = pytest.mark.slow
PHONE = {"width": 390, "height": 844}


@pytest.fixture
def ward(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    client = KioskClient(station.url, token, name)
    yield station, replace(ward, token=token, kiosk_id=name), client
    client.close()


def open_page(browser, station, user: str, role: str):
    context = browser.new_context(viewport=PHONE)
    page = context.new_page()
    page.set_default_timeout(PATIENCE_S * 1000)
    page.goto(station.url + "/")
    page.fill("input[name=name]", user)
    page.fill("input[name=password]", PASSWORDS[role])
    page.click("button[type=submit]")
    page.wait_for_selector("#kiosks")
    return context, page


def fits(page) -> None:
    width = page.evaluate("document.documentElement.scrollWidth")
    assert width <= PHONE["width"], f"{page.url} is {width} px wide on a {PHONE['width']} px phone"


def place(page, station, kiosk: str, patient: str) -> None:
    page.goto(station.url + "/orders")
    page.fill("input[name=patient_id]", patient)
    page.select_option("select[name=kiosk]", kiosk)
    page.click("#place-order")


def test_a_busy_kiosk_warns_and_a_running_visit_is_cancelled_in_words(browser, ward):
    station, ward, kiosk = ward
    context, page = open_page(browser, station, "nurse.kim", "nurse")
    place(page, station, ward.kiosk_id, "NHC-0036401")
    page.wait_for_selector("#order-code")
    first_url, code = page.url, page.inner_text("#order-code")

    place(page, station, ward.kiosk_id, "NHC-0036402")  # the kiosk already has an open visit
    warning = page.inner_text("#order-warning")
    assert f"kiosk {ward.kiosk_id} already has 1 open visit of other patients" in warning
    assert page.input_value("input[name=patient_id]") == "NHC-0036402" and page.is_checked("input[value=barthel]")
    fits(page)
    page.click("#order-anyway")
    page.wait_for_selector("#order-code")
    assert "NHC-0036402" in page.inner_text("h1")

    # the first visit starts at the kiosk and runs its first question
    assert kiosk.start_order(code).status_code == 200
    order_id = first_url.rsplit("/", 1)[1]
    rows = record_patient(PATIENTS / "barthel1.yaml", patient="NHC-0036401", visit=f"order {order_id}")
    first_answer = next(i for i, r in enumerate(rows) if r.kind == "record_answer")
    assert kiosk.sync(rows[:first_answer]).status_code == 200
    session_id = rows[0].session_id
    kiosk.status(session_id=session_id, patient_id="NHC-0036401", phase="questions", question=1, of=10)

    page.goto(first_url)
    assert page.inner_text("#cancel-running").startswith(f"The visit is running on kiosk {ward.kiosk_id}")
    asked: list[str] = []
    page.once("dialog", lambda dialog: (asked.append(dialog.message), dialog.accept()))
    page.fill("input[name=reason]", "patient discharged")
    page.click("#cancel-order")
    page.wait_for_selector("#order-state:has-text('cancelled')")
    assert asked == [
        f"The visit is running on kiosk {ward.kiosk_id}: cancelling ends it. Cancel the visit of NHC-0036401?"
    ]
    fits(page)

    page.goto(station.url + "/")
    tile = page.locator(f"#kiosk-{ward.kiosk_id}")
    assert tile.locator(".badge.cancelled").inner_text() == "visit cancelled: the kiosk is ending it"
    row = page.locator(f"#results li[data-session='{session_id}']")
    assert row.locator(".badge.status").inner_text() == "cancelled"
    fits(page)
    polled = kiosk.http.get("/api/v1/orders", params={"held": order_id}).json()
    assert polled["cancelled"] == [order_id] and [o["patient_id"] for o in polled["orders"]] == ["NHC-0036402"]
    context.close()


def test_a_walk_up_result_is_given_its_hospital_identifier(browser, ward):
    station, ward, kiosk = ward
    rows = record_patient(PATIENTS / "barthel1.yaml", visit="walk-up")
    assert kiosk.sync(rows).status_code == 200
    session_id, made_up = rows[0].session_id, rows[0].payload["patient_id"]
    context, page = open_page(browser, station, "nurse.kim", "nurse")
    page.goto(f"{station.url}/sessions/{session_id}")
    page.fill("#identify-patient", "Maria Lopez")
    page.once("dialog", lambda dialog: dialog.accept())
    page.click("#identify-go")
    page.wait_for_selector("p.message:has-text('never a name')")
    assert made_up in page.inner_text("h1")

    asked: list[str] = []
    page.once("dialog", lambda dialog: (asked.append(dialog.message), dialog.accept()))
    page.fill("#identify-patient", "NHC-0036403")
    page.fill("#identify-form input[name=reason]", "wristband checked")
    page.click("#identify-go")
    page.wait_for_selector("h1:has-text('Patient NHC-0036403')")
    assert made_up in asked[0] and "audit trail" in asked[0]
    trail = page.inner_text(".trail")
    assert "nurse.kim" in trail and f"patient identifier {made_up} -> NHC-0036403: wristband checked" in trail
    fits(page)
    context.close()
