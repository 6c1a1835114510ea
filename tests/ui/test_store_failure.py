"""A kiosk whose database refuses a write mid-answer (here: another process holds the write lock
past the wait) tells the patient plainly and starts over -- no traceback, nothing half-stored --
and the test it dropped is listed for staff once the database answers again."""

from __future__ import annotations

import sqlite3

from kiosk.app import KIOSK_SIZE

from .helpers import screen_name, settle, start_in_english


async def test_a_write_the_database_refuses_drops_the_test_plainly_and_staff_get_it_back(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    seen: list[str] = []
    notify = kiosk.app.notify
    kiosk.app.notify = lambda message, **kw: (seen.append(message), notify(message, **kw))  # type: ignore[method-assign]
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        session = kiosk.session
        kiosk.store._db.execute("PRAGMA busy_timeout = 0")  # noqa: SLF001 - do not wait 10 s for the lock here
        other = sqlite3.connect(kiosk.store.path, isolation_level=None)
        other.execute("BEGIN IMMEDIATE")  # another process writing, for longer than the kiosk waits
        try:
            await pilot.press("2")
            await settle(pilot, lambda: kiosk.app.session is not session)
            assert screen_name(kiosk) == "WelcomeScreen"
            assert any("could not store its last step" in m and "database is locked" in m for m in seen), seen
        finally:
            other.execute("ROLLBACK")
            other.close()
        kiosk.app.keep_session()  # the lease timer's round, now that the database answers
        assert kiosk.store.session(session.id).answers == ()
        (interrupted,) = kiosk.app.interrupted_tests()
        assert interrupted.id == session.id and interrupted.patient_id == session.patient_id
