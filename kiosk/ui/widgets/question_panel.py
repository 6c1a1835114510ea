"""A question with its numbered answer buttons: the heart of the question and practice screens."""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

from textual import events
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.geometry import Size
from textual.message import Message
from textual.widget import Widget

from kiosk.ui.answer_pages import GAP, MIN_ROWS, Plan, page_of, plan
from kiosk.ui.widgets.answer_button import AnswerButton
from kiosk.ui.widgets.literal import Label, Static


class MoreAnswers(AnswerButton):
    """The page button of answers that do not all fit the display (:mod:`kiosk.ui.answer_pages`):
    "More answers", or "Back" on the last page. A touch turns the page; it chooses nothing."""

    class Turned(Message):
        """The patient touched the page button."""

    def __init__(self, label: str) -> None:
        super().__init__(None, label, id="answer-more", shows=0)

    def compose(self) -> ComposeResult:
        """A quiet arrow where the number goes (no number: no key or remote button means it)."""
        yield Label("»", classes="small-number")
        yield Label(self.label, classes="label")

    def action_choose(self) -> None:
        """Ask the answer list for its next page."""
        self.post_message(self.Turned())


class AnswerList(Vertical):
    """The answer buttons, laid out again whenever the height left for them, or their texts,
    change: every answer's whole text on screen, on pages when the display is too small for all
    of them at once (:func:`kiosk.ui.answer_pages.plan`)."""

    def __init__(self, *, turn: tuple[str, str] = ("»", "«"), id: str | None = None) -> None:
        """``turn``: the page button's label on every page but the last, and on the last."""
        super().__init__(id=id)
        self.turn = turn
        self.plan: Plan | None = None
        #: the page shown (0: the first answers)
        self.page = 0
        #: the option whose page to show at the next layout (the chosen answer stays in view)
        self._wanted: int | None = None

    def on_resize(self, event: events.Resize) -> None:
        """The question above took more or fewer rows, or the display changed."""
        self.lay_out()

    def answers(self) -> list[AnswerButton]:
        """The item's answer buttons, in order (not the page button)."""
        return [b for b in self.query(AnswerButton) if not isinstance(b, MoreAnswers)]

    def lay_out(self, page: int | None = None) -> None:
        """Stack the answers, or put them two-by-two, all equally tall, on as many pages as their
        texts need; show ``page`` (default: the one shown, or the first if it is gone)."""
        rows, width = self.content_region.height, self.content_region.width
        buttons = self.answers()
        if rows <= 0 or width <= 0 or not buttons:
            return
        more = next(iter(self.query(MoreAnswers)), None)
        labels = [b.query_one(".label", Label) for b in buttons]
        size = Size(width, rows)

        def lines(index: int | None, text_width: int) -> int:
            if index is None:  # the page button's words, wrapped as a label wraps them
                return max(len(textwrap.wrap(words, text_width)) for words in self.turn)
            return labels[index].get_content_height(size, size, text_width)

        roomy = self.screen.has_class("-roomy")
        self.plan = plan_ = plan(len(buttons), rows, width, lines, roomy=roomy)
        if page is None and self._wanted is not None:
            index = next((i for i, b in enumerate(buttons) if b.option == self._wanted), None)
            page = page_of(plan_, index) if index is not None else None
        self._wanted = None
        self.page = min(self.page if page is None else page, len(plan_.pages) - 1)
        if plan_.paged and more is None:  # mounted the first time the answers need pages
            self.mount(MoreAnswers(self.turn[0]))
            self.call_after_refresh(self.lay_out)
        elif more is not None:
            more.display = plan_.paged
            more.relabel(self.turn[self.page == len(plan_.pages) - 1])
        shown = set(plan_.pages[self.page])
        self.set_class(plan_.columns == 2, "-two-by-two")
        self.styles.grid_rows = str(plan_.height)
        visible = [b for i, b in enumerate(buttons) if i in shown] + ([more] if plan_.paged and more else [])
        for index, button in enumerate(buttons):
            button.display = index in shown
        for n, button in enumerate(visible):
            button.styles.height = plan_.height
            last = n == len(visible) - 1
            button.styles.margin = (0, 0, 0 if plan_.columns == 2 or last else GAP, 0)
            button.set_class(plan_.height >= MIN_ROWS, "-big")

    def show_option(self, option: int | None) -> None:
        """Turn to the page with ``option`` on it (the chosen answer stays in view)."""
        if option is None:
            return
        self._wanted = option
        if self.plan is not None:
            self.lay_out()

    def on_more_answers_turned(self, message: MoreAnswers.Turned) -> None:
        """The next page, or the first after the last."""
        message.stop()
        if self.plan is not None:
            self.lay_out((self.page + 1) % len(self.plan.pages))


class QuestionPanel(Vertical):
    """The question in large bold text above one button per option, numbered from 1.

    The answers share the height the question leaves, all equally tall, stacked or -- when the
    display is short -- two-by-two, and on pages when even that cuts a text, so every answer shown
    is whole whatever the display's size.
    """

    def __init__(
        self,
        question: str,
        options: Sequence[str],
        *,
        chosen: int | None = None,
        over_question: Widget | None = None,
        buttons: Sequence[tuple[int, int | None]] | None = None,
        turn: tuple[str, str] = ("»", "«"),
    ) -> None:
        """Show ``question`` and the ``options`` labels (option 1 first); mark ``chosen`` if set.
        ``over_question`` (the thank-you row) is laid over the question text's rows when shown.
        ``buttons`` (a remote's page, :mod:`kiosk.ui.paging`): the (number shown, option) of each
        button, option None for the page button whose label is the last of ``options``.
        ``turn``: the words of the display's page button, "More answers" and "Back", shown when
        the answers do not all fit the display at once (:class:`AnswerList`)."""
        super().__init__(classes="panel")
        self.turn = turn
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
        with AnswerList(turn=self.turn, id="answers"):
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
        answers = self.query_one(AnswerList)
        for button, label in zip(answers.answers(), options):
            button.relabel(label)
        answers.lay_out(page=0)  # the new texts may wrap to other heights
        self.mark_chosen(chosen)
        return True

    def mark_chosen(self, option: int | None) -> None:
        """Highlight the recorded answer (after an answer, until the next question opens)."""
        self.chosen = option
        for button in self.query(AnswerButton):
            button.set_class(option is not None and button.option == option, "-chosen")
        self.query_one(AnswerList).show_option(option)
