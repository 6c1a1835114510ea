"""Paused: the session waits for the patient, with one big Continue button."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.widgets import Static

from kiosk.screens.base import PatientScreen
from kiosk.widgets.bars import ControlBar
from kiosk.widgets.text import ui_text


class PausedScreen(PatientScreen):
    """Tells the patient the test waits for them; Continue (P) and Call doctor stay available."""

    def compose(self) -> ComposeResult:
        """Bars, the paused title and text, and the controls with Continue."""
        yield from self.compose_bars()
        yield Static(ui_text(self.language, "paused_title"), classes="heading", id="paused-title")
        yield Static(self.view.questionnaire.message("paused", self.language)
                     or ui_text(self.language, "paused_text"), classes="notice")
        yield ControlBar(self.language, paused=True)
