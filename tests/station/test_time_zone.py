"""Staff read every time in the site's zone (issue 36, part 6): `kiosk station --time-zone` makes a
session stored at 09:15Z read 10:15 CET on its page, its visit, the patient's page and the live
alerts; an unknown zone is one line at start. The zones come from the system's tz database."""

from __future__ import annotations

import re
import subprocess
import sys
from datetime import datetime
from zoneinfo import ZoneInfo

import pytest

from station import times
from tests.station.conftest import PATIENCE_S, ROOT, make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient


def test_times_are_shown_in_the_zone_with_its_name():
    madrid = ZoneInfo("Europe/Madrid")
    assert times.shown("2026-01-15T09:15:30Z", madrid) == "2026-01-15 10:15 CET"
    assert times.shown("2026-07-15T09:15:30+00:00", madrid, "second") == "2026-07-15 11:15:30 CEST"
    assert times.shown("2026-07-15T09:15:30", madrid, "time") == "11:15:30 CEST"  # stored naive: UTC
    assert times.shown("2026-01-15T23:30:00Z", madrid, "date") == "2026-01-16"
    assert times.shown(None, madrid) == "" and times.shown("yesterday", madrid) == "yesterday"
    with pytest.raises(times.ZoneError, match="'Mars/Olympus': not a time zone this machine knows"):
        times.zone_named("Mars/Olympus")
    assert times.zone_named("") is None  # the machine's own


@pytest.mark.slow  # a station process
def test_a_station_in_madrid_shows_madrid_time(sqlite_url, station_factory):
    refused = subprocess.run(
        [sys.executable, "-m", "kiosk", "station", "--db", sqlite_url, "--time-zone", "Europe/Madird"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=PATIENCE_S,
    )
    assert refused.returncode != 0 and "'Europe/Madird': not a time zone" in refused.stderr
    assert "Traceback" not in refused.stderr

    ward = make_ward(sqlite_url)
    station = station_factory(sqlite_url, args=("--time-zone", "Europe/Madrid"))
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    rows = record_patient(PATIENTS / "barthel1.yaml")
    assert kiosk.sync(rows).status_code == 200
    kiosk.close()
    created = next(r for r in rows if r.kind == "create_session")
    started = datetime.fromisoformat(created.payload["started_at"].replace("Z", "+00:00"))
    local = started.astimezone(ZoneInfo("Europe/Madrid"))
    nurse = Staff(station.url, "nurse.kim", "nurse")
    session_id = created.payload["session_id"]
    page = nurse.http.get(f"/sessions/{session_id}").text
    assert f"started {local:%Y-%m-%d %H:%M:%S %Z}" in page and "UTC" not in page
    visit = nurse.http.get(f"/visits/{session_id}").text
    assert f"{local:%Y-%m-%d %H:%M} {local:%Z}" in visit
    patient = nurse.http.get(f"/patients/{created.payload['patient_id']}").text
    assert re.search(rf"{local:%Y-%m-%d %H:%M} {local:%Z}", patient) and "(UTC)" not in patient
