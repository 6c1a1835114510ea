"""One stored session for the clinician: per-item answers, total, band, completeness, the QoS
metrics over time, and exports (FHIR JSON, CSV, the plot as PNG)."""

from __future__ import annotations

import sqlite3
from pathlib import Path

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.widgets import DataTable

from kiosk.core.questionnaire import result_words
from kiosk.core.staff import entered_values, number_text
from kiosk.export import ExportError, csv_text, fhir_response, practice_outcomes, rescore, write_json, write_private
from kiosk.export.captured import questionnaire_of, site_of
from kiosk.store.database import StoredSession
from kiosk.store.lease import SessionTaken
from kiosk.ui.screens.base import ClinicianScreen, staff_nav
from kiosk.ui.widgets.literal import Button, Label, Static, cell
from kiosk.ui.widgets.metrics_plot import MetricsPlot, metrics_key, plot_data, save_png
from kiosk.ui.widgets.staff_items import StaffItems

#: the session log's entries staff see as events, in their words
EVENT_WORDS = {
    "call_doctor": "Doctor called",
    "doctor_call_cancelled": '"I\'m fine, carry on" (the patient called the doctor off)',
    "clinician_continue": "Continued by a clinician",
    "pause": "Paused",
    "resume": "Continued after a pause",
    "person_lost": "Patient left the kiosk",
    "person_back": "Patient back",
    "away_alert": "Ward alerted: patient away (seconds)",
    "unattended": "Ward alerted: no answer (questions in a row); waited for a touch",
    "unattended_ended": "Touched to go on",
    "continue_waits_for_touch": "Continue from staff: waited for the patient's touch",
    "answer_withdrawn": "Answer taken back",
    "abandoned": "Ended by staff",
}


def session_events(stored: StoredSession) -> list[tuple[str, str]]:
    """The events of ``stored`` staff read on its page: (time into the session, what happened)."""
    rows = []
    for entry in stored.log:
        if (words := EVENT_WORDS.get(entry.kind)) is not None:
            detail = f" ({entry.detail})" if entry.detail and entry.kind != "doctor_call_cancelled" else ""
            rows.append((f"{entry.t:.0f} s", words + detail))
    return rows


class SessionDetailScreen(ClinicianScreen):
    """The answers table, the events, the metrics plot, scrolling; exports and the way back at the
    bottom."""

    def __init__(self, stored: StoredSession) -> None:
        """Show ``stored`` (read from the store when the clinician opened it)."""
        super().__init__()
        self.stored = stored

    def compose(self) -> ComposeResult:
        """Header, answers, total line, plot and export buttons."""
        s = self.stored
        # at the bottom, above the buttons, so an export's outcome shows at every size
        with Vertical(id="detail-bottom"):
            yield Label("", id="export-result")
            with Horizontal(id="detail-actions"):
                yield Button("FHIR", id="export-fhir", tooltip="Export a FHIR QuestionnaireResponse")
                yield Button("CSV", id="export-csv", tooltip="Export the answers as CSV")
                yield Button("Plot PNG", id="export-png", tooltip="Save the QoS plot as a PNG")
            yield from staff_nav("Back")
        with VerticalScroll(classes="clinician staff-body", id="detail-body"):
            yield Static(
                f"Session {s.id}  {self._title()}  patient {s.patient_id}  {s.status}  language {s.language}  "
                f"answered by {s.answered_by.value}",
                classes="heading",
            )
            yield DataTable(id="answers-table", zebra_stripes=True, cursor_type="row")
            yield Label(self._total_line(), id="total")
            if staff := [item for item in self.q.items if item.staff]:
                answers = {a.item_id: a.option for a in s.answers}
                yield StaffItems(staff, s.language, answers, entered_values(self.q, s.log))
            yield Label(self._practice_line(), id="practice")
            events = session_events(s)
            yield Label(
                "Events:" if events else "Events: none (no doctor call, pause or patient away).", id="events-label"
            )
            table: DataTable[str] = DataTable(id="events", zebra_stripes=True, cursor_type="row")
            table.display = bool(events)
            yield table
            yield Static(metrics_key(), id="metrics-key")
            yield MetricsPlot(plot_data(s), id="metrics-plot")

    @property
    def q(self):  # -> Questionnaire
        """The questionnaire this session ran (captured as it started), not today's file."""
        return questionnaire_of(self.stored, fallback=self.kiosk.questionnaire)

    def on_mount(self) -> None:
        """One row per item, in questionnaire order, answered or not."""
        events = self.query_one("#events", DataTable)
        events.add_columns("when", "what")
        for when, what in session_events(self.stored):
            events.add_row(cell(when), cell(what))
        q = self.q
        table = self.query_one("#answers-table", DataTable)
        table.add_columns("#", "item", "option", "answer", "points", "attempt", "channel")
        answers = {a.item_id: a for a in self.stored.answers}
        values = entered_values(q, self.stored.log)
        for item in q.items:
            a = answers.get(item.id)
            if a is None and item.id in values and item.entry is not None:
                entered = f"{number_text(values[item.id])} {item.entry.unit}".strip()
                table.add_row(*map(cell, (item.number, item.id, "", entered, "", "", "staff")))
            elif a is None:
                outcome = "not answered" if item.id in self.stored.not_answered else "-"
                table.add_row(*map(cell, (item.number, item.id, "", outcome, "", "", "")))
            else:
                label = item.option(a.option).label_in(self.stored.language)
                row = (item.number, item.id, a.option, label, a.points, a.attempt, a.channel.value)
                table.add_row(*map(cell, row))

    def _title(self) -> str:
        """The instrument's own title (the session's captured one), so no line assumes the Barthel."""
        title = self.q.title
        return title.get(self.stored.language) or title.get("en") or self.q.id

    def _total_line(self) -> str:
        q = self.q
        try:
            score = rescore(q, self.stored)
        except ExportError as error:
            return f"Cannot score: {error}"
        if not score.complete:  # a partial sum is no total: never shown as one
            patient_missing = set(score.missing) - set(score.awaiting_staff)
            partial = f" (the answered ones add up to {score.total})" if patient_missing and not score.problem else ""
            return result_words(q, score) + partial
        band = score.band.label["en"] if score.band else "no band"
        return f"Total {score.total} of {score.max_total} (complete); {band}"

    def _practice_line(self) -> str:
        """How the familiarisation went: "Practice: hearing skipped (no voice out) / reading ✓"."""
        if not self.stored.practice:
            return "Practice: none (no practice questions in this session)"
        q = self.q
        parts = []
        for outcome in practice_outcomes(q, self.stored):
            if outcome.outcome == "right":
                parts.append(f"{outcome.what} ✓")
            elif outcome.outcome == "wrong":
                parts.append(f"{outcome.what} ✗ ({outcome.detail})")
            elif outcome.outcome == "not answered":
                parts.append(f"{outcome.what} ✗ (no answer)")
            else:
                parts.append(f"{outcome.what} {outcome.result}")
        return "Practice: " + " / ".join(parts)

    def _export_path(self, suffix: str) -> Path:
        folder = self.kiosk.export_dir
        if folder is None:  # make_kiosk always gives one; an app built by hand may not
            raise RuntimeError("this kiosk was built without an export folder")
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        return folder / f"session-{self.stored.id}{suffix}"

    def _done(self, text: str) -> None:
        result = self.query_one("#export-result", Label)
        result.update(text)
        result.display = True  # hidden until there is something to say: the plot needs the row

    @on(Button.Pressed, "#export-fhir")
    def _fhir(self) -> None:
        try:
            path = self._export_path(".fhir.json")
            write_json(path, fhir_response(self.q, self.stored, site=site_of(self.stored)))
        except (ExportError, OSError) as error:
            self._done(f"FHIR export failed: {error}")
            return
        self._done(f"FHIR QuestionnaireResponse written to {path}")

    @on(Button.Pressed, "#export-csv")
    def _csv(self) -> None:
        try:
            path = self._export_path(".csv")
            write_private(path, csv_text(self.q, [self.stored], site=site_of(self.stored)))
        except (ExportError, OSError) as error:
            self._done(f"CSV export failed: {error}")
            return
        self._done(f"CSV written to {path}")

    @on(Button.Pressed, "#export-png")
    def _png(self) -> None:
        try:
            path = save_png(
                plot_data(self.stored),
                self._export_path(".metrics.png"),
                f"{self._title()}: session {self.stored.id}, patient {self.stored.patient_id}",
            )
        except OSError as error:
            self._done(f"Saving the plot failed: {error}")
            return
        self._done(f"Plot saved to {path}")

    @on(StaffItems.Entered)
    def _staff_entered(self, event: StaffItems.Entered) -> None:
        """Store what staff entered (audited in the session's log), then show the session again."""
        event.stop()
        store = self.app.controller.store  # type: ignore[attr-defined]  # self.app is typed as Textual's App; it is the KioskApp
        item = self.q.item(event.item_id)
        points = item.option(event.option).points if event.option is not None else None
        try:
            store.record_staff_answer(
                self.stored.id, item_id=item.id, option=event.option, points=points, value=event.value, by="kiosk staff"
            )
        except (SessionTaken, KeyError, sqlite3.Error) as error:
            self._done(f"{item.id} was not saved: {error}")
            return
        self.app.switch_screen(SessionDetailScreen(store.session(self.stored.id)))

    @on(Button.Pressed, "#back")
    def _back(self) -> None:
        self.dismiss()
