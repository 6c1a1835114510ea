"""A kiosk whose database refuses a write mid-answer (here: another process holds the write lock
past the wait) shows the patient one calm out-of-order screen -- no traceback, nothing
half-stored, no notice naming anyone -- and once the database answers again the welcome is back
and the test it dropped is listed for staff."""

from __future__ import annotations

import sqlite3

from kiosk.ui.app import KIOSK_SIZE

from .helpers import settle, start_in_english, until_drawn


async def test_a_write_the_database_refuses_drops_the_test_plainly_and_staff_get_it_back(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    seen: list[str] = []
    notify = kiosk.app.notify
    # the test reads what the screen showed
    spy = lambda message, **kw: (seen.append(message), notify(message, **kw))  # noqa: E731 - one line
    kiosk.app.notify = spy  # type: ignore[method-assign]  # a spy that also notifies
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        session = kiosk.session
        kiosk.store._db.execute("PRAGMA busy_timeout = 0")  # do not wait 10 s for the lock here
        other = sqlite3.connect(kiosk.store.path, isolation_level=None)
        other.execute("BEGIN IMMEDIATE")  # another process writing, for longer than the kiosk waits
        try:
            await pilot.press("2")
            await settle(pilot, lambda: kiosk.app.session is not session)
            await until_drawn(pilot, "This kiosk is not working at the moment.")
            assert "database is locked" in kiosk.controller.out_of_order and seen == []  # for staff, not the patient
        finally:
            other.execute("ROLLBACK")
            other.close()
        kiosk.controller.keep_session()  # the lease timer's round, now that the database answers
        await until_drawn(pilot, "1  English")
        assert kiosk.store.session(session.id).answers == ()
        (interrupted,) = kiosk.controller.interrupted_tests()
        assert interrupted.id == session.id and interrupted.patient_id == session.patient_id
