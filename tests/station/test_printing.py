"""A visit printed for the paper chart (issue 36, part 3), on SQLite and PostgreSQL: every
instrument of the visit's order with its title, total, band, who answered and who signed it and
when; the patient's course as its visits, oldest first. In Chromium (a real station process) the
print media hides the navigation and the forms and shows those fields, and the PDF Chromium
prints of the page, read back, holds them, with times in the station's local zone."""

from __future__ import annotations

import io
from zoneinfo import ZoneInfo

import pytest

from kiosk.core.questionnaire import load_questionnaire
from station import db, printing
from station.sessions import NotFound
from tests.station._visits import PATIENT, store_visits
from tests.station.conftest import make_ward
from tests.station.test_visit_e2e import DESKTOP, login

MADRID = ZoneInfo("Europe/Madrid")


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request):
    url = request.getfixturevalue("sqlite_url" if request.param == "sqlite" else "pg_url")
    make_ward(url)
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def test_a_visit_prints_every_instrument_of_its_order(engine) -> None:
    visits = store_visits(engine)
    q = load_questionnaire()
    printed = printing.visit(engine, q, visits.mood, zone=MADRID)
    assert printing.visit(engine, q, visits.barthel, zone=MADRID) == printed  # either session: one visit
    assert (printed.patient_id, printed.order_id, printed.date) == (PATIENT, visits.order_id, "2026-11-20 11:15 CET")
    barthel, mood = printed.results  # in the order's order: Barthel, then MOOD4
    assert (barthel.title, barthel.total_words, barthel.band, barthel.answered_by) == (
        "Barthel Index",
        "100 of 100",
        "Independent",
        "the patient",
    )
    assert barthel.signed_by == "dr.lopez" and barthel.signed_at.endswith(("CET", "CEST"))
    assert (mood.title, mood.total_words, mood.band, mood.signed_by, mood.review) == (
        "Mood check (4 items)",
        "20 of 25",
        "Suggests depression",
        "",
        "unreviewed",
    )
    with pytest.raises(NotFound):
        printing.visit(engine, q, "no-such-session")


def test_a_course_prints_each_visit_oldest_first(engine) -> None:
    visits = store_visits(engine)
    course = printing.course(engine, load_questionnaire(), PATIENT, zone=MADRID)
    assert [v.date for v in course] == ["2026-10-02 11:30 CEST", "2026-11-20 11:15 CET"]
    assert [[r.session_id for r in v.results] for v in course] == [
        [visits.walk_up],
        [visits.barthel, visits.mood],
    ]
    assert course[0].order_id is None
    assert printing.course(engine, load_questionnaire(), "NHC-9999999") == []


def test_shown_time_reads_what_is_stored() -> None:
    assert printing.shown_time("2026-07-01T08:00:00Z", MADRID) == "2026-07-01 10:00 CEST"
    assert printing.shown_time("2026-07-01T08:00:00.123+00:00", ZoneInfo("UTC")) == "2026-07-01 08:00 UTC"
    assert printing.shown_time(None) == "" and printing.shown_time("yesterday") == "yesterday"


@pytest.mark.slow
def test_print_view_and_its_pdf_in_chromium(browser, sqlite_url, station_factory, monkeypatch) -> None:
    from pypdf import PdfReader

    make_ward(sqlite_url)
    engine = db.open_database(sqlite_url)
    visits = store_visits(engine)
    engine.dispose()
    monkeypatch.setenv("TZ", "Europe/Madrid")  # the station process's local zone
    station = station_factory(sqlite_url)
    context, page = login(browser, station.url, "dr.lopez", "doctor", DESKTOP)
    try:
        page.goto(f"{station.url}/sessions/{visits.mood}")
        page.click("#print-visit")
        page.wait_for_selector(".print-visit")
        assert page.is_visible("nav") and page.is_visible("button[data-print]")  # on screen: the page's tools
        page.emulate_media(media="print")
        assert not page.is_visible("header.bar") and not page.is_visible("nav")
        assert all(not f.is_visible() for f in page.query_selector_all("form, button"))
        rows = page.locator(".print-results tbody tr")
        assert rows.count() == 2
        first = [rows.nth(0).locator(c).inner_text() for c in (".instrument", ".total", ".band", ".answered")]
        assert first == ["Barthel Index", "100 of 100", "Independent", "the patient"]
        assert rows.nth(0).locator(".signed").inner_text().startswith("dr.lopez, 2026-")
        assert "not signed off" in rows.nth(1).locator(".signed").inner_text()
        text = " ".join(p.extract_text() for p in PdfReader(io.BytesIO(page.pdf(format="A4"))).pages)
        for shown in (
            PATIENT,
            "2026-11-20 11:15 CET",
            "Barthel Index",
            "100 of 100",
            "Independent",
            "Mood check (4 items)",
            "20 of 25",
            "Suggests depression",
            "the patient",
            "dr.lopez",
        ):
            assert shown in text, f"{shown!r} is not in the printed PDF:\n{text}"
        assert "Results waiting" not in text and "Log out" not in text  # no navigation on paper

        page.goto(f"{station.url}/patients/{PATIENT}/print")
        page.wait_for_selector(".print-visit")
        text = " ".join(p.extract_text() for p in PdfReader(io.BytesIO(page.pdf(format="A4"))).pages)
        assert "2026-10-02 11:30 CEST" in text and "2026-11-20 11:15 CET" in text
        for missing in ("/sessions/no-such-session/print", "/patients/NHC-9999999/print"):
            answer = page.goto(station.url + missing)
            assert answer is not None and answer.status == 404, missing
            assert "has reached this station" in page.inner_text("body")
    finally:
        context.close()
