"""The clinician's loop end to end, with every part real: a `kiosk station` process (SQLite at a
phone's 390x844, PostgreSQL at a desk's 1366x768), Chromium, the kiosk's own order watcher and a
real `kiosk replay --order-code` kiosk process. Staff order a visit; the kiosk is told (its
welcome greets the visit: see tests/kiosk/sync/test_orders_kiosk.py for the screen); staff confirm the
patient with the order's code at the kiosk; the patient answers; the doctor's inbox rings and
counts it; the doctor opens it, confirms the sign-off seeing the total; the patient's page shows
the visit. Every page the test visits fits the viewport's width (no sideways scrolling)."""

from __future__ import annotations

import subprocess
import sys
import threading

import pytest

from kiosk.sync.http import Station as StationHttp
from kiosk.sync.orders import OrderWatcher
from tests.station.conftest import PASSWORDS, PATIENCE_S, ROOT, make_ward

pytestmark = pytest.mark.slow
PHONE = {"width": 390, "height": 844}
DESKTOP = {"width": 1366, "height": 768}
RECORD_NOTIFICATIONS = """
window.__shown = [];
window.Notification = class { constructor(title, options) { window.__shown.push(title); }
  static get permission() { return "granted"; } static requestPermission() { return Promise.resolve("granted"); } };
"""


def login(browser, url: str, user: str, role: str, viewport):
    context = browser.new_context(viewport=viewport)
    context.add_init_script(RECORD_NOTIFICATIONS)
    page = context.new_page()
    page.set_default_timeout(PATIENCE_S * 1000)
    page.goto(url + "/login")
    page.fill("input[name=name]", user)
    page.fill("input[name=password]", PASSWORDS[role])
    page.click("button[type=submit]")
    page.wait_for_selector("#kiosks")
    return context, page


def fits(page, viewport) -> None:
    """No sideways scrolling: the document is no wider than the screen."""
    width = page.evaluate("document.documentElement.scrollWidth")
    assert width <= viewport["width"], f"{page.url} is {width} px wide on a {viewport['width']} px screen"


@pytest.mark.parametrize(
    ("viewport", "database"), [(PHONE, "sqlite"), (DESKTOP, "postgres")], ids=["phone-sqlite", "desktop-postgres"]
)
def test_order_greet_confirm_answer_ring_sign_off_course(
    browser, request, station_factory, tmp_path, viewport, database
):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)

    # the doctor's inbox is open, with sound on, before anything happens
    doctor_context, doctor = login(browser, station.url, "dr.lopez", "doctor", viewport)
    doctor.goto(station.url + "/inbox")
    doctor.click("#enable-sound")
    doctor.wait_for_selector("body[data-sound='on']", state="attached")
    doctor.wait_for_selector("body[data-live='1']", state="attached")
    assert doctor.locator("#waiting-count").inner_text() == "0"
    fits(doctor, viewport)

    # the kiosk listens for its orders with its own watcher (what its welcome shows)
    greeted: list = []
    arrived = threading.Event()

    def on_orders(found, problems):
        greeted[:] = found
        if found:
            arrived.set()

    watcher = OrderWatcher(
        StationHttp(station.url, ward.token),
        instruments=["barthel"],
        languages=["en", "es", "fr"],
        on_orders=on_orders,
        poll_wait_s=20,
    )
    watcher.start()

    # a nurse orders the visit on her phone (or the doctor at the desk)
    nurse_context, nurse = login(browser, station.url, "nurse.kim", "nurse", viewport)
    fits(nurse, viewport)
    nurse.goto(station.url + "/orders")
    fits(nurse, viewport)
    nurse.fill("input[name=patient_id]", "NHC-0042")
    nurse.select_option("select[name=kiosk]", ward.kiosk_id)
    nurse.click("#place-order")
    code = nurse.locator("#order-code").inner_text()
    assert nurse.locator("#order-state").inner_text() == "ordered"
    fits(nurse, viewport)
    try:
        assert arrived.wait(PATIENCE_S), "the kiosk was never told of the order"
    finally:
        watcher.stop()
    assert [o.patient_id for o in greeted] == ["NHC-0042"]

    # at the kiosk staff type the code; the scripted patient answers; the kiosk delivers
    config = tmp_path / "kiosk.yaml"
    config.write_text(f"station: {{url: '{station.url}', token: '{ward.token}', kiosk_id: {ward.kiosk_id}}}\n")
    kiosk = subprocess.run(
        [
            sys.executable,
            "-m",
            "kiosk",
            "replay",
            str(ROOT / "recordings/patients/barthel1.yaml"),
            "--data-dir",
            str(tmp_path / "kiosk"),
            "--config",
            str(config),
            "--order-code",
            code,
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=300,
    )
    assert kiosk.returncode == 0, kiosk.stderr
    assert "patient NHC-0042" in kiosk.stdout

    # the inbox rings, notifies, counts, and lists the result
    doctor.wait_for_selector("body[data-audible]", state="attached")
    doctor.wait_for_selector("#waiting-count.some", state="attached")
    assert doctor.locator("#waiting-count").inner_text() == "1"
    doctor.wait_for_selector("#inbox li.result:has-text('NHC-0042')")
    assert any("Result waiting: NHC-0042" in title for title in doctor.evaluate("window.__shown"))
    nurse.wait_for_selector("#order-state:text-is('awaiting validation')")  # the order's page follows live
    assert nurse.locator("#order-code").count() == 0
    fits(doctor, viewport)

    # the doctor opens the visit, asks to sign it off, sees each total, confirms once
    doctor.click("#inbox li.result a.open-result")
    doctor.wait_for_selector(".visit-result .total")
    assert doctor.get_attribute("#visit-order", "href").startswith("/orders/order-")  # the visit links to its order
    fits(doctor, viewport)
    total = doctor.locator(".visit-result .total").inner_text()
    assert total.endswith(" of 100")
    doctor.click("#sign-off-visit")
    assert total in doctor.locator(".confirm-total").inner_text()
    assert doctor.locator(".confirm-state").inner_text() == "signed off"
    fits(doctor, viewport)
    doctor.click("#confirm-sign-off-visit")
    doctor.wait_for_selector("#visit-final")
    assert doctor.locator("p.message[role=status]").inner_text() == "Signed off: 1 result of the visit."
    assert doctor.locator(".visit-result .result-state").inner_text() == "signed off"
    assert doctor.locator(".visit-result .signed").inner_text().startswith("dr.lopez, ")
    doctor.wait_for_selector("#waiting-count:not(.some)", state="attached")
    # the result's own page still says it, and links back to its visit
    doctor.click(".visit-result a.open-session")
    assert doctor.locator("#review-words").inner_text().startswith("Signed off as recorded by dr.lopez")
    assert doctor.locator("#visit-line").inner_text().startswith("Ordered visit")
    assert doctor.get_attribute("#open-visit", "href").startswith("/visits/")

    # the patient's course shows the visit: total, band, review state, ordered, and the plot's point
    doctor.goto(station.url + "/patients")
    doctor.fill("input[name=q]", "nhc-004")  # by the identifier's start, typed in lower case
    doctor.click("form[role=search] button")
    fits(doctor, viewport)
    doctor.click("#patients a:has-text('NHC-0042')")
    doctor.wait_for_selector("#visits")
    visit = doctor.locator("#visits tbody tr").first.inner_text()
    assert total in visit and "signed off" in visit and "ordered" in visit
    assert doctor.locator("svg.course-plot circle.visit-point").count() == 1
    fits(doctor, viewport)
    nurse.wait_for_selector("#order-state:text-is('signed off')")
    doctor_context.close()
    nurse_context.close()
