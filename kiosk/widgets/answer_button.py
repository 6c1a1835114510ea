"""A big answer button numbered like the remote control's buttons."""

from __future__ import annotations

from textual import events
from textual.app import ComposeResult
from textual.binding import Binding
from textual.message import Message
from textual.widget import Widget
from textual.widgets import Digits, Label


class AnswerButton(Widget, can_focus=True):
    """One answer option: its number in large digits (as printed on the remote) and its label.
    The layout around it sets its height and the class ``-big`` when the digits fit.

    A click or tap posts :class:`AnswerButton.Chosen`; the screen forwards it to the session as a
    touch input. It never decides anything itself.
    """

    BINDINGS = [Binding("enter,space", "choose", "Choose", show=False)]

    class Chosen(Message):
        """The patient touched (or clicked) this answer."""

        def __init__(self, option: int) -> None:
            self.option = option
            """1-based option number, the same number as on the remote's button."""
            super().__init__()

    def __init__(self, option: int, label: str, *, id: str | None = None) -> None:
        """Show answer ``option`` (1-based) with its ``label`` in the session's language."""
        super().__init__(id=id, classes="answer")
        self.option = option
        self.label = label

    def compose(self) -> ComposeResult:
        """The number -- in block digits when the button is tall enough, else in bold -- beside
        the answer text."""
        yield Digits(str(self.option), classes="number")
        yield Label(str(self.option), classes="small-number")
        yield Label(self.label, classes="label")

    def relabel(self, label: str) -> None:
        """Show another answer text under the same number (the next question's option)."""
        self.label = label
        self.query_one(".label", Label).update(label)

    def on_click(self, event: events.Click) -> None:
        """A touch anywhere on the button chooses it."""
        event.stop()
        self.action_choose()

    def action_choose(self) -> None:
        """Tell the screen this answer was chosen."""
        self.post_message(self.Chosen(self.option))
