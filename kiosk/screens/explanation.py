"""Explanation: how to answer, read aloud; the patient confirms to reach the first question."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.message import Message
from textual.widgets import Button, Static

from kiosk.screens.base import PatientScreen
from kiosk.widgets.bars import ControlBar
from kiosk.widgets.text import ui_text


class ExplanationScreen(PatientScreen):
    """The explanation text and one big Start button (any answer key or remote button also starts)."""

    class Understood(Message):
        """The patient touched Start."""

    def compose(self) -> ComposeResult:
        """Bars, the explanation, Start, and the controls."""
        yield from self.compose_bars()
        yield Static(self.view.questionnaire.message("explanation", self.language), classes="heading",
                     id="explanation")
        yield Button(ui_text(self.language, "start"), id="understood", classes="big-action")
        yield ControlBar(self.language)

    @on(Button.Pressed, "#understood")
    def _understood(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.Understood())
