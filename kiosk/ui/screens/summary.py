"""The end: "Thank you, you are done. Please call the nurse." The total and band the session
recomputed are shown to the patient only where the site chose so (``show_score_to_patient``); the
kiosk goes back to the welcome for the next patient after ``next_patient_after_s``."""

from __future__ import annotations

from textual.app import ComposeResult

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.literal import Static
from kiosk.ui.widgets.text import ui_text


class SummaryScreen(PatientScreen):
    """Thank-you and what to do now; if the site shows it, the total out of the maximum, the band,
    and how many items went unanswered. No notices once it is over: what the kiosk adapted no
    longer concerns the patient."""

    NOTICES = False

    def progress_text(self, view: PatientView) -> str:
        """The title the patient saw all along (the plain one: "Questions about how you feel",
        never the clinical "Geriatric Depression Scale"): the questions are over."""
        return view.questionnaire.title_for_patient(self.language)

    def compose(self) -> ComposeResult:
        """Bars, thanks, the total and band."""
        yield from self.compose_bars()
        yield Static(ui_text(self.language, "summary_title"), classes="heading")
        yield Static(
            self.view.questionnaire.message("finished", self.language) or ui_text(self.language, "summary_text"),
            classes="notice",
        )
        score = self.view.snapshot.score
        if score is not None and self.view.show_score:  # a site's choice; staff always see it
            if score.missing:  # a partial sum is no total: the patient is not shown one
                lines = [ui_text(self.language, "summary_incomplete", missing=len(score.missing))]
            else:
                lines = [ui_text(self.language, "summary_total", total=score.total, maximum=score.max_total)]
                if score.band is not None:
                    lines.append(score.band.label[self.language])
            yield Static("\n".join(lines), id="summary-total")
