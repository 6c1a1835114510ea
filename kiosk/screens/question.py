"""A Barthel question: large text, big numbered answers, progress, attempt and controls."""

from __future__ import annotations

from collections.abc import Hashable

from textual.app import ComposeResult

from kiosk.screens.base import PatientScreen, PatientView
from kiosk.widgets.bars import ControlBar
from kiosk.widgets.question_panel import QuestionPanel
from kiosk.widgets.text import ui_text


class QuestionScreen(PatientScreen):
    """One scored item. Touching an answer posts ``AnswerButton.Chosen``; the app forwards it."""

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """A new screen per item and language."""
        snap = view.snapshot
        return (snap.item.id if snap.item else None, snap.language)

    def compose(self) -> ComposeResult:
        """Bars, the question with its answers, and the controls."""
        yield from self.compose_bars()
        item = self.view.snapshot.item
        if item is not None:
            answer = self.view.snapshot.answers.get(item.id)
            yield QuestionPanel(item.text[self.language], [o.label_in(self.language) for o in item.options],
                                chosen=answer.option if answer else None)
        yield ControlBar(self.language)

    def show(self, view: PatientView) -> None:
        """Also mark the recorded answer once there is one."""
        super().show(view)
        item = view.snapshot.item
        answer = view.snapshot.answers.get(item.id) if item else None
        for panel in self.query(QuestionPanel):
            panel.mark_chosen(answer.option if answer else None)

    def progress_text(self, view: PatientView) -> str:
        """"Question 3 of 10"."""
        snap = view.snapshot
        if snap.number is None:
            return super().progress_text(view)
        return ui_text(self.language, "question_of", number=snap.number, total=snap.count)
