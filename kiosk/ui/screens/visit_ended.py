"""The visit was cancelled at the ward station while it ran: one calm end in the patient's
language ("This visit has ended. Thank you for your time. A member of staff will come to you."),
naming no one, until someone touches the screen; then the welcome (or the visits waiting)."""

from __future__ import annotations

from collections.abc import Hashable

from textual import events, on
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.message import Message

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text


class VisitEndedScreen(PatientScreen):
    """The end of a visit the ward cancelled: what was answered is stored (the controller did that
    before this screen), nothing here starts or answers anything; a touch anywhere dismisses it."""

    NOTICES = False
    SHOWS_ATTEMPT = False

    class Dismissed(Message):
        """Someone touched the screen: the welcome may come back."""

    def __init__(self, view: PatientView, language: str) -> None:
        """``language``: the cancelled visit's (the session on the stage is already the next one)."""
        super().__init__(view)
        self.ended_language = language
        self._sent = False

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        return "visit ended"

    def progress_text(self, view: PatientView) -> str:
        return ""

    def compose(self) -> ComposeResult:
        yield from self.compose_bars()
        with Vertical(id="visit-ended"):
            yield Static(ui_text(self.ended_language, "visit_ended_title"), classes="heading", id="visit-ended-title")
            yield Static(ui_text(self.ended_language, "visit_ended_text"), classes="notice", id="visit-ended-text")
            yield Button(ui_text(self.ended_language, "visit_ended_ok"), id="visit-ended-ok", classes="big-action")

    @on(Button.Pressed, "#visit-ended-ok")
    def _ok(self, event: Button.Pressed) -> None:
        event.stop()
        self._touched()

    def on_click(self, event: events.Click) -> None:
        event.stop()
        self._touched()

    def on_key(self, event: events.Key) -> None:
        """A key or a remote's button dismisses it too (never answers: no test runs)."""
        event.stop()
        event.prevent_default()
        self._touched()

    def _touched(self) -> None:
        if not self._sent:
            self._sent = True
            self.post_message(self.Dismissed())
