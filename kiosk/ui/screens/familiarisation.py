"""Familiarisation: practice questions checking the patient can hear, read and choose."""

from __future__ import annotations

from collections.abc import Hashable

from textual.app import ComposeResult

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.bars import ControlBar
from kiosk.ui.widgets.literal import Static
from kiosk.ui.widgets.question_panel import QuestionPanel
from kiosk.ui.widgets.text import ui_text
from kiosk.ui.widgets.waiting_sign import WaitingSign


class FamiliarisationScreen(PatientScreen):
    """A practice question laid out exactly like a real one, so the real ones feel familiar."""

    ASKS = True

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """A new screen per practice question and language."""
        practice = view.snapshot.practice
        return (practice.id if practice else None, view.snapshot.language)

    def compose(self) -> ComposeResult:
        """Bars, the introduction or the kind word after an answer, the practice question with its
        answers (or the introduction alone), the waiting sign and the controls."""
        yield from self.compose_bars()
        practice = self.view.snapshot.practice
        if practice is None:
            yield Static(self._intro(self.view), classes="heading", id="practice-intro")
        else:
            # in the flow above the question, as on the question screen
            yield Static("", id="interlude", classes="interlude")
            yield QuestionPanel(
                practice.text[self.language],
                [o.label_in(self.language) for o in practice.options],
                turn=(ui_text(self.language, "more_answers"), ui_text(self.language, "back_answers")),
            )
        yield WaitingSign(self.language)
        yield ControlBar(self.language, repeat=self.view.ways.voice_out)

    def show(self, view: PatientView) -> None:
        """Also the line above the question: "First, a few practice questions…" on the first one,
        and the kind word ("Well done.") once it is answered, until the next one opens."""
        super().show(view)
        for bar in self.query(ControlBar):  # Repeat only while the kiosk can speak
            bar.show_repeat(view.ways.voice_out)
        snap = view.snapshot
        feedback = view.questionnaire.message(snap.interlude, self.language) if snap.interlude else ""
        intro = self._intro(view) if snap.practice_number == 1 else ""
        for line in self.query("#interlude").results(Static):
            line.update(feedback or intro)
            line.display = bool(feedback or intro)
        for heading in self.query("#practice-intro").results(Static):
            heading.update(self._intro(view))
        for panel in self.query(QuestionPanel):  # the answer given stays marked, as on a question
            panel.mark_chosen(snap.practice_chosen)

    def _intro(self, view: PatientView) -> str:
        """ "First, a few practice questions…": the questionnaire's words, which promise a hearing
        check, only while the kiosk can speak; without voice out the kiosk's own words, which do not
        (the hearing check is skipped then)."""
        if view.ways.voice_out:
            return view.questionnaire.message("familiarisation", self.language)
        return ui_text(self.language, "practice_intro_silent")

    def progress_text(self, view: PatientView) -> str:
        """ "Practice 1 of 3" (of those asked on this kiosk, as the session counts them)."""
        snap = view.snapshot
        if snap.practice_number is None:
            return super().progress_text(view)
        return ui_text(self.language, "practice_of", number=snap.practice_number, total=snap.practice_count)
