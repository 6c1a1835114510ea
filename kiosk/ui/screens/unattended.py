"""Nobody answered questions in a row: the kiosk waits for a touch instead of asking on into an
empty room ("Are you still there? Touch the screen to go on.")."""

from __future__ import annotations

from textual import events, on
from textual.app import ComposeResult
from textual.message import Message

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text


class UnattendedScreen(PatientScreen):
    """One calm line and one big Go on; a touch anywhere on the screen goes on too (as do the
    number keys and the remote, through the session). While the patient is away the line gives
    way to the away notice: one message at a time."""

    SHOWS_ATTEMPT = False

    class GoOn(Message):
        """Someone touched the screen."""

    def __init__(self, view: PatientView) -> None:
        """Build the screen for ``view``."""
        super().__init__(view)
        self._sent = False

    def compose(self) -> ComposeResult:
        """Bars, the line and Go on."""
        yield from self.compose_bars()
        yield Static(self._line(self.view), classes="heading", id="unattended-text")
        yield Button(ui_text(self.language, "go_on"), id="go-on", classes="big-action")

    def _line(self, view: PatientView) -> str:
        return "" if not view.snapshot.person_present else ui_text(self.language, "unattended")

    def show(self, view: PatientView) -> None:
        """The line, unless the away notice says the one thing to say."""
        super().show(view)
        for line in self.query("#unattended-text").results(Static):
            line.update(self._line(view))
            line.display = view.snapshot.person_present

    @on(Button.Pressed, "#go-on")
    def _go_on(self, event: Button.Pressed) -> None:
        event.stop()
        self._touched()

    def on_click(self, event: events.Click) -> None:
        """A touch anywhere on the screen is the touch the kiosk waits for."""
        event.stop()
        self._touched()

    def _touched(self) -> None:
        """Go on, once: a second tap must not answer the question that opens next."""
        if not self._sent:
            self._sent = True
            self.post_message(self.GoOn())
