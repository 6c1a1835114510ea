"""Two kiosk processes on one kiosk id (the served page open in two browser tabs: each tab runs
its own `kiosk run`), against a real `kiosk station` process over HTTP: the ward tile shows the
test that runs, with its doctor call and Continue button, however often the other tab's welcome
reports; once the running process falls silent, the tile shows what the other one reports."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest
import sqlalchemy as sa

from station import db, ward
from tests.station.conftest import new_kiosk
from tests.station.helpers import KioskClient, Staff

pytestmark = pytest.mark.slow

RUNNING = {"session_id": "5e55a0000777", "patient_id": "P-TWO01", "phase": "questions", "question": 4, "of": 10}


@pytest.fixture
def two_tabs(shared_station):
    station, stored = shared_station
    name, token = new_kiosk(stored.db_url)
    tabs = KioskClient(station.url, token, name), KioskClient(station.url, token, name)
    yield replace(stored, token=token, kiosk_id=name), station, tabs
    for tab in tabs:
        tab.close()


def _tile(station, name: str) -> str:
    page = Staff(station.url).http.get("/").text
    start = page.index(f'id="kiosk-{name}"')
    return page[start : page.index("</article>", start)]


def test_the_tile_shows_the_running_test_whatever_the_other_tab_reports(two_tabs):
    stored, station, (calling, idle) = two_tabs
    name = stored.kiosk_id
    assert calling.status(instance="tab-a", doctor_called=True, **RUNNING).status_code == 200
    for _ in range(3):  # the other tab's heartbeats, after the doctor call: still the call shows
        assert idle.status(instance="tab-b", phase="welcome").status_code == 200
        tile = _tile(station, name)
        assert "P-TWO01" in tile and "doctor called" in tile and "cmd-continue" in tile, tile
        assert "no session" not in tile

    # the running tab closes (its process ends): once its report is older than a silent kiosk's,
    # the tile shows the tab still open
    engine = db.make_engine(stored.db_url)
    with engine.begin() as connection:
        row = connection.execute(sa.select(db.kiosks.c.status).where(db.kiosks.c.name == name)).scalar_one()
        reports = json.loads(row)["reports"]
        reports["tab-a"]["received"] -= ward.OFFLINE_AFTER_S + 1
        connection.execute(
            db.kiosks.update().where(db.kiosks.c.name == name).values(status=json.dumps({"reports": reports}))
        )
    engine.dispose()
    tile = _tile(station, name)
    assert "no session" in tile and "doctor called" not in tile and "cmd-continue" not in tile


def test_a_kiosk_from_before_reporting_processes_still_shows_its_last_report(two_tabs):
    stored, station, (old, _) = two_tabs
    assert old.status(doctor_called=True, **RUNNING).status_code == 200  # no instance field
    tile = _tile(station, stored.kiosk_id)
    assert "P-TWO01" in tile and "cmd-continue" in tile
    assert old.status(phase="welcome").status_code == 200
    assert "no session" in _tile(station, stored.kiosk_id)


def test_the_shown_status_prefers_a_live_session_and_keeps_a_bounded_history():
    now = 1_000.0
    stored = None
    stored = ward.merge_status(stored, {"instance": "a", "session_id": "s1", "phase": "questions"}, now)
    stored = ward.merge_status(stored, {"instance": "b", "session_id": None, "phase": "welcome"}, now + 1)
    assert ward.shown_status(stored, now + 2)["session_id"] == "s1"
    assert ward.shown_status(stored, now + ward.OFFLINE_AFTER_S + 5)["phase"] == "welcome"
    for n in range(3 * ward.MOST_INSTANCES):  # a kiosk restarted many times keeps its newest few
        stored = ward.merge_status(stored, {"instance": f"p{n}", "phase": "welcome"}, now + 10 + n)
    assert len(json.loads(stored)["reports"]) == ward.MOST_INSTANCES
    assert ward.shown_status(json.dumps({"phase": "welcome", "session_id": "old"}), now)["session_id"] == "old"
