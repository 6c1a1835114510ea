"""Shall I call the nurse? Asked over the phase's screen when a call was heard by voice, before
it is made (kiosk.core.session.calls)."""

from __future__ import annotations

from textual.app import ComposeResult

from kiosk.core.session.words import CONFIRM_WORDS
from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.confirm_panel import ConfirmPanel


class CallConfirmScreen(PatientScreen):
    """The question and two big replies, Yes (1) and No (2): touched, pressed on the keys or the
    remote, or said. The doctor's key (D) still calls at once. No attempt count: the question under
    it waits, its clock stopped."""

    SHOWS_ATTEMPT = False

    def compose(self) -> ComposeResult:
        """Bars, then the question with Yes and No."""
        yield from self.compose_bars()
        words = CONFIRM_WORDS.get(self.language, CONFIRM_WORDS["en"])
        yield ConfirmPanel(self.view.snapshot.calling or "", [label for label, _ in words.values()])

    def show(self, view: PatientView) -> None:
        """Put the question as asked now ("Please press Yes or No" once a spoken yes was unsure)."""
        super().show(view)
        for panel in self.query(ConfirmPanel):
            panel.ask(view.snapshot.calling or "")
