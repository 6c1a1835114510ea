"""The shift's handover (issue 36, part 7), on SQLite and PostgreSQL: the alerts raised in the
chosen window and who answered them, the visits finished in it, the orders open and the results
unsigned as they stand, today's visits per kiosk; a window typed wrong is named. In Chromium (a
real station process) the page fits a 360x740 phone and a 1366x768 desk and shows those."""

from __future__ import annotations

from datetime import UTC, datetime, timedelta
from zoneinfo import ZoneInfo

import pytest

from kiosk.core.questionnaire import load_questionnaire
from station import auth, db, handover, orders, ward
from tests.station._visits import KIOSK, ORDERED_AT, PATIENT, WALK_UP_AT, raise_alert, store_visits
from tests.station.conftest import make_ward
from tests.station.test_visit_e2e import DESKTOP, fits, login

MADRID = ZoneInfo("Europe/Madrid")
NOW = ORDERED_AT + timedelta(hours=3)  # 14:15 CET on 20 November 2026
OTHER = "NHC-0036002"


def _shift_day(engine):
    """The two visits, two alerts (one in the shift, answered; one weeks before) and an order
    placed but not started (open)."""
    visits = store_visits(engine)
    called = raise_alert(engine, visits.barthel, 900, "doctor_called", ORDERED_AT + timedelta(minutes=5))
    ward.acknowledge(engine, called, "nurse.kim")
    raise_alert(engine, visits.walk_up, 901, "doctor_called", WALK_UP_AT + timedelta(minutes=3))
    waiting = orders.create(
        engine,
        kiosk_id=KIOSK,
        patient_id=OTHER,
        instruments=["barthel"],
        language="en",
        relative=True,
        by=auth.User("nurse.kim", "nurse"),
        known_instruments=["barthel"],
        languages=["en"],
    )
    return visits, called, waiting


@pytest.fixture(params=["sqlite", "postgresql"])
def engine(request):
    url = request.getfixturevalue("sqlite_url" if request.param == "sqlite" else "pg_url")
    make_ward(url)
    engine = db.open_database(url)
    yield engine
    engine.dispose()


def test_the_shift_summary(engine) -> None:
    visits, called, waiting = _shift_day(engine)
    chosen = handover.window("2026-11-20T07:00", "2026-11-20T15:00", NOW, MADRID)
    found = handover.shift(engine, load_questionnaire(), chosen, NOW, MADRID)
    (alert,) = found.alerts  # the walk-up's alert was weeks before the shift
    assert (alert.alert.id, alert.alert.text, alert.patient_id, alert.raised) == (
        called,
        "Doctor called",
        PATIENT,
        "2026-11-20 11:20 CET",
    )
    assert alert.alert.ack_by == "nurse.kim" and alert.answered
    (done,) = found.visits_done
    assert done.order_id == visits.order_id
    assert [(r.title, r.total_words, r.band) for r in done.results] == [
        ("Barthel Index", "100 of 100", "Independent"),
        ("Mood check (4 items)", "20 of 25", "Suggests depression"),
    ]
    assert [o.id for o in found.orders_open] == [waiting.id]
    assert found.unsigned_count == 2
    assert [u.session_id for u in found.unsigned] == [visits.walk_up, visits.mood]
    assert list(found.today) == [KIOSK]
    assert [v.order_id for v in found.today[KIOSK]] == [visits.order_id]


def test_a_shift_before_anything_happened_is_empty_but_what_is_left_stays(engine) -> None:
    _shift_day(engine)
    chosen = handover.window("2026-09-01T07:00", "2026-09-01T15:00", NOW, MADRID)
    found = handover.shift(engine, load_questionnaire(), chosen, NOW, MADRID)
    assert found.alerts == [] and found.visits_done == []
    assert found.unsigned_count == 2 and len(found.orders_open) == 1  # as they stand now
    tomorrow = handover.shift(engine, load_questionnaire(), chosen, NOW + timedelta(days=1), MADRID)
    assert tomorrow.today == {}


def test_the_window() -> None:
    now = datetime(2026, 11, 20, 12, 0, tzinfo=UTC)
    assert handover.window("", "", now) == handover.Window(now - timedelta(hours=8), now)
    typed = handover.window("2026-11-20T07:00", "2026-11-20T15:00", now, MADRID)
    assert typed.start == datetime(2026, 11, 20, 6, 0, tzinfo=UTC)
    assert typed.typed(MADRID) == ("2026-11-20T07:00", "2026-11-20T15:00")
    with pytest.raises(handover.HandoverError, match=r"^from: 'monday' is not a date and time"):
        handover.window("monday", "", now)
    with pytest.raises(handover.HandoverError, match="start before it ends"):
        handover.window("2026-11-20T15:00", "2026-11-20T07:00", now, MADRID)
    with pytest.raises(handover.HandoverError, match="at most 31 days"):
        handover.window("2026-01-01T00:00", "2026-11-20T07:00", now, MADRID)


@pytest.mark.slow
def test_handover_page_in_chromium_on_a_phone_and_a_desk(browser, sqlite_url, station_factory, monkeypatch) -> None:
    make_ward(sqlite_url)
    engine = db.open_database(sqlite_url)
    visits, _, waiting = _shift_day(engine)
    engine.dispose()
    monkeypatch.setenv("TZ", "Europe/Madrid")
    station = station_factory(sqlite_url)
    path = "/handover?from=2026-11-20T07%3A00&to=2026-11-20T15%3A00"
    for viewport in ({"width": 360, "height": 740}, DESKTOP):
        context, page = login(browser, station.url, "nurse.kim", "nurse", viewport)
        try:
            page.click("nav >> text=Handover")
            page.wait_for_selector("#shift-window")
            page.goto(station.url + path)
            page.wait_for_selector("#shift-alerts")
            fits(page, viewport)
            alert = page.locator("#shift-alerts li").inner_text()
            assert "Doctor called" in alert and "answered by nurse.kim" in alert and PATIENT in alert
            assert "2026-11-20 11:20 CET" in alert
            done = page.locator("#visits-done li").inner_text()
            assert "Barthel Index: 100 of 100 (Independent)" in done and "Mood check (4 items): 20 of 25" in done
            assert page.locator(f'#orders-open li[data-order="{waiting.id}"]').is_visible()
            # the order's instruments by their titles, never their ids
            assert "· Barthel Index ·" in page.locator(f'#orders-open li[data-order="{waiting.id}"]').inner_text()
            assert page.locator("#unsigned-count").inner_text() == "2"
            assert page.locator(f'#unsigned li[data-session="{visits.mood}"]').is_visible()
            assert page.locator('#shift-window input[name="from"]').input_value() == "2026-11-20T07:00"
            page.goto(station.url + "/handover?from=monday")
            assert "is not a date and time" in page.locator("#window-error").inner_text()
            fits(page, viewport)
        finally:
            context.close()
