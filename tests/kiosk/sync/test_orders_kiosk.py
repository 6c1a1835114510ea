"""The kiosk as `kiosk run` builds it, against a real `kiosk station` process on 127.0.0.1: a visit
ordered on the station replaces the welcome, nothing a patient presses starts it, a wrong code is
refused, and the order's code starts a session under the ordered patient, language and answerer,
which the station files under the order. Without a station, staff start a visit by touch on the
clinician screen, and a site without walk-ups never starts a test from the welcome."""

from __future__ import annotations

import re

import pytest
import sqlalchemy as sa

from kiosk.commands.run import build_app
from kiosk.core.session import AnsweredBy, Phase
from kiosk.core.visits import visit_of
from kiosk.ui.app import KIOSK_SIZE
from station import db
from station.orders import orders as orders_table
from tests.kiosk.ui.helpers import until_thread
from tests.station.conftest import make_ward, start_station
from tests.station.helpers import Staff

CODE = re.compile(r'id="order-code"[^>]*>(\d{4})<')


def config_for(tmp_path, station_url: str | None = None, token: str = "", walk_up: bool = True):
    config = tmp_path / "config.yaml"
    text = (
        f"data_dir: {tmp_path / 'data'}\nfamiliarisation: false\ntiming: {{between_questions_s: 0.1}}\n"
        f'clinician_pin: "246813"\nwalk_up: {str(walk_up).lower()}\n'
        # the orders below are in Spanish, a translation of the team's own this site accepts
        "accept_unvalidated_translations: [es]\n"
    )
    if station_url:
        text += f"station: {{url: '{station_url}', token: '{token}', kiosk_id: ward3-bed2}}\n"
    config.write_text(text)
    return config


def screen(app) -> str:
    return type(app.screen).__name__


def text_of(app, selector: str) -> str:
    return str(app.screen.query_one(selector).render())


async def type_code(pilot, code: str) -> None:
    for digit in code:
        assert await pilot.click(f"#visit-key-{digit}"), f"the tap on {digit} missed its key"
    await pilot.click("#visit-key-ok")


@pytest.mark.slow  # a station process
async def test_an_ordered_visit_starts_at_the_kiosk_only_with_its_code(tmp_path):
    ward = make_ward(db.sqlite_url(tmp_path / "station"))
    station = start_station(ward.db_url, tmp_path / "station.log")
    app, close = build_app(config_path=config_for(tmp_path, station.url, ward.token), voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await until_thread(lambda: screen(app) == "WelcomeScreen", "the welcome")
            nurse = Staff(station.url, "nurse.kim", "nurse")
            placed = nurse.post(
                "/orders",
                patient_id="NHC-4242",
                kiosk="ward3-bed2",
                instrument="barthel",
                language="es",
                relative="yes",
            )
            order_id = placed.headers["location"].rsplit("/", 1)[1]
            code = CODE.search(nurse.http.get(placed.headers["location"]).text).group(1)

            await until_thread(lambda: screen(app) == "VisitReadyScreen", "the visit on the kiosk's welcome")
            await pilot.pause()  # the keypad laid out
            # nothing of the patient for passers-by to read: a neutral line of the visit only
            assert text_of(app, ".visit-order") == "Visit 1 · 1 questionnaire · Español"
            assert "NHC-4242" not in "".join(str(w.render()) for w in app.screen.query("Static, Label"))
            await pilot.press("1")  # a remote's 1 (a keyboard remote): a digit of the code, nothing starts
            await pilot.pause()
            assert app.session.phase is Phase.WELCOME and screen(app) == "VisitReadyScreen"
            assert text_of(app, "#visit-code") == "1"
            await pilot.click("#visit-key-delete")

            await type_code(pilot, "0000" if code != "0000" else "1111")
            await until_thread(
                lambda: "not one of this kiosk's visits" in text_of(app, "#visit-error"), "the wrong code refused"
            )
            assert app.session.phase is Phase.WELCOME

            await type_code(pilot, code)
            await until_thread(lambda: app.session.phase is not Phase.WELCOME, "the ordered session starting")
            session = app.session
            assert (session.patient_id, session.language, session.answered_by) == (
                "NHC-4242",
                "es",
                AnsweredBy.RELATIVE,
            )
            assert visit_of(app.controller.store.session(session.id).log) == f"order {order_id}"

            engine = db.make_engine(ward.db_url)

            def linked() -> bool:
                with engine.connect() as connection:
                    row = connection.execute(
                        sa.select(orders_table.c.state, orders_table.c.session_id).where(orders_table.c.id == order_id)
                    ).one()
                return tuple(row) == ("in_progress", session.id)

            await until_thread(linked, "the station filing the session under the order", patience_s=60)
            engine.dispose()
    finally:
        close()
        station.stop()


async def test_without_a_station_staff_start_a_visit_by_touch_and_no_walk_up_starts(tmp_path):
    app, close = build_app(config_path=config_for(tmp_path, walk_up=False), voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await until_thread(lambda: screen(app) == "VisitReadyScreen", "the welcome held for staff")
            assert "No visit is ready" in text_of(app, "#visit-heading")
            await pilot.press("1", "1")
            await pilot.pause()
            assert app.session.phase is Phase.WELCOME

            await pilot.press("ctrl+k", *"246813", "enter")
            await until_thread(lambda: screen(app) == "ClinicianHomeScreen", "the clinician screen")
            await pilot.click("#start-visit")
            await until_thread(lambda: screen(app) == "StartVisitScreen", "the start-a-visit screen")
            for key in ("id-key-L", "id-key-O", "id-key-P", "id-key-E", "id-key-Z"):  # a name: refused
                await pilot.click(f"#{key}")
            await pilot.click("#start-visit-go")
            assert "never a name" in text_of(app, "#start-visit-error")
            for _ in range(5):
                await pilot.click("#id-key-delete")
            for key in ("id-key-N", "id-key-H", "id-key-C", "id-key-dash", "id-key-7", "id-key-0"):
                await pilot.click(f"#{key}")
            await pilot.click("#start-visit-go")
            await until_thread(lambda: app.session.phase is not Phase.WELCOME, "the staff's visit starting")
            assert app.session.patient_id == "NHC-70"
            assert visit_of(app.controller.store.session(app.session.id).log) == "staff"
    finally:
        close()


@pytest.mark.slow  # a station process
async def test_a_code_typed_while_the_station_is_down_says_so_and_starts_nothing(tmp_path):
    ward = make_ward(db.sqlite_url(tmp_path / "station"))
    station = start_station(ward.db_url, tmp_path / "station.log")
    app, close = build_app(config_path=config_for(tmp_path, station.url, ward.token), voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            nurse = Staff(station.url, "nurse.kim", "nurse")
            placed = nurse.post("/orders", patient_id="NHC-9", kiosk="ward3-bed2", instrument="barthel", language="en")
            code = CODE.search(nurse.http.get(placed.headers["location"]).text).group(1)
            await until_thread(lambda: screen(app) == "VisitReadyScreen", "the visit on the kiosk's welcome")
            await pilot.pause()  # the keypad laid out
            station.stop()
            await type_code(pilot, code)
            await until_thread(
                lambda: "cannot be reached" in text_of(app, "#visit-error"), "the station's absence said"
            )
            assert app.session.phase is Phase.WELCOME and screen(app) == "VisitReadyScreen"
    finally:
        close()
        station.stop()
