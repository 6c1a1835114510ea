"""'Change my answer': offered during the thank-you gap after an answer."""

from __future__ import annotations

from textual.message import Message
from textual.widgets import Button

from kiosk.widgets.text import ui_text


class ChangeAnswerButton(Button):
    """Takes back the answer just given (the app sends the undo command); hidden otherwise."""

    class Requested(Message):
        """The patient touched "Change my answer"."""

    def __init__(self, language: str) -> None:
        """A hidden button with the words of ``language``."""
        super().__init__(ui_text(language, "change_answer"), id="change-answer")
        self.display = False

    def show(self, offered: bool) -> None:
        """Show the button while an answer can still be changed."""
        self.display = offered

    def on_button_pressed(self, event: Button.Pressed) -> None:
        """Forward the touch as a request; the session decides whether it is still possible."""
        event.stop()
        self.post_message(self.Requested())
