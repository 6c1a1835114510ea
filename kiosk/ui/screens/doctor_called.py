"""Doctor called: the session is halted until a clinician continues it, or the patient says they
are fine (an accidental D must not end their test)."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.message import Message

from kiosk.ui.screens.base import PatientScreen
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text


class DoctorCalledScreen(PatientScreen):
    """Reassures the patient that help is coming, and offers "1  I'm fine, carry on" (the button,
    the 1 key or the remote's 1; never by voice, so a misheard phrase cannot call help off). No
    attempt count: nothing is being asked while help comes."""

    SHOWS_ATTEMPT = False

    class CarryOn(Message):
        """The patient touched "I'm fine, carry on"."""

    def compose(self) -> ComposeResult:
        """Bars, the title, the reassurance and the way back to the test."""
        yield from self.compose_bars()
        yield Static(ui_text(self.language, "doctor_title"), classes="heading", id="doctor-title")
        yield Static(
            self.view.questionnaire.message("doctor_called", self.language) or ui_text(self.language, "doctor_text"),
            classes="notice",
        )
        yield Button(ui_text(self.language, "doctor_cancel"), id="doctor-cancel", classes="big-action")

    @on(Button.Pressed, "#doctor-cancel")
    def _carry_on(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.CarryOn())
