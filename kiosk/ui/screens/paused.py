"""Paused: the session waits for the patient, with one big Continue button."""

from __future__ import annotations

from textual.app import ComposeResult

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.bars import ControlBar
from kiosk.ui.widgets.literal import Static
from kiosk.ui.widgets.text import ui_text, ways_sentence


def how_to_continue(view: PatientView) -> str:
    """ "We are waiting for you. When you are ready, touch Continue ..." from the channels on now."""
    lang = view.snapshot.language
    return (
        f"{view.questionnaire.message('paused', lang) or ui_text(lang, 'paused_text')} "
        f"{ways_sentence(lang, 'continue_by', view.ways.answering(), '_continue')}"
    )


class PausedScreen(PatientScreen):
    """Tells the patient the test waits for them; Continue (P) and Call doctor stay available."""

    def compose(self) -> ComposeResult:
        """Bars, the paused title and text, and the controls with Continue."""
        yield from self.compose_bars()
        yield Static(ui_text(self.language, "paused_title"), classes="heading", id="paused-title")
        yield Static(how_to_continue(self.view), classes="notice", id="paused-text")
        yield ControlBar(self.language, paused=True)

    def show(self, view: PatientView) -> None:
        """Keep the instructions true to the channels on now."""
        super().show(view)
        for line in self.query("#paused-text").results(Static):
            line.update(how_to_continue(view))
