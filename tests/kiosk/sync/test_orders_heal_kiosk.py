"""A kiosk that stopped mid-visit heals its order, against a real `kiosk station` process: the
kiosk as `kiosk run` builds it tells the station, on every orders poll, the orders its database
can still go on with. Killed after the code was accepted and before a session was stored, the
restarted kiosk offers the visit again and its code starts it; an order whose session runs at
the kiosk is never released; and what the database holds is read as the poll reads it."""

from __future__ import annotations

import pytest

from kiosk.commands.run import build_app
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import Session
from kiosk.store.database import Store
from kiosk.sync.orders import held_orders
from kiosk.ui.app import KIOSK_SIZE
from station import db
from station.orders import orders as orders_table
from tests.kiosk.sync.test_orders_kiosk import CODE, config_for, screen, text_of, type_code
from tests.kiosk.ui.helpers import until_thread
from tests.station.conftest import make_ward, start_station
from tests.station.helpers import KioskClient, Staff
from tests.station.test_orders import state


def _order(nurse: Staff, patient: str) -> tuple[str, str]:
    placed = nurse.post(
        "/orders",
        patient_id=patient,
        kiosk="ward3-bed2",
        instrument="barthel",
        language="en",
        relative="no",
        anyway="yes",  # visits queue on the kiosk: past the double-booking warning
    )
    return placed.headers["location"].rsplit("/", 1)[1], CODE.search(
        nurse.http.get(placed.headers["location"]).text
    ).group(1)


def _started_long_ago(db_url: str, order_id: str) -> None:
    """As if the order went in progress before the station's grace for a kiosk to store it."""
    engine = db.make_engine(db_url)
    with engine.begin() as connection:
        connection.execute(
            orders_table.update()
            .where(orders_table.c.id == order_id)
            .values(updated_at="2000-01-01T00:00:00.000+00:00")
        )
    engine.dispose()


@pytest.mark.slow  # a station process
async def test_a_kiosk_killed_after_the_code_offers_the_visit_again_and_keeps_one_it_runs(tmp_path):
    ward = make_ward(db.sqlite_url(tmp_path / "station"))
    station = start_station(ward.db_url, tmp_path / "station.log")
    nurse = Staff(station.url, "nurse.kim", "nurse")
    order_id, code = _order(nurse, "NHC-5150")
    # the kiosk that took the code and was killed before it stored a session: its request, then nothing
    killed = KioskClient(station.url, ward.token, ward.kiosk_id)
    assert killed.start_order(code).status_code == 200
    killed.close()
    _started_long_ago(ward.db_url, order_id)
    app, close = build_app(config_path=config_for(tmp_path, station.url, ward.token), voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:  # restarted on the same data directory
            await until_thread(lambda: screen(app) == "VisitReadyScreen", "the visit offered again", patience_s=60)
            await pilot.pause()
            assert text_of(app, ".visit-order") == "Visit 1 · 1 questionnaire · English"
            assert state(ward.db_url, order_id) == ("ordered", None)
            await type_code(pilot, code)
            await until_thread(lambda: app.session.patient_id == "NHC-5150", "the visit starting with its code")
            session_id = app.session.id
            await until_thread(
                lambda: state(ward.db_url, order_id) == ("in_progress", session_id), "the order running", patience_s=60
            )
            # the session runs here: polls after the order looks old still leave it in progress (two
            # more orders wake two polls, the second begun after this kiosk saw the first)
            _started_long_ago(ward.db_url, order_id)
            for patient in ("NHC-5151", "NHC-5152"):
                woke, _ = _order(nurse, patient)
                await until_thread(
                    lambda: woke in [o.id for o in app.controller.visits.ready], f"{woke} at the kiosk", patience_s=60
                )
            assert state(ward.db_url, order_id) == ("in_progress", session_id)
    finally:
        close()
        station.stop()


def test_the_poll_holds_the_orders_of_running_and_unsent_sessions(tmp_path):
    store = Store.open(tmp_path, outbox=True)
    questionnaire = load_questionnaire()

    def visit(order_id: str) -> Session:
        session = Session(
            questionnaire, clock=SimClock(), engine=None, store=store, patient_id="NHC-1", visit=f"order {order_id}"
        )
        session.start()
        return session

    assert held_orders(tmp_path / "nothing.sqlite3") == []
    visit("order-running")
    assert held_orders(store.path) == ["order-running"]
    ended = visit("order-ended")
    ended.abandon()
    assert "order-ended" in held_orders(store.path)  # its rows are not at the station yet
    store._db.execute("DELETE FROM outbox")  # as the sync client does once delivered
    assert held_orders(store.path) == ["order-running"]
    store.close()
