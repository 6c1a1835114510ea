"""The clinician's first screen: the running session (continue it, adaptation on/off, patient left or
back), the channel states with their reasons, the interrupted tests staff may continue, and the
list of stored sessions. It scrolls (wheel, Tab, or the Up/Down buttons for a finger on the
touch display), with "Back to the patient" always at the bottom."""

from __future__ import annotations

from typing import Any

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, VerticalScroll
from textual.widgets import DataTable, Switch

from kiosk.core.channels import ChannelState
from kiosk.core.room import STAFF_NOTICE
from kiosk.core.session import Phase
from kiosk.core.visits import TUG
from kiosk.export.captured import questionnaire_of, result_line
from kiosk.store.records import SessionSummary
from kiosk.ui.screens.base import ClinicianScreen, staff_nav
from kiosk.ui.widgets.channel_board import CAMERA
from kiosk.ui.widgets.literal import Button, Label, Static, cell

#: how often the running session's line is redrawn (seconds)
REFRESH_S = 1.0


#: a visit whose battery has the Timed Up and Go, on a kiosk that cannot time it (issue 34)
_TUG_BY_STOPWATCH = "; this visit's Timed Up and Go: no camera, so a stopwatch time or a skip"


def _has_tug(place: object) -> bool:
    return TUG in getattr(place, "instruments", ())


class ClinicianHomeScreen(ClinicianScreen):
    """Reads the app's session and store; every action goes back through the app."""

    #: the session list has the keys: arrows pick a session, Enter opens it
    AUTO_FOCUS = "#sessions"

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        #: (session, answered, not answered, status) -> its result line
        self._results: dict[tuple[str, int, int, str], str] = {}

    def compose(self) -> ComposeResult:
        """The running session, channels, stored sessions, and the way back."""
        app = self.kiosk
        session = app.session
        with VerticalScroll(classes="clinician staff-body", id="clinician-body"):
            yield Static("Clinician", classes="heading")
            if (warning := app.pin_guard.warning) is not None:
                yield Static(warning, id="pin-warning")
            yield Static("", id="out-of-order-reason")
            yield Static(self._session_line(), id="current")
            with Horizontal(id="current-actions"):
                yield Button("Continue", id="continue", variant="primary")
                yield Label("Adaptation", id="adaptation-label")
                yield Switch(
                    value=session.adaptation is not None and session.adaptation.enabled,
                    id="adaptation",
                    disabled=session.adaptation is None,
                )
                yield Button("New patient", id="new-session", disabled=not app.controller.can_start_new_session)
                yield Button("Start a visit", id="start-visit", disabled=app.controller.visits is None)
            # the kiosk has no presence sensor: the clinician says when the patient leaves and returns
            with Horizontal(id="presence-actions"):
                yield Button("Patient left", id="person-lost")
                yield Button("Patient back", id="person-back")
                # the only way out of the locked-down kiosk, on the shorter row so it always shows
                yield Button("Quit the kiosk", id="quit-kiosk", variant="error")
            yield Static(self._channels_text(), id="channel-reasons")
            if app.controller.sync is not None:
                yield Static(self._station_text(), id="station")
            # continuing a test is the staff's decision: only with the same patient at the kiosk
            yield Label("Interrupted tests: none.", id="interrupted-label")
            yield DataTable(id="interrupted", cursor_type="row", zebra_stripes=True)
            with Horizontal(id="interrupted-actions"):
                yield Button("Continue this test", id="continue-test", variant="warning")
                yield Static("", id="continue-result")
            yield Label("Stored sessions (tap one, or Enter, to open):")
            yield DataTable(id="sessions", cursor_type="row", zebra_stripes=True)
        yield from staff_nav()

    def on_mount(self) -> None:
        """Fill the tables, and keep the running session's line current while it runs."""
        interrupted = self.query_one("#interrupted", DataTable)
        interrupted.add_columns("patient", "started", "progress", "why it stopped", "session")
        for test in self.kiosk.controller.interrupted_tests():
            count = len(questionnaire_of(test, fallback=self.kiosk.questionnaire).items)
            progress = f"{len(test.answers)} of {count} answered" + (
                f", {len(test.not_answered)} not answered" if test.not_answered else ""
            )
            started = test.started_at[:16].replace("T", " ")
            row = (test.patient_id, started, progress, test.interrupted_reason or "", test.id)
            interrupted.add_row(*map(cell, row), key=test.id)
        # "Continue this test" only when there is one to continue
        some = bool(interrupted.row_count)
        interrupted.display = some
        self.query_one("#interrupted-actions").display = some
        if some:
            self.query_one("#interrupted-label", Label).update(
                "Interrupted tests (continue one only with that patient in front of the kiosk):"
            )
        table = self.query_one("#sessions", DataTable)
        table.add_columns(
            "session", "patient", "started", "status", "result", "lang", "answered", "not answered", "instrument"
        )
        self._fill_sessions()
        self.refresh_session()
        self.set_interval(REFRESH_S, self.refresh_session)

    def on_screen_resume(self) -> None:
        """Back from a session's detail, where staff may have entered its staff items: every
        result is read again, and the list shows it at once rather than at the next refresh."""
        self._results.clear()
        self._fill_sessions()

    def _result(self, s: SessionSummary) -> str:
        """A session's result line, read from the store only when its answers or status changed."""
        if s.status == "running":
            return "in progress: no total yet"
        key = (s.id, s.answered, s.not_answered, s.status)
        store = self.kiosk.controller.store
        if key not in self._results and store is not None:
            self._results[key] = result_line(store.session(s.id))
        return self._results.get(key, "")

    def _fill_sessions(self) -> None:
        table = self.query_one("#sessions", DataTable)
        store = self.kiosk.controller.store
        for s in store.sessions() if store is not None else []:
            row = (
                *(s.id, s.patient_id, s.started_at[:19], s.label, self._result(s), s.language),
                *(str(s.answered), str(s.not_answered), s.questionnaire_id),
            )
            if s.id in table.rows:
                for column, value in zip(table.columns, row):
                    table.update_cell(s.id, column, cell(value))
            else:
                table.add_row(*map(cell, row), key=s.id)

    def refresh_session(self) -> None:
        """Redraw what a running session changes: its line, the channels, which actions apply,
        and the stored sessions' progress."""
        app = self.kiosk
        session = app.session
        self.query_one("#current", Static).update(self._session_line())
        reason = app.controller.out_of_order
        line = self.query_one("#out-of-order-reason", Static)
        line.display = reason is not None
        if reason is not None:
            remedy = (
                "the display is large enough again"
                if app.controller.store_fault is None
                else "the data directory can be written again (free disk space)"
            )
            line.update(
                f'Out of order: {reason}. The patient sees "This kiosk is not working"; the welcome '
                f"comes back by itself once {remedy}."
            )
        self.query_one("#channel-reasons", Static).update(self._channels_text())
        # Continue is for a session halted by call-doctor or paused by the patient, not for the
        # pause that opening these screens made (leaving them resumes that one)
        paused_by_patient = session.paused and not app.controller.held_for_clinician
        self.query_one("#continue", Button).disabled = not (session.halted or paused_by_patient)
        running = session.phase not in (Phase.WELCOME, Phase.SUMMARY)
        present = session.snapshot().person_present
        self.query_one("#person-lost", Button).disabled = not (running and present)
        self.query_one("#person-back", Button).disabled = not (running and not present)
        self._fill_sessions()

    def _session_line(self) -> str:
        session = self.kiosk.session
        state = (
            "waiting for a clinician (doctor called)"
            if session.halted
            else (
                "paused while you are here"
                if self.kiosk.controller.held_for_clinician
                else "paused"
                if session.paused
                else session.phase.value
            )
        )
        if not session.snapshot().person_present:
            state += ", patient away"
        line = (
            f"This kiosk: session {session.id}, patient {session.patient_id}, {state}, "
            f"{len(session.answers)} of {len(session.questionnaire.items)} answered."
        )
        if "voice_room" in session.snapshot().adaptations:
            line += f" {STAFF_NOTICE}."
        if session.metrics:
            line += " QoS now: " + ", ".join(f"{name} {value:.2f}" for name, value in session.metrics.items())
        return line

    def _station_text(self) -> str:
        sync, store = self.kiosk.controller.sync, self.kiosk.controller.store
        if sync is None or store is None:  # shown only with a station, which needs a store
            return "No ward station."
        waiting, parked = store.outbox_waiting()
        state = f"not reachable ({sync.problem})" if sync.problem else "reachable"
        text = f"Ward station {sync.station.url}: {state}; {waiting} stored changes waiting to be sent"
        text += (f", {parked} refused by the station (kept for an engineer)" if parked else "") + "."
        visits = self.kiosk.controller.visits
        if visits is not None and visits.problems:  # ordered visits this kiosk cannot run (kiosk.core.visits)
            text += " Orders this kiosk cannot run: " + "; ".join(visits.problems) + "."
        return text

    def _channels_text(self) -> str:
        lines = self.kiosk.board.lines("en", patient=False)
        state, reason = self.kiosk.board.state(CAMERA)
        camera = (
            "camera on" if state is ChannelState.ON else f"camera {state.value}" + (f" ({reason})" if reason else "")
        )
        return (
            "Channels: "
            + "; ".join(
                f"{line.name} {line.state}" + (f" ({line.reason})" if line.reason and not line.live else "")
                for line in lines
            )
            + f"; {camera}"
            + (_TUG_BY_STOPWATCH if state is not ChannelState.ON and _has_tug(self.kiosk.session.battery) else "")
        )

    @on(Button.Pressed, "#continue")
    def _continue(self) -> None:
        self.kiosk.controller.clinician_continue()
        self.kiosk.close_clinician()

    @on(Button.Pressed, "#person-lost")
    def _person_lost(self) -> None:
        self.kiosk.controller.person_lost()
        self.kiosk.close_clinician()

    @on(Button.Pressed, "#person-back")
    def _person_back(self) -> None:
        self.kiosk.controller.person_back()
        self.kiosk.close_clinician()

    @on(Button.Pressed, "#continue-test")
    def _continue_test(self) -> None:
        table = self.query_one("#interrupted", DataTable)
        if not table.row_count:
            return
        row_key, _ = table.coordinate_to_cell_key(table.cursor_coordinate)
        refused = self.kiosk.controller.continue_test(str(row_key.value))
        if refused:
            self.query_one("#continue-result", Static).update(f"Not continued: {refused}")

    @on(Button.Pressed, "#new-session")
    def _new_session(self) -> None:
        self.kiosk.controller.start_new_session()

    @on(Button.Pressed, "#start-visit")
    def _start_visit(self) -> None:
        from kiosk.ui.screens.start_visit import StartVisitScreen

        self.app.push_screen(StartVisitScreen())

    @on(Button.Pressed, "#back")
    def _back(self) -> None:
        self.kiosk.close_clinician()

    @on(Button.Pressed, "#quit-kiosk")
    def _quit(self) -> None:
        self.kiosk.quit_kiosk()

    @on(Switch.Changed, "#adaptation")
    def _adaptation(self, event: Switch.Changed) -> None:
        self.kiosk.controller.set_adaptation(event.value)

    @on(DataTable.RowSelected, "#sessions")
    def _open(self, event: DataTable.RowSelected) -> None:
        store = self.kiosk.controller.store
        if store is None:  # without a store the table has no rows to select
            return
        stored = store.session(str(event.row_key.value))
        # the detail's plot (plotext) and exports load when staff first open one, not at start-up
        from kiosk.ui.screens.session_detail import SessionDetailScreen

        self.app.push_screen(SessionDetailScreen(stored))

    def action_close(self) -> None:
        """Escape from here goes back to the patient."""
        self.kiosk.close_clinician()
