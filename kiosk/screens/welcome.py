"""Welcome: the patient chooses a language and starts; the channel states are listed in full."""

from __future__ import annotations

from collections.abc import Hashable

from textual import on
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.message import Message
from textual.widgets import Button, Static

from kiosk.screens.base import PatientScreen, PatientView
from kiosk.widgets.bars import channel_reasons
from kiosk.widgets.text import ui_text

#: each language's start button, in that language: choosing the language starts the test
START_IN = {"en": "Start in English", "es": "Empezar en español", "fr": "Commencer en français"}


class WelcomeScreen(PatientScreen):
    """A welcome sentence, one big button per language, and which channels are on or off."""

    class LanguageChosen(Message):
        """The patient touched a language: start in it."""

        def __init__(self, language: str) -> None:
            self.language = language
            """One of the questionnaire's languages."""
            super().__init__()

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """Rebuilt when the language changes (the welcome sentence changes with it)."""
        return view.snapshot.language

    def compose(self) -> ComposeResult:
        """Bars, the welcome message, the language buttons (numbered like the remote)."""
        yield from self.compose_bars()
        q = self.view.questionnaire
        yield Static(q.message("welcome", self.language), classes="heading", id="welcome")
        yield Static(ui_text(self.language, "choose_language"), classes="notice")
        with Vertical(id="languages"):
            for number, language in enumerate(q.languages, start=1):
                yield Button(f"{number}  {START_IN.get(language, language)}", id=f"language-{language}")
        yield Static(channel_reasons(self.view.channels), id="channel-reasons")

    def show(self, view: PatientView) -> None:
        """Also keep the list of channels that are off (and why) current."""
        super().show(view)
        for reasons in self.query("#channel-reasons").results(Static):
            reasons.update(channel_reasons(view.channels))

    @on(Button.Pressed, "#languages Button")
    def _language(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.LanguageChosen((event.button.id or "").removeprefix("language-")))
