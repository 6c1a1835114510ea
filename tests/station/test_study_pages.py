"""The validation study's pages on a real station process: the clinician's result form refuses a
logged-out browser, a kiosk's token and a form without its CSRF token (nothing stored), and stores
a nurse's answers with her name; the study's CSV downloads and reads back to the study's figures
(SQLite and PostgreSQL). In Chromium, on a phone and a desk: from a result's page to the form,
answers chosen by their labels, then the Validation page with its ICC and kappas."""

from __future__ import annotations

import csv
import io
from datetime import date

import httpx
import pytest

from kiosk.core.questionnaire import load_questionnaire
from station import auth, db, reference, study
from tests.station._study_visits import store_study_visits
from tests.station.conftest import make_ward
from tests.station.helpers import Staff
from tests.station.test_visit_e2e import DESKTOP, fits, login

pytestmark = pytest.mark.slow

PHONE = {"width": 360, "height": 740}
STUDY = "/study?instrument=barthel&from=2026-11-01&to=2026-11-20"


def _ward(db_url: str, entered: range = range(1, 4)):
    """A ward with the study's results, the clinician's answers entered for sessions ``entered``;
    returns the kiosk's token."""
    ward = make_ward(db_url)
    engine = db.open_database(db_url)
    visits = store_study_visits(engine)
    for n in entered:
        chosen = {item_id: str(option) for item_id, option in visits.clinician[n].items()}
        reference.record_answers(
            engine, load_questionnaire(), visits.session_ids[n], chosen, auth.User("dr.lopez", "doctor")
        )
    engine.dispose()
    return ward.token, visits


def _stored(db_url: str, session_id: str) -> dict:
    engine = db.make_engine(db_url)
    try:
        with engine.connect() as connection:
            return reference.answers_in(connection, [session_id]).get(session_id, {})
    finally:
        engine.dispose()


@pytest.mark.parametrize("database", ["sqlite", "postgresql"])
def test_the_form_refuses_and_stores_and_the_csv_reads_back(request, station_factory, database) -> None:
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    token, _ = _ward(db_url)
    station = station_factory(db_url)
    form = {"item-transfers": "3", "item-feeding": "2"}
    anyone = httpx.Client(base_url=station.url, timeout=30)
    refused = anyone.post("/sessions/study-0/reference", data=form)
    assert refused.status_code == 303 and refused.headers["location"].startswith("/login")
    kiosk = httpx.Client(base_url=station.url, timeout=30, headers={"Authorization": f"Bearer {token}"})
    for response in (kiosk.post("/sessions/study-0/reference", data=form), kiosk.get(STUDY)):
        assert response.status_code == 303 and response.headers["location"].startswith("/login")
    nurse = Staff(station.url, "nurse.kim", "nurse")
    assert nurse.http.post("/sessions/study-0/reference", data=form).status_code == 403  # no CSRF token
    assert _stored(db_url, "study-0") == {}

    page = nurse.http.get("/sessions/study-0")
    assert 'href="/sessions/study-0/reference"' in page.text
    stored = nurse.post("/sessions/study-0/reference", **form)
    assert stored.status_code == 303 and "2%20clinician%27s%20answers%20stored" in stored.headers["location"]
    answers = _stored(db_url, "study-0")
    assert {i: (a.option, a.entered_by) for i, a in answers.items()} == {
        "transfers": (3, "nurse.kim"),
        "feeding": (2, "nurse.kim"),
    }
    wrong = nurse.post("/sessions/study-0/reference", **{"item-stairs": "9"})
    assert "stairs" in wrong.headers["location"] and "stairs" not in _stored(db_url, "study-0")

    download = nurse.http.get(STUDY.replace("/study", "/study.csv"))
    assert download.status_code == 200 and download.headers["content-type"].startswith("text/csv")
    assert "agreement-barthel-2026-11-01-2026-11-20.csv" in download.headers["content-disposition"]
    rows = list(csv.reader(io.StringIO(download.text)))
    engine = db.make_engine(db_url)
    try:
        found = study.study(engine, load_questionnaire(), "barthel", date(2026, 11, 1), date(2026, 11, 20))
    finally:
        engine.dispose()
    icc = next(r for r in rows if r and r[0] == "icc_2_1")
    assert (int(icc[2]), float(icc[3])) == (found.totals, round(found.icc.estimate.value, 4))
    assert nurse.http.get("/study.csv?instrument=barthel&from=monday&to=2026-11-20").status_code == 400


@pytest.mark.parametrize("viewport", [PHONE, DESKTOP], ids=["phone", "desktop"])
def test_the_form_and_the_study_page_in_chromium(browser, sqlite_url, station_factory, viewport) -> None:
    _, visits = _ward(sqlite_url, entered=range(1, 3))
    engine = db.open_database(sqlite_url)
    try:
        patient = study.study(engine, load_questionnaire(), "barthel", date(2026, 11, 1), date(2026, 11, 20))
        assert [p.session_id for p in patient.pairs] == ["study-1", "study-2"]  # before the nurse's entry
    finally:
        engine.dispose()
    station = station_factory(sqlite_url)
    context, page = login(browser, station.url, "nurse.kim", "nurse", viewport)
    try:
        page.goto(station.url + "/sessions/study-0")
        page.click("#reference-link")
        page.wait_for_selector("#reference-form")
        fits(page, viewport)
        q = load_questionnaire()
        transfers = q.item("transfers").option(3).label["en"]
        assert "kiosk:" not in page.locator("#reference-form").inner_text()  # entered blind to the kiosk's
        for item in reference.asked(q):  # the kiosk's answer, except transfers
            kiosk_label = item.option(visits.kiosk[0][item.id]).label["en"]
            select = page.locator(f'select[name="item-{item.id}"]')
            select.select_option(label=transfers if item.id == "transfers" else kiosk_label)
        page.click("#store-reference")
        page.wait_for_selector("#reference-trail")
        assert "10 clinician's answers stored." in page.locator(".message").inner_text()
        assert page.locator("#reference-trail li").count() == 10
        entry = page.locator('#reference-trail li[data-item="transfers"]').inner_text()
        assert "nurse.kim" in entry and q.item("transfers").text["en"] in entry and transfers in entry
        assert page.locator('select[name="item-transfers"] option:checked').inner_text() == transfers

        page.click("nav >> text=Validation")
        page.wait_for_selector("#study-form")
        page.goto(station.url + STUDY)
        page.wait_for_selector("#study-icc")
        fits(page, viewport)
        assert page.locator('select[name="instrument"] option:checked').inner_text() == "Barthel Index"
        engine = db.make_engine(sqlite_url)
        try:
            found = study.study(engine, q, "barthel", date(2026, 11, 1), date(2026, 11, 20))
        finally:
            engine.dispose()
        assert page.locator("#study-patients").inner_text() == "3" and page.locator("#study-totals").inner_text() == "3"
        assert page.locator("#icc-value").inner_text() == f"{found.icc.estimate.value:.2f}"
        assert "0.89" in page.locator("#study-icc").inner_text()
        stairs_row = page.locator('#study-items li[data-item="stairs"]').inner_text()
        kappa = next(i for i in found.items if i.item_id == "stairs").kappa
        assert f"κw {kappa.value:.2f}" in stairs_row and "n = 3" in stairs_row
        assert "same answer" in page.locator('#study-items li[data-item="transfers"]').inner_text()
        assert "Bias" in page.locator("#study-bias").inner_text()
        csv_text = page.request.get(station.url + page.locator("#study-csv").get_attribute("href")).text()
        assert next(r for r in csv.reader(io.StringIO(csv_text)) if r and r[0] == "icc_2_1")[3] == (
            f"{found.icc.estimate.value:.4f}"
        )
        page.goto(station.url + "/study?instrument=barthel&from=2026-11-20&to=2026-11-01")
        assert "is before from" in page.locator("#study-error").inner_text()
        fits(page, viewport)
    finally:
        context.close()
