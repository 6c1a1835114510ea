"""A Barthel question: large text, big numbered answers, progress, attempt and controls."""

from __future__ import annotations

from collections.abc import Hashable

from textual.app import ComposeResult
from textual.widget import Widget

from kiosk.core.questionnaire import Item
from kiosk.ui.paging import needs_paging, shown
from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.answer_button import AnswerButton
from kiosk.ui.widgets.bars import ControlBar
from kiosk.ui.widgets.change_answer import ThanksRow
from kiosk.ui.widgets.confirm_panel import ConfirmPanel
from kiosk.ui.widgets.literal import Static
from kiosk.ui.widgets.question_panel import QuestionPanel
from kiosk.ui.widgets.text import ui_text
from kiosk.ui.widgets.waiting_sign import WaitingSign


class QuestionScreen(PatientScreen):
    """One scored item. Touching an answer posts ``AnswerButton.Chosen``; the app forwards it.

    Between questions the last item (before the first, the explanation) stays on screen, its answer
    marked, under a calm line such as "Thank you. Next question…", as the session's
    :attr:`Snapshot.interlude` says, so the patient never faces an empty screen meanwhile; during
    that thank-you gap "Change my answer" is offered beside it. The line and the button take the
    question text's rows (the answers keep theirs), so the chosen answer is never covered. While the
    session asks back an unsure answer ("I heard: … Is that right?") the question's panel gives way
    to the Yes/No panel. While an
    answer is awaited a gentle sign says so.
    """

    ASKS = True

    def __init__(self, view: PatientView) -> None:
        """Build the screen for ``view``'s item."""
        super().__init__(view)
        #: the item whose panel is on screen
        self._item_id: str | None = None
        #: the option the Yes/No panel on screen asks about (None: the question's panel is shown)
        self._confirming: int | None = None
        #: the remote's page of a 5- or 6-answer item on screen
        self._page = 0

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """One screen for all the items of a language: the next item only swaps the panel."""
        return view.snapshot.language

    def compose(self) -> ComposeResult:
        """Bars, the thank-you row (the between-questions line and "Change my answer", hidden
        until a gap), the question with its answers, and the controls."""
        yield from self.compose_bars()
        yield from self._panel(self.view)
        yield WaitingSign(self.language)
        yield ControlBar(self.language, repeat=self.view.ways.voice_out)

    def _panel(self, view: PatientView) -> list[Widget]:
        """The question and answers of the view's item, the thank-you row laid over the question
        text; between the explanation and item 1 the row above the explanation the patient just
        read (none if the questionnaire has no explanation)."""
        item = view.snapshot.item
        self._item_id = item.id if item else None
        self._confirming = view.snapshot.confirming
        prompt = view.snapshot.prompt
        if self._confirming is not None and prompt is not None and prompt.kind == "confirm":
            return [ConfirmPanel(prompt.text, [o.label for o in prompt.options])]
        thanks = ThanksRow(self.language, self._line(view), offered=view.snapshot.can_undo)
        if item is None:
            explanation = view.questionnaire.message("explanation", self.language)
            return [thanks, Static(explanation, classes="notice", id="recap")] if explanation else [thanks]
        answer = view.snapshot.answers.get(item.id)
        labels, buttons = self._answers(view, item)
        return [
            QuestionPanel(
                item.patient_text_in(self.language),
                labels,
                chosen=answer.option if answer else None,
                over_question=thanks,
                buttons=buttons,
                turn=(ui_text(self.language, "more_answers"), ui_text(self.language, "back_answers")),
            )
        ]

    def _answers(self, view: PatientView, item: Item) -> tuple[list[str], list[tuple[int, int | None]] | None]:
        """The answer labels and, on a 5- or 6-answer item while a remote is in use, the page the
        remote is on: three answers numbered 1-3 and "4 More answers" (or "4 Back"), so the
        patient never sees a number the remote cannot press (:mod:`kiosk.ui.paging`)."""
        self._page = view.remote_page
        if not (view.ways.remote and needs_paging(len(item.options))):
            return [o.patient_label_in(self.language) for o in item.options], None
        page = shown(view.remote_page, len(item.options))
        turn = ui_text(self.language, "more_answers" if view.remote_page == 0 else "back_answers")
        labels = [item.option(b.option).patient_label_in(self.language) if b.option else turn for b in page]
        return labels, [(b.number, b.option) for b in page]

    def _line(self, view: PatientView) -> str:
        """The between-questions line in the patient's language ("" outside a gap)."""
        key = view.snapshot.interlude
        return (view.questionnaire.message(key, self.language) or ui_text(self.language, key)) if key else ""

    def show(self, view: PatientView) -> None:
        """Refresh the bars and the thank-you row; swap in the next item's panel, or mark the
        recorded answer."""
        super().show(view)
        for bar in self.query(ControlBar):
            bar.show_repeat(view.ways.voice_out)
        for thanks in self.query(ThanksRow):
            thanks.show(self._line(view), view.snapshot.can_undo)
        if not self.is_mounted:  # compose has not run yet: it will draw this view
            return
        item = view.snapshot.item
        confirming = view.snapshot.confirming
        if (
            (item.id if item else None) != self._item_id
            or confirming != self._confirming
            or view.remote_page != self._page
        ):
            if (
                item is not None
                and self._item_id is not None
                and confirming is None
                and self._confirming is None
                and self._reword(view, item)
            ):
                return
            for old in self.query("QuestionPanel, ConfirmPanel, #recap, ThanksRow"):
                old.remove()
            if widgets := self._panel(view):
                self.mount_all(widgets, before=self.query_one(WaitingSign))
            return
        prompt = view.snapshot.prompt
        if confirming is not None and prompt is not None and prompt.kind == "confirm":
            for confirm in self.query(ConfirmPanel):
                confirm.ask(prompt.text)
        answer = view.snapshot.answers.get(item.id) if item else None
        for panel in self.query(QuestionPanel):
            panel.mark_chosen(answer.option if answer else None)

    def _reword(self, view: PatientView, item: Item) -> bool:
        """Put ``item`` into the panel on screen when it has as many answers (no remount); False
        when it cannot, so the caller builds a new panel."""
        answer = view.snapshot.answers.get(item.id)
        labels, buttons = self._answers(view, item)
        for panel in self.query(QuestionPanel):
            if panel.show_item(
                item.patient_text_in(self.language),
                labels,
                chosen=answer.option if answer else None,
                buttons=buttons,
            ):
                self._item_id = item.id
                if isinstance(self.focused, AnswerButton):  # it would look chosen on the new item
                    self.set_focus(None)
                return True
        return False
