"""A big answer button numbered like the remote control's buttons."""

from __future__ import annotations

from textual import events
from textual.app import ComposeResult
from textual.binding import Binding
from textual.message import Message
from textual.widget import Widget

from kiosk.ui.widgets.literal import Label

#: each digit as 3x5 pixels: solid strokes, not Textual's box-drawing Digits, which read as
#: brackets from a metre away
_FONT = {
    "0": ("111", "101", "101", "101", "111"),
    "1": ("010", "110", "010", "010", "111"),
    "2": ("111", "001", "111", "100", "111"),
    "3": ("111", "001", "111", "001", "111"),
    "4": ("101", "101", "111", "001", "001"),
    "5": ("111", "100", "111", "001", "111"),
    "6": ("111", "100", "111", "101", "111"),
    "7": ("111", "001", "001", "001", "001"),
    "8": ("111", "101", "111", "101", "111"),
    "9": ("111", "101", "111", "001", "111"),
}
_HALVES = {("0", "0"): " ", ("1", "0"): "▀", ("0", "1"): "▄", ("1", "1"): "█"}


def big_number(number: int, rows: int = 5) -> str:
    """``number`` in solid block figures, six columns a digit (two a pixel, so on a cell twice as
    tall as wide each pixel is square): five rows high with ``rows`` >= 5, else three rows of half
    blocks (a blank pixel row on top centres the five-pixel figure)."""
    lines: list[str] = []
    for digit in str(number):
        pixels = _FONT[digit]
        if rows >= 5:
            drawn = ["".join("██" if p == "1" else "  " for p in row) for row in pixels]
        else:
            padded = ("000", *pixels)
            drawn = ["".join(_HALVES[t, b] * 2 for t, b in zip(padded[2 * r], padded[2 * r + 1])) for r in range(3)]
        lines = [a + (" " if a else "") + b for a, b in zip(lines, drawn)] if lines else drawn
    return "\n".join(lines)


class BigNumber(Widget):
    """An answer's number in :func:`big_number` figures, five rows high when it has the rows."""

    def __init__(self, number: int, *, classes: str | None = None) -> None:
        super().__init__(classes=classes)
        self.number = number

    def render(self) -> str:
        """The figure for the height the layout gave it."""
        return big_number(self.number, self.size.height)


class AnswerButton(Widget, can_focus=True):
    """One answer option: its number in large solid figures (as printed on the remote) and its label.
    The layout around it sets its height and the class ``-big`` when the digits fit.

    A click or tap posts :class:`AnswerButton.Chosen`; the screen forwards it to the session as a
    touch input. It never decides anything itself.
    """

    BINDINGS = [Binding("enter,space", "choose", "Choose", show=False)]
    #: a touch chooses, it does not focus: the focus outline drew a light strip over the chosen
    #: answer's dark edge (Tab still focuses, for a keyboard)
    FOCUS_ON_CLICK = False

    class Chosen(Message):
        """The patient touched (or clicked) this answer."""

        def __init__(self, option: int | None) -> None:
            self.option = option
            """1-based option number of the item; None for the page button of a paged item
            ("More answers" / "Back", :mod:`kiosk.ui.paging`)."""
            super().__init__()

    def __init__(self, option: int | None, label: str, *, id: str | None = None, shows: int | None = None) -> None:
        """Show answer ``option`` (1-based; None: the page button) with its ``label`` in the
        session's language, numbered ``shows`` (default: the option's own number) -- on a paged
        item, option 5 shows 2, the number the remote presses for it."""
        super().__init__(id=id, classes="answer")
        self.option = option
        self.shows = shows if shows is not None else (option or 0)
        self.label = label

    def compose(self) -> ComposeResult:
        """The number -- in block digits when the button is tall enough, else in bold -- beside
        the answer text."""
        yield BigNumber(self.shows, classes="number")
        yield Label(str(self.shows), classes="small-number")
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
