"""Cancelling an order while its patient answers ends the visit at the kiosk (issue 36), with every
part real: the kiosk as `kiosk run` builds it (its own order watcher, sync client and store) and a
`kiosk station` process over HTTP on 127.0.0.1. Staff read that the visit is running before they
cancel; the kiosk learns it through its orders poll, stops asking, keeps what was answered (the
session abandoned with why, delivered to the station) and shows one calm end; the order stays
cancelled, its trail says the kiosk ended the session, and the ward's Results say "cancelled"."""

from __future__ import annotations

import pytest
import sqlalchemy as sa

from kiosk.commands.run import build_app
from kiosk.core.session import Phase
from kiosk.core.visits import CANCELLED
from kiosk.ui.app import KIOSK_SIZE
from station import db
from station.db import audit, inbox
from tests.kiosk.sync.test_orders_kiosk import CODE, config_for, screen, text_of, type_code
from tests.kiosk.ui.helpers import until_thread
from tests.station.conftest import make_ward, start_station
from tests.station.helpers import Staff
from tests.station.test_orders import state


def _station_rows(engine, session_id: str) -> list[str]:
    with engine.connect() as connection:
        return list(
            connection.execute(
                sa.select(inbox.c.kind).where(inbox.c.session_id == session_id).order_by(inbox.c.seq)
            ).scalars()
        )


def _trail(engine, order_id: str) -> list[str]:
    with engine.connect() as connection:
        return list(connection.execute(sa.select(audit.c.action).where(audit.c.session_id == order_id)).scalars())


@pytest.mark.slow  # a station process
async def test_cancelling_a_running_visit_ends_it_at_the_kiosk_and_keeps_its_answers(tmp_path):
    ward = make_ward(db.sqlite_url(tmp_path / "station"))
    station = start_station(ward.db_url, tmp_path / "station.log")
    engine = db.make_engine(ward.db_url)
    app, close = build_app(config_path=config_for(tmp_path, station.url, ward.token), voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            nurse = Staff(station.url, "nurse.kim", "nurse")
            placed = nurse.post(
                "/orders", patient_id="NHC-7007", kiosk="ward3-bed2", instrument="barthel", language="en"
            )
            location = placed.headers["location"]
            order_id = location.rsplit("/", 1)[1]
            code = CODE.search(nurse.http.get(location).text).group(1)
            await until_thread(lambda: screen(app) == "VisitReadyScreen", "the visit on the kiosk's welcome")
            await pilot.pause()
            await type_code(pilot, code)
            await until_thread(lambda: app.session.phase is not Phase.WELCOME, "the ordered session starting")
            session = app.session
            await until_thread(lambda: state(ward.db_url, order_id) == ("in_progress", session.id), "the order linked")
            await until_thread(lambda: screen(app) == "ExplanationScreen", "the explanation")
            await pilot.press("1")
            await until_thread(lambda: session.current_attempt == 1, "the first question open")
            item = session.current_item
            await pilot.press("2")
            await until_thread(lambda: item.id in session.answers, "the first answer taken")

            page = nurse.http.get(location).text
            assert "The visit is running on kiosk ward3-bed2: cancelling ends it" in page
            cancelled = nurse.post(f"/orders/{order_id}/cancel", reason="patient discharged")
            assert cancelled.status_code == 303

            # wait on what is drawn: the screen is current a moment before its widgets are mounted
            await until_thread(
                lambda: screen(app) == "VisitEndedScreen" and bool(app.screen.query("#visit-ended-title")),
                "the kiosk ending the visit",
                patience_s=60,
            )
            assert "This visit has ended." in text_of(app, "#visit-ended-title")
            assert app.session is not session and app.session.phase is Phase.WELCOME  # nothing more is asked
            stored = app.controller.store.session(session.id)
            assert stored.status == "abandoned" and [a.item_id for a in stored.answers] == [item.id]
            assert any(e.kind == "abandoned" and e.detail == CANCELLED for e in stored.log)

            # the station has what was answered and the end; the order stays cancelled
            await until_thread(lambda: "abandon" in _station_rows(engine, session.id), "the end at the station", 60)
            assert "record_answer" in _station_rows(engine, session.id)
            assert state(ward.db_url, order_id)[0] == "cancelled"
            await until_thread(lambda: "order_ended" in _trail(engine, order_id), "the trail of the end", 60)
            assert "order_cancel" in _trail(engine, order_id)
            ward_results = nurse.http.get("/fragments/results").text
            assert f'data-session="{session.id}"' in ward_results
            row = ward_results.split(f'data-session="{session.id}"', 1)[1].split("</li>", 1)[0]
            assert '<span class="badge status">cancelled</span>' in row

            await pilot.click("#visit-ended-ok")  # a touch: the welcome for the next patient
            await until_thread(lambda: screen(app) == "WelcomeScreen", "the welcome back")
    finally:
        close()
        engine.dispose()
        station.stop()
