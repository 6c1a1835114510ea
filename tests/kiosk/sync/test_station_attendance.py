"""Nobody at the kiosk, end to end with the real ward station (issues 34 and 36): the kiosk as
`kiosk run` builds it, reporting to a `kiosk station` process. A camera's "no person" (delivered
through the app's channel sink, as the camera channel does) becomes the ward's alert only once the
patient has been away the site's time, and closes when they are back; two unanswered questions
become a "no answer" alert on the ward page, the ward's Continue acknowledges it while the kiosk
still waits, and the patient's touch goes on."""

from __future__ import annotations

import threading

import pytest

from kiosk.core.channels import Presence, PresenceSource
from tests.kiosk.sync.test_station_e2e import PATIENCE_S, free_port, start_station
from tests.station.conftest import PASSWORDS

pytestmark = pytest.mark.slow
KIOSK = "ward3-bed2"


def from_thread(app, item) -> None:
    """Deliver ``item`` as a channel thread does: through the app's sink, from another thread."""
    thread = threading.Thread(target=app.channel_sink, args=(item,))
    thread.start()
    thread.join(timeout=5)


async def test_away_and_unanswered_reach_the_ward_and_continue_waits_for_the_touch(tmp_path):
    from kiosk.commands.run import build_app
    from kiosk.ui.app import KIOSK_SIZE
    from station import auth, db, ward
    from tests.kiosk.ui.helpers import until_thread
    from tests.station.helpers import Staff

    db_url = db.sqlite_url(tmp_path / "station")
    engine = db.open_database(db_url)
    token = auth.add_kiosk(engine, KIOSK)
    auth.add_user(engine, "dr.lopez", "doctor", PASSWORDS["doctor"])
    port = free_port()
    config = tmp_path / "config.yaml"
    config.write_text(
        f"data_dir: {tmp_path / 'data'}\nfamiliarisation: false\n"
        "timing: {attempt_window_s: 2, between_questions_s: 0.5}\n"
        "away_alert_after_s: 10\nunattended_after: 2\n"
        f"station: {{url: 'http://127.0.0.1:{port}', token: '{token}', kiosk_id: {KIOSK}}}\n"
    )
    station = start_station(db_url, port, tmp_path / "station.log")
    app, close = build_app(config_path=config, voice=False, remote=False)

    def alerts(kind: str) -> list:
        return [a for a in ward.open_alerts(engine, KIOSK) if a.kind == kind]

    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await pilot.press("1", "1")
            await until_thread(lambda: app.session.current_attempt == 1, "the first question", PATIENCE_S)
            session = app.session

            # the camera sees nobody: the clock stops; the ward hears of it after the site's 10 s
            from_thread(app, Presence(False, PresenceSource.CAMERA, "no person in 15 frames"))
            await until_thread(lambda: not session.snapshot().person_present, "the kiosk hearing the camera")
            await until_thread(lambda: alerts("person_lost"), "the away alert at the station", PATIENCE_S)
            (away,) = alerts("person_lost")
            assert away.text == "Patient away from the kiosk for 10 s" and away.session_id == session.id
            assert session.current_attempt == 1 and session.snapshot().not_answered == ()  # nothing timed out
            from_thread(app, Presence(True, PresenceSource.CAMERA, "person in 15 frames"))
            await until_thread(lambda: not alerts("person_lost"), "the alert closing when the patient is back")

            # nobody answers two questions: the ward is alerted and the kiosk waits for a touch
            await until_thread(lambda: alerts("unattended"), "the no-answer alert at the station", PATIENCE_S)
            (unattended,) = alerts("unattended")
            assert unattended.text == "No answer to two questions in a row; the kiosk waits for a touch"
            assert session.snapshot().unattended and session.snapshot().not_answered == ("feeding", "bathing")
            await until_thread(
                lambda: ward.kiosk_views(engine, KIOSK)[0].status.get("unattended") is True,
                "the kiosk's status at the station",
                PATIENCE_S,
            )
            staff = Staff(f"http://127.0.0.1:{port}", "dr.lopez", "doctor")
            page = staff.http.get("/").text
            assert "No answer to two questions in a row; the kiosk waits for a touch" in page
            assert "no answer: waits for a touch" in page and "cmd-continue" in page

            # the ward's Continue: acknowledged and logged, and the kiosk still waits for the touch
            response = staff.post(f"/kiosks/{KIOSK}/command", session_id=session.id, kind="continue")
            assert response.status_code == 303
            await until_thread(
                lambda: (ward.recent_commands(engine, session.id) or [{}])[0].get("result") == "done",
                "the kiosk's ack of the continue",
                PATIENCE_S,
            )
            assert not alerts("unattended")  # acknowledged by who sent it
            assert session.snapshot().unattended and session.current_attempt is None
            stored = app.controller.store.session(session.id)
            assert "continue_waits_for_touch" in [e.kind for e in stored.log]

            await pilot.click("#go-on")  # the patient's touch at the kiosk
            await until_thread(lambda: session.current_item.id == "grooming", "the next question", PATIENCE_S)
            staff.http.close()
    finally:
        close()
        station.terminate()
        station.wait(timeout=PATIENCE_S)
