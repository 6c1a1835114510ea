"""A question with its numbered answer buttons: the heart of the question and practice screens."""

from __future__ import annotations

from collections.abc import Sequence

from textual import events
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.widget import Widget

from kiosk.ui.widgets.answer_button import AnswerButton
from kiosk.ui.widgets.literal import Static

#: rows between two answers (stacked or two-by-two)
GAP = 1
#: the fewest rows an answer gets before the answers go two-by-two; at 3 rows and wide enough, the
#: number is drawn in big block digits
MIN_ROWS = 3


def arrangement(count: int, rows: int) -> tuple[int, int]:
    """How ``count`` answers share ``rows`` rows: (columns, height of each answer). One column
    while each answer still gets :data:`MIN_ROWS`, else two-by-two; every answer the same height
    (spare rows stay below the last), and never less than one row."""
    columns = 1 if (rows - GAP * (count - 1)) // count >= MIN_ROWS else 2
    lines = -(-count // columns)
    return columns, max(1, (rows - GAP * (lines - 1)) // lines)


class AnswerList(Vertical):
    """The answer buttons, laid out again whenever the height left for them changes."""

    def on_resize(self, event: events.Resize) -> None:
        """The question above took more or fewer rows, or the display changed."""
        self.lay_out()

    def lay_out(self) -> None:
        """Stack the answers, or put them two-by-two, all equally tall (:func:`arrangement`)."""
        rows = self.content_region.height
        buttons = list(self.query(AnswerButton))
        if rows <= 0 or not buttons:
            return
        columns, height = arrangement(len(buttons), rows)
        self.set_class(columns == 2, "-two-by-two")
        self.styles.grid_rows = str(height)
        for button in buttons:
            button.styles.height = height
            button.set_class(height >= MIN_ROWS, "-big")


class QuestionPanel(Vertical):
    """The question in large bold text above one button per option, numbered from 1.

    The answers share the height the question leaves, all equally tall, stacked or -- when the
    display is short -- two-by-two, so every answer is on screen whatever its size.
    """

    def __init__(
        self,
        question: str,
        options: Sequence[str],
        *,
        chosen: int | None = None,
        over_question: Widget | None = None,
        buttons: Sequence[tuple[int, int | None]] | None = None,
    ) -> None:
        """Show ``question`` and the ``options`` labels (option 1 first); mark ``chosen`` if set.
        ``over_question`` (the thank-you row) is laid over the question text's rows when shown.
        ``buttons`` (a remote's page, :mod:`kiosk.ui.paging`): the (number shown, option) of each
        button, option None for the page button whose label is the last of ``options``."""
        super().__init__(classes="panel")
        self.question = question
        self.options = tuple(options)
        self.buttons = tuple(buttons) if buttons is not None else tuple((n, n) for n in range(1, len(options) + 1))
        self.chosen = chosen
        self._over = over_question

    def compose(self) -> ComposeResult:
        """The question text (with what is laid over it), then the answers taking all the height left."""
        with Vertical(id="head"):
            yield Static(self.question, id="question")
            if self._over is not None:
                yield self._over
        with AnswerList(id="answers"):
            for (shows, option), label in zip(self.buttons, self.options):
                name = f"answer-{option}" if option is not None else "answer-page"
                yield AnswerButton(option, label, id=name, shows=shows)

    def on_mount(self) -> None:
        """Show the chosen answer, if any, once the buttons exist."""
        self.mark_chosen(self.chosen)

    def show_item(
        self,
        question: str,
        options: Sequence[str],
        *,
        chosen: int | None = None,
        buttons: Sequence[tuple[int, int | None]] | None = None,
    ) -> bool:
        """Show another question in place when it has the same buttons as this one (the usual next
        question), rewording the existing widgets instead of mounting new ones, which is most of
        the cost of a question change; returns False, changing nothing, when they differ."""
        options = tuple(options)
        layout = tuple(buttons) if buttons is not None else tuple((n, n) for n in range(1, len(options) + 1))
        if layout != self.buttons:
            return False
        self.question, self.options = question, options
        self.query_one("#question", Static).update(question)
        for button, label in zip(self.query(AnswerButton), options):
            button.relabel(label)
        self.mark_chosen(chosen)
        return True

    def mark_chosen(self, option: int | None) -> None:
        """Highlight the recorded answer (after an answer, until the next question opens)."""
        self.chosen = option
        for button in self.query(AnswerButton):
            button.set_class(option is not None and button.option == option, "-chosen")
