"""Several station processes behind one PostgreSQL: an alert a kiosk posts to one station shows on
a page served by another (fanned out with LISTEN/NOTIFY), and a command queued on one answers a
kiosk's long poll held by another."""

from __future__ import annotations

import json
import queue
import threading

import pytest

from station.sync import RAISES as RAISING
from tests.station.conftest import PATIENCE_S, make_ward
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

pytestmark = pytest.mark.slow


def listen(staff: Staff, events: queue.Queue) -> None:
    """Read the page's event stream (as the browser's EventSource does) into ``events``."""
    try:
        with staff.http.stream("GET", "/events", timeout=PATIENCE_S * 2) as response:
            name = None
            for line in response.iter_lines():
                if line.startswith("event: "):
                    name = line[7:]
                elif line.startswith("data: ") and name:
                    events.put((name, json.loads(line[6:])))
    except Exception as exc:  # the test's end closes the stream
        events.put(("closed", repr(exc)))


def test_an_alert_posted_to_one_station_appears_on_a_page_of_another(pg_url, station_factory):
    ward = make_ward(pg_url)
    first, second = station_factory(pg_url), station_factory(pg_url)
    staff = Staff(second.url, "nurse.kim", "nurse")
    events: queue.Queue = queue.Queue()
    threading.Thread(target=listen, args=(staff, events), daemon=True).start()
    name, initial = events.get(timeout=PATIENCE_S)
    assert name == "alerts" and initial["ids"] == []
    rows = record_patient(PATIENTS / "barthel6.yaml")
    alert = next(r for r in rows if r.alert and r.payload["kind"] in RAISING)
    kiosk = KioskClient(first.url, ward.token, ward.kiosk_id)
    assert kiosk.sync([alert]).status_code == 200
    while True:
        name, data = events.get(timeout=PATIENCE_S)
        if name == "alerts" and data["ids"]:
            break
    (text,) = [a["text"] for a in data["alerts"]]
    assert ward.kiosk_id in text and ("Doctor called" in text or "Patient away" in text)
    assert f'href="#kiosk-{ward.kiosk_id}"' in data["html"]

    # a command queued on the second station answers a long poll held by the first
    kiosk.sync([r for r in rows if r.seq < alert.seq])
    got: list = []
    poll = threading.Thread(target=lambda: got.extend(kiosk.commands(wait=25)))
    poll.start()
    response = staff.post(f"/kiosks/{ward.kiosk_id}/command", session_id=alert.session_id, kind="person_back")
    assert response.status_code == 303
    poll.join(PATIENCE_S)
    assert [c["kind"] for c in got] == ["person_back"]
    kiosk.close()
