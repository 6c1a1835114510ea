"""The visit's pages in Chromium (issue 36, part 1), on a real station process (SQLite) at a
phone's 360x740 and a desk's 1366x768: the inbox lists the battery as one row with its three
instruments; the visit page shows each instrument's total, band, state, staff items and changes
in words, and the TUG's place; one sign-off signs the three (the incomplete one only with a
reason: the form will not send without it, and the station refuses a post without it, naming it);
a result is amended from the visit's page. No page scrolls sideways."""

from __future__ import annotations

import re

import pytest

from station import db
from tests.station._battery import store_battery
from tests.station._visits import PATIENT
from tests.station.conftest import make_ward
from tests.station.helpers import Staff
from tests.station.test_visit_e2e import DESKTOP, fits, login

pytestmark = pytest.mark.slow
PHONE_SMALL = {"width": 360, "height": 740}
REASON = "patient too tired to be weighed; not to be repeated"


@pytest.mark.parametrize("viewport", [PHONE_SMALL, DESKTOP], ids=["360x740", "1366x768"])
def test_inbox_visit_sign_off_and_amend_in_chromium(browser, sqlite_url, station_factory, tmp_path, viewport) -> None:
    make_ward(sqlite_url)
    engine = db.open_database(sqlite_url)
    battery = store_battery(engine, tmp_path)
    engine.dispose()
    station = station_factory(sqlite_url)
    visit = f"/visits/{battery.order_id}"
    nurse = Staff(station.url, name="nurse.kim", role="nurse")
    doctor_http = Staff(station.url)
    try:
        changed = nurse.post(f"/sessions/{battery.mood}/items/satisfied", option="1", reason="misheard: she said yes")
        assert changed.status_code == 303, changed.text
        # the station refuses a sign-off without the incomplete result's reason, naming it
        step = doctor_http.http.get(visit + "/sign-off")
        seen = re.search(r'name="seen" value="([^"]+)"', step.text).group(1)
        refused = doctor_http.post(visit + "/sign-off", seen=seen)
        assert refused.headers["location"].startswith(visit + "/sign-off?message=")
        back = doctor_http.http.get(refused.headers["location"]).text
        assert "Walking: 2 items not answered (weight, aid): sign off as incomplete" in back
        assert "nothing was signed off" in back
    finally:
        nurse.http.close()
        doctor_http.http.close()

    context, page = login(browser, station.url, "dr.lopez", "doctor", viewport)
    try:
        page.goto(station.url + "/inbox")
        row = page.locator(f'#inbox li.result[data-visit="{battery.order_id}"]')
        assert row.locator(".instruments > li").count() == 3
        shown = [" ".join(t.split()) for t in row.locator(".instruments > li").all_inner_texts()]
        assert shown == [
            "Barthel Index 100 of 100 · Independent unreviewed",
            "Mood check (4 items) 15 of 25 · Suggests depression corrected",
            "Walking incomplete unreviewed",
        ]
        assert page.locator("#inbox li.result").count() == 2  # the battery and the walk-up: two visits
        assert page.locator("#waiting-count").inner_text() == "4"  # the count of results, as on every page
        fits(page, viewport)

        row.locator("a.open-result").click()
        page.wait_for_selector(".visit-result")
        assert page.locator("#visit-patient").inner_text() == PATIENT
        sections = page.locator(".visit-result")
        assert [sections.nth(i).locator(".instrument").inner_text() for i in range(3)] == [
            "Barthel Index",
            "Mood check (4 items)",
            "Walking",
        ]
        barthel, mood, walking = (sections.nth(i) for i in range(3))
        assert [barthel.locator(c).inner_text() for c in (".total", ".band", ".answered", ".result-state")] == [
            "100 of 100",
            "Independent",
            "the patient",
            "unreviewed",
        ]
        assert mood.locator(".changes li").inner_text() == (
            "Are you basically satisfied with your life?: “No” changed to “Yes” by nurse.kim (“misheard: she said yes”)"
        )
        assert walking.locator(".staff-items li").all_inner_texts() == [
            "Weight: not entered",
            "Uses a walking aid: not entered",
        ]
        assert "Not answered: Weight, Uses a walking aid." in walking.locator(".missing").inner_text()
        assert page.locator("#tug-results").count() == 0  # no TUG in this visit: no section for one
        fits(page, viewport)

        page.click("#sign-off-visit")
        page.wait_for_selector(".confirm-result")
        totals = page.locator(".confirm-total").all_inner_texts()
        assert totals == ["100 of 100 — Independent", "15 of 25 — Suggests depression", "incomplete"]
        assert page.locator(".confirm-state").all_inner_texts() == [
            "signed off",
            "amended with 1 change",
            "signed off as incomplete",
        ]
        assert "“No” changed to “Yes”" in page.locator(".confirm-changes").nth(1).inner_text()
        fits(page, viewport)
        page.click("#confirm-sign-off-visit")  # without the reason the browser does not send the form
        assert page.evaluate("document.querySelector('form.stack').checkValidity()") is False
        assert page.url.split("?")[0].endswith("/sign-off") and page.locator(".confirm-result").count() == 3
        page.fill(".incomplete-reason", REASON)
        page.click("#confirm-sign-off-visit")
        page.wait_for_selector("#visit-final")
        assert page.locator("p.message[role=status]").inner_text() == "Signed off: 3 results of the visit."
        assert page.locator(".visit-result .result-state").all_inner_texts() == ["signed off", "amended", "signed off"]
        assert page.locator("#waiting-count").inner_text() == "1"  # the walk-up alone waits
        fits(page, viewport)

        # amend after sign-off: per result, from the visit's page, back to it
        mood = page.locator(".visit-result").nth(1)
        mood.locator("details.amend summary").click()
        mood.locator("input[name=reason]").fill("the daughter says she is often bored")
        mood.locator("button.amend-result").click()
        page.wait_for_selector("#sign-off-visit")
        assert page.url.split("?")[0].endswith(visit)
        assert page.locator("#sign-off-visit").inner_text() == "Sign off the visit (1 result)"
        assert page.locator(".visit-result .result-state").nth(1).inner_text() == "corrected"
        fits(page, viewport)

        page.goto(f"{station.url}/patients/{PATIENT}")
        first = page.locator("#visits tbody.visit").first
        assert first.get_attribute("data-visit") == battery.order_id  # newest first
        assert first.locator("tr").count() == 3
        fits(page, viewport)
    finally:
        context.close()
