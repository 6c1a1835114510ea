"""The rest between two instruments of a battery: "Well done. Next: <title>. Take a breath." and
Continue, which shows the next instrument's explanation (any answer key or remote button too)."""

from __future__ import annotations

from textual.app import ComposeResult

from kiosk.ui.screens.explanation import ExplanationScreen
from kiosk.ui.widgets.bars import ControlBar
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text


class RestScreen(ExplanationScreen):
    """The rest screen: one sentence and one big Continue (it posts the explanation's
    ``Understood``, which the session takes as "go on" in both phases)."""

    def compose(self) -> ComposeResult:
        """Bars, the rest sentence naming the next instrument, Continue, and the controls."""
        yield from self.compose_bars()
        title = self.view.questionnaire.title_for_patient(self.language) or self.view.questionnaire.id
        yield Static(ui_text(self.language, "rest", title=title), classes="heading", id="rest")
        yield Button(ui_text(self.language, "rest_continue"), id="understood", classes="big-action")
        yield ControlBar(self.language, repeat=self.view.ways.voice_out)
