"""The patient's screen during a visit's Timed Up and Go (issue 34): its place in the visit, the
instructions in the patient's language, the live phase and the seconds since "Go"; staff's Go and
Stop under them. Everything it does goes to the TUG desk (:mod:`kiosk.ui.tug_desk`)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Hashable

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal
from textual.css.query import NoMatches

from kiosk.core.tug.step import TugStage, TugStepError
from kiosk.ui.screens.base import PatientScreen, PatientView
from kiosk.ui.tug_desk import TugDesk
from kiosk.ui.widgets.literal import Button, Label, Static
from kiosk.ui.widgets.text import ui_text


class TugScreen(PatientScreen):
    """Shown while the visit's TUG is under way (instead of the session's screens)."""

    NOTICES = False

    def __init__(self, view: PatientView, desk: TugDesk) -> None:
        super().__init__(view)
        self.desk = desk

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        return (view.snapshot.language, "tug")

    @property
    def language(self) -> str:
        run = self.desk.run
        return run.language if run is not None else self.view.snapshot.language

    def compose(self) -> ComposeResult:
        yield from self.compose_bars()
        yield Static("", classes="heading", id="tug-title")
        yield Static("", classes="heading", id="tug-phase")
        yield Static("", classes="notice", id="tug-instructions")
        yield Label("", id="tug-clock")
        yield Label("", id="tug-staff-note")
        with Horizontal(id="tug-staff-buttons"):
            yield Button("Staff: Go", id="tug-go", classes="big-action")
            yield Button("Staff: Stop", id="tug-stop")

    def progress_text(self, view: PatientView) -> str:
        run = self.desk.run
        return "" if run is None else ui_text(self.language, "tug_part", number=run.part[0], total=run.part[1])

    def show(self, view: PatientView) -> None:
        super().show(view)
        self.tick()

    def tick(self) -> None:
        """Redraw what changes (the app calls it at every poll); nothing while the screen goes."""
        with contextlib.suppress(NoMatches):  # composed not yet, or being taken down
            self._tick()

    def _tick(self) -> None:
        """Redraw what changes as the test goes on (the app calls it at every poll)."""
        run = self.desk.run
        if run is None or not self.query("#tug-title"):  # gone, or not composed yet
            return
        lang, stage = self.language, run.stage
        self.query_one("#tug-title", Static).update(ui_text(lang, "tug_title"))
        phase = ui_text(lang, "tug_wait") if stage is TugStage.SETUP else ui_text(lang, f"tug_phase_{run.live}")
        if stage is TugStage.RUNNING and run.live == "seated" and (run.elapsed() or 0) < 1.5:
            phase = ui_text(lang, "tug_go")
        self.query_one("#tug-phase", Static).update(phase)
        self.query_one("#tug-instructions", Static).update(
            ui_text(lang, "tug_instructions") if stage in (TugStage.READY, TugStage.RUNNING) else ""
        )
        elapsed = run.elapsed()
        running = stage is TugStage.RUNNING
        self.query_one("#tug-clock", Label).update(f"{elapsed:.1f} s" if running and elapsed is not None else "")
        note = {
            TugStage.SETUP: "Staff: set the test up on the clinician screen.",
            TugStage.READY: "Staff: touch Go when the patient sits ready.",
            TugStage.RUNNING: "Staff: touch Stop when the patient is seated again."
            if not run.timed_by_camera
            else "The camera is timing the test. Staff: Stop ends it early.",
            TugStage.ANALYSED: "Staff: record the result on the clinician screen.",
        }.get(stage, "")
        self.query_one("#tug-staff-note", Label).update(note)
        self.query_one("#tug-go", Button).display = stage is TugStage.READY
        self.query_one("#tug-stop", Button).display = running

    @on(Button.Pressed, "#tug-go")
    def _go(self, event: Button.Pressed) -> None:
        event.stop()
        self._act(self.desk.go)

    @on(Button.Pressed, "#tug-stop")
    def _stop(self, event: Button.Pressed) -> None:
        event.stop()
        if self.desk.run is not None:
            self._act(self.desk.run.finish)

    def _act(self, action: Callable[[], object]) -> None:
        try:
            action()
        except TugStepError as refused:
            self.query_one("#tug-staff-note", Label).update(str(refused))
            return
        self.tick()
