"""Explanation: how to answer, read aloud; the patient confirms to reach the first question."""

from __future__ import annotations

from textual import on
from textual.app import ComposeResult
from textual.message import Message

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.bars import ControlBar
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text, ways_sentence


def how_to_answer(view: PatientView) -> str:
    """ "Answer by touching it on the screen or ..." and how to start, from the channels on now."""
    lang, ways = view.snapshot.language, view.ways.answering()
    return f"{ways_sentence(lang, 'answer_by', ways)} {ways_sentence(lang, 'start_by', ways, '_start')}"


class ExplanationScreen(PatientScreen):
    """The explanation text and one big Start button (any answer key or remote button also starts)."""

    ASKS = True

    class Understood(Message):
        """The patient touched Start."""

    def compose(self) -> ComposeResult:
        """Bars, the explanation, how to answer, Start, and the controls."""
        yield from self.compose_bars()
        yield Static(self.view.questionnaire.message("explanation", self.language), classes="heading", id="explanation")
        yield Static(how_to_answer(self.view), classes="notice", id="how-to-answer")
        yield Button(ui_text(self.language, "start"), id="understood", classes="big-action")
        yield ControlBar(self.language, repeat=self.view.ways.voice_out)

    def show(self, view: PatientView) -> None:
        """Keep the instructions true to the channels on now."""
        super().show(view)
        for line in self.query("#how-to-answer").results(Static):
            line.update(how_to_answer(view))
        for bar in self.query(ControlBar):
            bar.show_repeat(view.ways.voice_out)

    @on(Button.Pressed, "#understood")
    def _understood(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.Understood())
