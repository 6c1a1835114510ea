"""A question with its numbered answer buttons: the heart of the question and practice screens."""

from __future__ import annotations

from collections.abc import Sequence

from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widgets import Static

from kiosk.widgets.answer_button import AnswerButton


class QuestionPanel(Vertical):
    """The question in large bold text above one button per option, numbered from 1."""

    def __init__(self, question: str, options: Sequence[str], *, chosen: int | None = None) -> None:
        """Show ``question`` and the ``options`` labels (option 1 first); mark ``chosen`` if set."""
        super().__init__(classes="panel")
        self.question = question
        self.options = tuple(options)
        self.chosen = chosen

    def compose(self) -> ComposeResult:
        """The question text, then the answers taking all the height left."""
        yield Static(self.question, id="question")
        with Vertical(id="answers"):
            for number, label in enumerate(self.options, start=1):
                yield AnswerButton(number, label, id=f"answer-{number}")

    def on_mount(self) -> None:
        """Show the chosen answer, if any, once the buttons exist."""
        self.mark_chosen(self.chosen)

    def show_item(self, question: str, options: Sequence[str], *, chosen: int | None = None) -> bool:
        """Show another question in place when it has as many options as this one (the usual next
        question), rewording the existing widgets instead of mounting new ones, which is most of
        the cost of a question change; returns False, changing nothing, when the count differs."""
        options = tuple(options)
        if len(options) != len(self.options):
            return False
        self.question, self.options = question, options
        self.query_one("#question", Static).update(question)
        for button in self.query(AnswerButton):
            button.relabel(options[button.option - 1])
        self.mark_chosen(chosen)
        return True

    def mark_chosen(self, option: int | None) -> None:
        """Highlight the recorded answer (after an answer, until the next question opens)."""
        self.chosen = option
        for button in self.query(AnswerButton):
            button.set_class(button.option == option, "-chosen")
