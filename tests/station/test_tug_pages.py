"""The Timed Up and Go on the station's pages, in Chromium against a real station process
(issue 34, parts 3 and 5): the session page of the visit shows the TUG (total time, phases,
quality flags, staff decision, worded against the site's threshold, never a diagnosis); the
patient's course has a row and a plot point per TUG time; the print view of the visit holds it;
the order form offers the Timed Up and Go and orders it. Every page fits a phone's width."""

from __future__ import annotations

import re

import pytest

from station import db
from tests.station._tug import store_tug_visits
from tests.station.conftest import make_ward
from tests.station.test_visit_e2e import DESKTOP, PHONE, fits, login

pytestmark = pytest.mark.slow
#: words that would turn a screening time into a diagnosis
DIAGNOSES = re.compile(r"\b(high|low) (fall )?risk\b|\bfaller\b|\bfrail\b", re.IGNORECASE)


def test_the_tug_on_the_visit_course_print_and_order_pages(browser, sqlite_url, station_factory, tmp_path) -> None:
    make_ward(sqlite_url)
    engine = db.open_database(sqlite_url)
    visits = store_tug_visits(engine, tmp_path)
    engine.dispose()
    station = station_factory(sqlite_url)
    context, page = login(browser, station.url, "dr.lopez", "doctor", PHONE)
    try:
        page.goto(f"{station.url}/sessions/{visits.barthel}")
        tug = page.locator(f"#tug-results [data-tug='{visits.camera}']")
        tug.wait_for()
        assert re.fullmatch(r"1\d\.\d s", tug.locator(".tug-total").inner_text())
        assert re.fullmatch(
            r"1\d\.\d s, not above the site's threshold \(13\.5 s\)\.", tug.locator(".tug-wording").inner_text()
        )
        assert tug.locator(".tug-decision").inner_text() == "dr-lee accepted the camera's time"
        phases = tug.locator(".tug-phases tbody tr")
        assert phases.count() == 5 and phases.nth(2).locator("td").nth(0).inner_text() == "Turn"
        flags = tug.locator(".tug-flags").inner_text()
        assert "whole body seen" in flags and "turn seen" in flags and "a person in " in flags
        assert "Get Up & Go rating: 3" in tug.locator(".tug-items").inner_text()
        assert "not a diagnosis" in page.inner_text("#tug-results")
        assert not DIAGNOSES.search(page.inner_text("body"))
        fits(page, PHONE)

        page.click("#print-visit")
        row = page.locator(f".print-tugs tr[data-tug='{visits.camera}']")
        row.wait_for()
        assert "not above the site's threshold" in row.locator(".tug-wording").inner_text()
        assert "dr-lee accepted" in row.locator(".signed").inner_text()

        page.goto(f"{station.url}/patients/{visits.patient_id}")
        page.wait_for_selector("#tug-course")
        rows = page.locator("#tug-course tbody tr")
        assert rows.count() == 2  # newest first
        assert rows.nth(1).locator(".tug-total").inner_text() == "15.5 s"
        assert "above the site's threshold (13.5 s)" in rows.nth(1).inner_text()
        assert page.locator("svg.tug-plot .tug-point").count() == 2
        assert page.locator("svg.tug-plot .tug-threshold").count() == 1
        assert not DIAGNOSES.search(page.inner_text("body"))
        fits(page, PHONE)

        rows.nth(1).locator("a").click()  # the staff visit's TUG alone: a page of its own
        page.wait_for_selector(f"[data-tug='{visits.stopwatch}']")
        assert "nurse-7 entered a stopwatch time" in page.inner_text(".tug-decision")
        assert "timed by staff with a stopwatch" in page.inner_text("#tug-results")
        with page.expect_download() as download:
            page.click("text=FHIR (JSON)")
        assert download.value.suggested_filename == f"tug-{visits.stopwatch}.fhir.json"
    finally:
        context.close()

    context, page = login(browser, station.url, "nurse.kim", "nurse", DESKTOP)
    try:
        page.goto(f"{station.url}/orders")
        label = page.locator("label", has=page.locator("#instrument-tug"))
        assert label.inner_text().startswith("Timed Up and Go")
        page.fill("input[name=patient_id]", "NHC-0034200")
        page.uncheck("input[name=instrument][value=barthel]")
        page.check("#instrument-tug")
        page.click("#place-order")  # the TUG alone: the kiosk gives it within a visit
        page.wait_for_selector("text=the Timed Up and Go is given within a visit: choose an instrument with it")
        page.check("input[name=instrument][value=barthel]")
        page.check("#instrument-tug")
        page.click("#place-order")
        page.wait_for_selector("#order-code")
        assert page.inner_text("#order-instruments") == "Barthel Index → Timed Up and Go"
    finally:
        context.close()
