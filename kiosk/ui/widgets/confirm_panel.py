"""'I heard: Independent. Is that right?' with two big answers, Yes (1) and No (2)."""

from __future__ import annotations

from collections.abc import Sequence

from textual.app import ComposeResult
from textual.containers import Vertical

from kiosk.ui.widgets.answer_button import AnswerButton
from kiosk.ui.widgets.literal import Static


class ConfirmPanel(Vertical):
    """The question back, large, above one button per reply (numbered like the remote's buttons).

    A touch posts ``AnswerButton.Chosen`` like any answer; the session knows that 1 is Yes and 2
    is No while it asks back.
    """

    def __init__(self, question: str, replies: Sequence[str]) -> None:
        """Show ``question`` (the session's confirm prompt) and the ``replies`` (Yes first)."""
        super().__init__(classes="panel", id="confirm")
        self.question = question
        self.replies = tuple(replies)

    def ask(self, question: str) -> None:
        """Put ``question`` in place of the one shown (asked again in other words: "Please press
        Yes or No" where a spoken yes could not be told from the room)."""
        if question != self.question:
            self.question = question
            for line in self.query("#confirm-question").results(Static):
                line.update(question)

    def compose(self) -> ComposeResult:
        """The question back, then the replies taking the height left."""
        yield Static(self.question, id="confirm-question")
        with Vertical(id="confirm-answers"):
            for number, label in enumerate(self.replies, start=1):
                yield AnswerButton(number, label, id=f"reply-{number}")
