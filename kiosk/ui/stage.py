"""The patient's screens on the app's stack: the screen of the session's phase, and the paused or
doctor-called screen covering it; and :func:`patient_view`, what they show.

The phase's screen stays mounted under a covering screen, so resuming only uncovers it; it is
rebuilt only when its :meth:`PatientScreen.key` changes (a rebuild loses focus and scrolling).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

from textual.app import App

from kiosk.core.adaptation import VOICE_OFF
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.session import Phase, Session
from kiosk.ui.channels import KioskChannels
from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.screens.welcome import WelcomeScreen
from kiosk.ui.widgets.channel_board import VOICE_IN


def phase_screen(phase: Phase) -> type[PatientScreen]:
    """The screen of each phase of a session. Each but the welcome is imported when first shown:
    the first screen does not wait for the others' modules (issue 24, start-up)."""
    if phase is Phase.WELCOME:
        return WelcomeScreen
    if phase is Phase.FAMILIARISATION:
        from kiosk.ui.screens.familiarisation import FamiliarisationScreen

        return FamiliarisationScreen
    if phase is Phase.EXPLANATION:
        from kiosk.ui.screens.explanation import ExplanationScreen

        return ExplanationScreen
    if phase is Phase.REST:
        from kiosk.ui.screens.rest import RestScreen

        return RestScreen
    if phase is Phase.QUESTIONS:
        from kiosk.ui.screens.question import QuestionScreen

        return QuestionScreen
    if phase is Phase.SUMMARY:
        from kiosk.ui.screens.summary import SummaryScreen

        return SummaryScreen
    raise ValueError(f"no screen for the phase {phase!r}")


def _overlay_screen(
    halted: bool, paused: bool, unattended: bool = False, calling: bool = False
) -> type[PatientScreen] | None:
    """The screen over the phase's one: the doctor called, "Shall I call the nurse?" after a call
    heard by voice, paused, or waiting for a touch after questions in a row went unanswered
    (imported when first shown)."""
    if halted:
        from kiosk.ui.screens.doctor_called import DoctorCalledScreen

        return DoctorCalledScreen
    if calling:
        from kiosk.ui.screens.call_confirm import CallConfirmScreen

        return CallConfirmScreen
    if paused:
        from kiosk.ui.screens.paused import PausedScreen

        return PausedScreen
    if unattended:
        from kiosk.ui.screens.unattended import UnattendedScreen

        return UnattendedScreen
    return None


class PatientStage:
    """Keeps ``app``'s patient screens in step with what it is shown (:meth:`show`)."""

    def __init__(self, app: App[Any]) -> None:
        self.app = app
        #: (screen class, its key) of the phase's screen shown; None: rebuild on the next show
        self.key: tuple[type, object] | None = None

    def forget(self) -> None:
        """Rebuild the phase's screen on the next :meth:`show`, even if it looks the same."""
        self.key = None

    def show(
        self,
        view: PatientView,
        *,
        out_of_order: bool = False,
        held_visits: Any = None,
        tug: Any = None,
        ended: str | None = None,
    ) -> None:
        """Show the screens ``view`` calls for, or refresh the ones shown. ``out_of_order``: one
        calm screen instead; ``held_visits``: the visits desk when the welcome waits for staff;
        ``tug``: the TUG desk while a visit's Timed Up and Go is under way (its screen instead);
        ``ended``: the language of a visit the ward cancelled, whose calm end replaces the welcome."""
        app, snap = self.app, view.snapshot
        base_cls = phase_screen(snap.phase)
        overlay_cls = _overlay_screen(snap.halted, snap.paused, snap.unattended, snap.calling is not None)
        if out_of_order:
            from kiosk.ui.screens.out_of_order import OutOfOrderScreen

            base_cls, overlay_cls = OutOfOrderScreen, None
        shown = [s for s in app.screen_stack if isinstance(s, PatientScreen)]
        base, overlay = (shown + [None, None])[:2]
        key = (base_cls, base_cls.key(view))
        make: Callable[[], PatientScreen] = partial(base_cls, view)
        if tug is not None and not out_of_order:
            from kiosk.ui.screens.tug import TugScreen

            base_cls, overlay_cls = TugScreen, None
            key, make = (TugScreen, TugScreen.key(view)), partial(TugScreen, view, tug)
        elif base_cls is WelcomeScreen and held_visits is not None:  # kiosk.core.visits: staff confirm first
            from kiosk.ui.screens.visit_ready import VisitReadyScreen

            base_cls, key = VisitReadyScreen, (VisitReadyScreen, held_visits.ready)
            make = partial(VisitReadyScreen, view, held_visits.ready, held_visits.walk_up)
        if snap.phase is Phase.WELCOME and ended is not None and not out_of_order:
            from kiosk.ui.screens.visit_ended import VisitEndedScreen

            base_cls, key = VisitEndedScreen, (VisitEndedScreen, ended)
            make = partial(VisitEndedScreen, view, ended)
        if overlay is not None and (type(overlay) is not overlay_cls or key != self.key):
            app.pop_screen()
            overlay = None
        if base is None or key != self.key:
            screen = make()
            (app.push_screen if base is None else app.switch_screen)(screen)
        else:
            base.show(view)
        self.key = key
        if overlay is not None:
            overlay.show(view)
        elif overlay_cls is not None:
            app.push_screen(overlay_cls(view))


def patient_view(
    session: Session,
    channels: KioskChannels,
    questionnaire: Questionnaire,
    *,
    show_score: bool = False,
    remote_page: int = 0,
) -> PatientView:
    """What the patient's screens show now: the session's snapshot and the ways to answer."""
    snap = session.snapshot()
    # the session lifts voice_off when voice in goes; checked here too so the button never
    # promises listening that cannot happen (and not over Continue while paused)
    voice_again = bool(VOICE_OFF & snap.adaptations) and not (snap.paused or snap.halted) and channels.on(VOICE_IN)
    question = snap.item or snap.practice
    hint = len(question.options) if channels.no_such_option and question is not None else None
    return PatientView(
        snap,
        questionnaire,
        channels.ways(snap),
        voice_again=voice_again,
        hint_options=hint,
        now=session.now(),
        show_score=show_score,
        remote_page=remote_page,
    )
