"""The kiosk's side of ordered visits, drawn with Pilot on a simulated clock (issue 36): the "A
visit is ready" screen names no patient (passers-by read it), and a visit the ward cancels while
it runs ends at once: what was answered is stored, the patient reads one calm end, and a touch
brings the visits waiting back. The same path against a real station is
tests/kiosk/sync/test_order_cancel_kiosk.py."""

from __future__ import annotations

from kiosk.core.session import Phase
from kiosk.core.visits import CANCELLED, Order

from .helpers import screen_name, settle

ORDER = Order("order-5150aa", "NHC-4242", ("barthel",), "en", "relative", "nurse.kim")
OTHER = Order("order-5150bb", "NHC-0077", ("barthel",), "es", "patient", "nurse.kim")


def shown(app) -> str:
    """Every text the screen on top shows."""
    return "\n".join(str(w.render()) for w in app.screen.query("Static, Label, Button"))


async def test_the_ready_screen_names_no_patient(ui_kiosk):
    kiosk = ui_kiosk(visits=True, familiarisation=False)
    async with kiosk.app.run_test() as pilot:
        kiosk.controller.orders_changed([ORDER, OTHER])
        await settle(pilot, lambda: screen_name(kiosk) == "VisitReadyScreen")
        text = shown(kiosk.app)
        assert "A visit is ready" in text
        assert "Visit 1 · 1 questionnaire · English" in text and "Visit 2 · 1 questionnaire · Español" in text
        for private in ("NHC-4242", "NHC-0077", "relative", "barthel"):
            assert private not in text, f"{private!r} is on the screen anyone passing reads"


async def test_a_visit_cancelled_while_it_runs_ends_calmly_and_keeps_its_answers(ui_kiosk):
    kiosk = ui_kiosk(visits=True, familiarisation=False)
    async with kiosk.app.run_test() as pilot:
        kiosk.controller.orders_changed([ORDER, OTHER])
        await settle(pilot, lambda: screen_name(kiosk) == "VisitReadyScreen")
        kiosk.controller.order_started(ORDER)
        session = kiosk.app.session
        await settle(pilot, lambda: session.phase is not Phase.WELCOME)
        while session.phase is Phase.FAMILIARISATION:  # the practice questions, answered right
            practice = session.snapshot().practice
            if practice is not None and session.current_attempt is not None:
                await pilot.press(str(practice.expected))
            else:
                kiosk.to_next_deadline_of(session)
            await settle(pilot)
        assert screen_name(kiosk) == "ExplanationScreen"
        await pilot.press("1")
        await settle(pilot, lambda: session.phase is Phase.QUESTIONS)
        kiosk.to_next_deadline_of(session)  # the gap before the first question opens
        await settle(pilot, lambda: session.current_attempt == 1)
        item = session.current_item
        await pilot.press("2")  # the first item's second option
        await settle(pilot, lambda: item.id in session.answers)

        kiosk.app.visit_cancelled(("order-other",))  # another kiosk's visit: nothing happens here
        await pilot.pause()
        assert kiosk.app.session is session and session.phase is Phase.QUESTIONS

        kiosk.app.visit_cancelled((ORDER.id,))
        await settle(
            pilot, lambda: screen_name(kiosk) == "VisitEndedScreen" and "This visit has ended." in shown(kiosk.app)
        )
        assert "NHC-4242" not in shown(kiosk.app)
        stored = kiosk.store.session(session.id)
        assert stored.status == "abandoned"
        assert [a.option for a in stored.answers] == [2]  # nothing answered is lost
        assert any(e.kind == "abandoned" and e.detail == CANCELLED for e in stored.log)
        assert kiosk.app.session is not session and kiosk.app.session.phase is Phase.WELCOME

        await pilot.press("1")  # a key (or a touch) is not an answer here: it dismisses the end
        await settle(pilot, lambda: screen_name(kiosk) == "VisitReadyScreen")
        assert kiosk.app.session.phase is Phase.WELCOME
        assert "Visit 1 · 1 questionnaire · Español" in shown(kiosk.app)  # the other visit still waits


async def test_the_end_of_a_cancelled_visit_is_in_its_patients_language(ui_kiosk):
    kiosk = ui_kiosk(visits=True, familiarisation=False)
    async with kiosk.app.run_test() as pilot:
        kiosk.controller.orders_changed([OTHER])
        await settle(pilot, lambda: screen_name(kiosk) == "VisitReadyScreen")
        kiosk.controller.order_started(OTHER)
        await settle(pilot, lambda: kiosk.app.session.phase is not Phase.WELCOME)
        kiosk.app.visit_cancelled((OTHER.id,))
        await settle(
            pilot, lambda: screen_name(kiosk) == "VisitEndedScreen" and "Esta visita ha terminado." in shown(kiosk.app)
        )
        await pilot.click("#visit-ended-ok")
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
