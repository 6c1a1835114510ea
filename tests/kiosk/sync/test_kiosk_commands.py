"""The kiosk as `kiosk run` builds it, configured with a station (a real HTTP server on 127.0.0.1
speaking the protocol): its doctor call reaches the station, and the station's commands act on
the running session through the clinician's operations, on the UI thread; without a station
nothing of the sync client runs."""

from __future__ import annotations

import subprocess
import sys
import threading
from contextlib import contextmanager

import pytest

from kiosk.commands.run import build_app
from kiosk.core.session import Phase
from kiosk.store.database import Store
from kiosk.store.lease import Owner
from kiosk.ui.app import KIOSK_SIZE
from tests.kiosk.ui.helpers import until_thread

from .ward import TOKEN, Server

KIOSK = "ward3-bed2"


@contextmanager
def other_kiosk():
    """A real process standing in for another kiosk process on the same data directory."""
    child = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"], stdin=subprocess.PIPE)
    try:
        yield child.pid
    finally:
        child.kill()
        child.wait(timeout=30)


def config_for(tmp_path, server: Server | None):
    config = tmp_path / "config.yaml"
    text = (
        f"data_dir: {tmp_path / 'data'}\nfamiliarisation: false\ntiming: {{between_questions_s: 0.1}}\n"
        'clinician_pin: "246813"\n'
    )
    if server is not None:
        text += f"station: {{url: '{server.url}', token: {TOKEN}, kiosk_id: {KIOSK}}}\n"
    config.write_text(text)
    return config


async def test_a_kiosk_without_a_station_starts_no_sync_thread_and_queues_nothing(tmp_path):
    app, close = build_app(config_path=config_for(tmp_path, None), voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await pilot.press("1", "1")
            await until_thread(lambda: app.session.phase is Phase.QUESTIONS, "the questions")
            assert app.controller.sync is None
            assert not [t for t in threading.enumerate() if t.name.startswith("station")]
            assert app.controller.store._db.execute("SELECT COUNT(*) FROM outbox").fetchone() == (0,)
    finally:
        close()


@pytest.mark.slow  # a subprocess
async def test_station_commands_continue_mark_away_and_back_and_end_the_running_session(tmp_path):
    server = Server().start()
    app, close = build_app(config_path=config_for(tmp_path, server), voice=False, remote=False)
    ward = server.ward
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await pilot.press("1", "1")
            await until_thread(lambda: app.session.current_attempt == 1, "the first question")
            session = app.session
            await pilot.press("d")  # the patient calls the doctor
            # the station is watched from the app's own loop: the commands need it running
            await until_thread(
                lambda: any(
                    e["kind"] == "record_event" and e["payload"]["kind"] == "doctor_called"
                    for e in list(ward.stored.values())
                ),
                "the doctor call at the station",
            )
            await until_thread(
                lambda: any(s.get("doctor_called") and s["session_id"] == session.id for s in list(ward.statuses)),
                "the status with the doctor called",
            )

            async def command(number: int, kind: str, session_id: str = session.id) -> dict:
                ward.queue(
                    {
                        "id": number,
                        "kind": kind,
                        "session_id": session_id,
                        "by": "dr.lopez",
                        "at": "2026-11-23T15:02:11Z",
                    }
                )
                await until_thread(lambda: number in ward.acks, f"the ack of command {number}")
                return ward.acks[number]

            assert await command(1, "continue") == {"result": "done"}
            assert not session.halted
            assert (await command(2, "continue"))["result"] == "refused"  # not waiting for a doctor any more
            assert await command(3, "person_away") == {"result": "done"}
            assert not session.snapshot().person_present
            assert await command(4, "person_back") == {"result": "done"}
            assert session.snapshot().person_present
            refused = await command(5, "continue", session_id="someoneelse")
            assert refused["result"] == "refused" and "not the one running" in refused["reason"]
            await pilot.press("ctrl+k", *"246813", "enter")  # staff see the station's state too
            await until_thread(lambda: type(app.screen).__name__ == "ClinicianHomeScreen", "the clinician screen")
            line = str(app.screen.query_one("#station").render())
            assert line.startswith(f"Ward station {server.url}: reachable;") and "waiting to be sent" in line
            app.close_clinician()
            # a session another kiosk process on this data directory runs (another tab of kiosk
            # serve): its command is left for that process, never refused from here
            with other_kiosk() as pid:
                elsewhere = Store.open(tmp_path / "data", owner=Owner(pid=pid))
                elsewhere.create_session(
                    session_id="other1",
                    patient_id="P-OTHER1",
                    questionnaire_id="barthel",
                    language="en",
                    answered_by="patient",
                    started_at="2026-11-23T15:00:00+00:00",
                    timing={},
                )
                ward.queue({"id": 7, "kind": "continue", "session_id": "other1", "by": "dr.lopez", "at": "x"})
                assert await command(6, "end") == {"result": "done"}
                assert 7 not in ward.acks
            await until_thread(lambda: app.session is not session, "the kiosk starting over")
            await pilot.pause()
            assert app.session.phase is Phase.WELCOME and type(app.screen).__name__ == "WelcomeScreen"
            stored = app.controller.store.session(session.id)
            assert stored.status == "abandoned"
            assert stored.log[-1].detail == "ended from the ward station by dr.lopez"
            await until_thread(
                lambda: any(
                    e["kind"] == "abandon" and e["session_id"] == session.id for e in list(ward.stored.values())
                ),
                "the end reaching the station",
            )
    finally:
        close()
        server.stop()
