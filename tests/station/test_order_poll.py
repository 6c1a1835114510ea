"""A kiosk's waiting orders poll is woken by its own order, on SQLite and on PostgreSQL (there
through a second station process and NOTIFY), while other kiosks' reports and orders flow; and
the bus hands a long poll only the messages of its kiosk and kinds (a poll fed every kiosk's
status reports fell hundreds of ms behind under 50 kiosks: bench/station.py)."""

from __future__ import annotations

import asyncio
import threading
from concurrent.futures import ThreadPoolExecutor

import pytest
import sqlalchemy as sa

from station.bus import Bus
from tests.station.conftest import PATIENCE_S, make_ward, new_kiosk
from tests.station.helpers import KioskClient, Staff


def test_the_bus_hands_a_kiosks_poll_only_its_kinds_and_a_page_everything():
    bus = Bus(sa.create_engine("sqlite://"))
    sent = [
        {"type": "kiosk", "kiosk": "bed1"},
        {"type": "order", "kiosk": "bed2"},
        {"type": "command", "kiosk": "bed1"},
        {"type": "order", "kiosk": "bed1"},
        {"type": "resync"},
    ]

    async def run() -> tuple[list, list, list, bool]:
        bus.start(asyncio.get_running_loop())
        page = bus.subscribe()
        orders = bus.subscribe("bed1", ("order", "resync"))
        commands = bus.subscribe("bed1", ("command", "resync"))
        bus.publish(*sent)
        on_page = [await page.get() for _ in sent]  # each message reaches every queue in one go
        polled = [orders.get_nowait() for _ in range(orders.qsize())]
        commanded = [commands.get_nowait() for _ in range(commands.qsize())]
        bus.unsubscribe(orders)
        bus.publish({"type": "order", "kiosk": "bed1"})
        await page.get()
        return on_page, polled, commanded, orders.empty()

    # a loop of its own on a thread of its own: the station tests' Chromium (Playwright's sync API)
    # keeps an event loop running on this thread for the whole session
    with ThreadPoolExecutor(1) as thread:
        on_page, polled, commanded, left_alone = thread.submit(asyncio.run, run()).result()
    bus.stop()
    assert on_page == sent
    assert polled == [{"type": "order", "kiosk": "bed1"}, {"type": "resync"}]
    assert commanded == [{"type": "command", "kiosk": "bed1"}, {"type": "resync"}]
    assert left_alone  # unsubscribed: nothing more


@pytest.mark.slow
@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_a_waiting_orders_poll_answers_with_its_own_order_only(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    # on PostgreSQL staff order on another station process: the poll wakes by LISTEN/NOTIFY
    ordering = station_factory(db_url) if database == "postgres" else station
    other_name, other_token = new_kiosk(db_url)
    mine = KioskClient(station.url, ward.token, ward.kiosk_id)
    other = KioskClient(station.url, other_token, other_name)
    nurse = Staff(ordering.url, "nurse.kim", "nurse")
    before = mine.orders()
    assert before["orders"] == []

    answered: list[dict] = []
    poll = threading.Thread(target=lambda: answered.append(mine.orders(wait=25, version=before["version"])))
    poll.start()
    # another kiosk's reports and its order while ours waits: none of them answers our poll
    assert other.status(phase="welcome").status_code == 200
    assert (
        nurse.post(
            "/orders", patient_id="NHC-0000777", kiosk=other_name, instrument="barthel", language="en"
        ).status_code
        == 303
    )
    assert other.status(phase="welcome").status_code == 200
    placed = nurse.post("/orders", patient_id="NHC-0012345", kiosk=ward.kiosk_id, instrument="barthel", language="en")
    assert placed.status_code == 303
    poll.join(PATIENCE_S)

    (listed,) = answered
    assert [o["id"] for o in listed["orders"]] == [placed.headers["location"].rsplit("/", 1)[1]]
    assert listed["orders"][0]["patient_id"] == "NHC-0012345" and listed["version"] != before["version"]
    assert [o["patient_id"] for o in other.orders()["orders"]] == ["NHC-0000777"]
    mine.close()
    other.close()
