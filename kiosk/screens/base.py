"""What every patient screen shares: the view it renders and the way it forwards keys."""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass

from textual import events
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.screen import Screen
from textual.widgets import Label

from kiosk.questionnaire import Questionnaire
from kiosk.session import ATTEMPTS, Snapshot
from kiosk.widgets.bars import AdaptationBanner, ChannelBar, ChannelLine, VoiceAgainButton
from kiosk.widgets.text import ui_text
from kiosk.widgets.waiting_sign import WaitingSign


@dataclass(frozen=True)
class PatientView:
    """Everything a patient screen draws: the session's snapshot plus what the app knows around it."""

    snapshot: Snapshot
    questionnaire: Questionnaire
    #: channel indicators, in display order
    channels: tuple[ChannelLine, ...]
    #: a notice to show above the answers (an adaptation, "we cannot see you"), or None
    banner: str | None = None
    #: offer "Answer by voice again" (voice is switched off by adaptation and voice in works)
    voice_again: bool = False
    #: session time now (the waiting sign's slow dot follows it)
    now: float = 0.0
    #: the end screen shows the total and band (a site's choice; default: staff only)
    show_score: bool = False

    @property
    def waiting(self) -> bool:
        """An answer is awaited now (an attempt is open and nothing stops the clock)."""
        snap = self.snapshot
        return snap.attempt is not None and not (snap.paused or snap.halted) and snap.person_present


class PatientScreen(Screen):
    """Base of the patient's screens: built from a view, refreshed in place by :meth:`show`.

    The app switches to a new screen only when :meth:`key` of the new view differs (another
    phase, question or language); otherwise it calls :meth:`show` so a tick of the clock or a
    channel change does not rebuild the screen.
    """

    #: nothing starts focused: a focused answer would look chosen; keys and touch need no focus
    AUTO_FOCUS = ""

    def __init__(self, view: PatientView) -> None:
        """Build the screen for ``view``."""
        super().__init__()
        self.view = view

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """What makes two views need different screens of this class (default: the language)."""
        return view.snapshot.language

    @property
    def language(self) -> str:
        """The language the screen is drawn in."""
        return self.view.snapshot.language

    def compose_bars(self) -> ComposeResult:
        """Progress and attempt, channel states, the adaptation banner and its voice-again button."""
        with Horizontal(id="topbar"):
            yield Label("", id="progress")
            yield Label("", id="attempt")
        yield ChannelBar(id="channels")
        yield AdaptationBanner(id="banner")
        yield VoiceAgainButton(self.language)

    def on_mount(self) -> None:
        """Fill the bars once they exist."""
        self.show(self.view)

    def show(self, view: PatientView) -> None:
        """Refresh the parts that change within one screen (bars, banner, attempt)."""
        self.view = view
        snap = view.snapshot
        for progress in self.query("#progress").results(Label):
            progress.update(self.progress_text(view))
        for attempt in self.query("#attempt").results(Label):
            attempt.update(ui_text(self.language, "attempt_of", number=snap.attempt, total=ATTEMPTS)
                           if snap.attempt else "")
        for bar in self.query(ChannelBar):
            bar.show(view.channels)
        for banner in self.query(AdaptationBanner):
            banner.show(view.banner)
        for button in self.query(VoiceAgainButton):
            button.show(view.voice_again)
        for sign in self.query(WaitingSign):
            sign.show(view.waiting, view.now)

    def progress_text(self, view: PatientView) -> str:
        """The left of the top bar: the questionnaire's title unless a screen says more."""
        return view.questionnaire.title.get(self.language, "")

    def on_key(self, event: events.Key) -> None:
        """Hand kiosk keys (1-4, P, D, R, a keyboard remote's keys) to the app."""
        if self.app.patient_key(event.key):  # type: ignore[attr-defined]
            event.stop()
            event.prevent_default()


class ClinicianScreen(Screen):
    """Base of the screens behind the PIN; the patient's screen waits underneath until they close."""

    BINDINGS = [("escape", "close", "Back")]

    def action_close(self) -> None:
        """Go back one clinician screen (from the first one, back to the patient)."""
        self.dismiss()
