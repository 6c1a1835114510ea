"""Doctor called: the session is halted until a clinician continues it (behind the PIN)."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.widgets import Static

from kiosk.screens.base import PatientScreen
from kiosk.widgets.text import ui_text


class DoctorCalledScreen(PatientScreen):
    """Reassures the patient that help is coming; no buttons, nothing to do but wait."""

    def compose(self) -> ComposeResult:
        """Bars, the title and the reassurance."""
        yield from self.compose_bars()
        yield Static(ui_text(self.language, "doctor_title"), classes="heading", id="doctor-title")
        yield Static(self.view.questionnaire.message("doctor_called", self.language)
                     or ui_text(self.language, "doctor_text"), classes="notice")
