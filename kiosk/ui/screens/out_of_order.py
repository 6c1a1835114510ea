"""Out of order: the kiosk cannot store a test (a full disk, a failing drive), so it takes none."""

from __future__ import annotations

from collections.abc import Hashable

from textual.app import ComposeResult
from textual.containers import Vertical

from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.widgets.literal import Static
from kiosk.ui.widgets.text import ui_text


class OutOfOrderScreen(PatientScreen):
    """One calm screen, in every language of the questionnaire: the kiosk is not working, please
    ask the nurse. Nothing on it starts a test, and no notice names anyone; staff read the reason
    on the clinician screen (behind the corner and the PIN, as always) and on the ward station.
    The app puts the welcome back by itself once the kiosk can write again."""

    NOTICES = False
    SHOWS_ATTEMPT = False

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """One screen whatever the session's language."""
        return "out of order"

    def progress_text(self, view: PatientView) -> str:
        """The title in every language, as on the welcome."""
        return " · ".join(dict.fromkeys(view.questionnaire.title.values()))

    def compose(self) -> ComposeResult:
        """Bars, then the two sentences in each language."""
        yield from self.compose_bars()
        with Vertical(id="out-of-order"):
            for language in self.view.questionnaire.languages:
                yield Static(ui_text(language, "out_of_order_title"), classes="heading")
                yield Static(ui_text(language, "out_of_order_text"), classes="notice")
