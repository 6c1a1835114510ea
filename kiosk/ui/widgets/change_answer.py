"""The thank-you gap after an answer: the calm line and 'Change my answer', in a row of their own."""

from __future__ import annotations

from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.message import Message

from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import ui_text


class ChangeAnswerButton(Button):
    """Takes back the answer just given (the app sends the undo command); hidden otherwise."""

    class Requested(Message):
        """The patient touched "Change my answer"."""

    def __init__(self, language: str, *, offered: bool = False) -> None:
        """A button with the words of ``language``, shown while ``offered``."""
        super().__init__(ui_text(language, "change_answer"), id="change-answer")
        self.display = offered

    def show(self, offered: bool) -> None:
        """Show the button while an answer can still be changed."""
        self.display = offered

    def on_button_pressed(self, event: Button.Pressed) -> None:
        """Forward the touch as a request; the session decides whether it is still possible."""
        event.stop()
        self.post_message(self.Requested())


class ThanksRow(Horizontal):
    """ "Thank you. Next question…" with "Change my answer" at its right, shown during a gap.

    Over a question it takes exactly the question text's rows (the stylesheet lays it over them),
    so the answers below -- the chosen one marked -- neither move nor are covered; above the
    explanation recap it is a row in the flow. It never measures anything after a refresh: where
    it is drawn follows from the layout alone.
    """

    def __init__(self, language: str, line: str = "", *, offered: bool = False) -> None:
        """The row in ``language`` showing ``line`` (hidden while empty and nothing is ``offered``)."""
        super().__init__(id="gap")
        self.language = language
        self._line, self._offered = line, offered
        self.display = bool(line) or offered

    def compose(self) -> ComposeResult:
        """The line, then the button."""
        line = Static(self._line, id="interlude", classes="interlude")
        line.display = bool(self._line)
        yield line
        yield ChangeAnswerButton(self.language, offered=self._offered)

    def show(self, line: str, offered: bool) -> None:
        """Show ``line`` (none: empty) and the button while ``offered``; hide the row if neither."""
        self._line, self._offered = line, offered
        self.display = bool(line) or offered
        for static in self.query("#interlude").results(Static):
            static.update(line)
            static.display = bool(line)
        for button in self.query(ChangeAnswerButton):
            button.show(offered)
