"""Staff's side of a visit's Timed Up and Go (issue 34), behind the PIN: the set-up with a live
preview of the landmarks (a stick figure in text, never a picture, never stored) and the
whole-body check at the chair and at the 3 m line, staff's confirmation that they are beside the
patient, then the result: accept the camera's time, enter a stopwatch time instead, or reject it,
with the Get Up & Go rating and the walking aid. Without a camera it says so and offers the
stopwatch only, or a skip with a stated reason. Logic is the TUG desk's (:mod:`kiosk.ui.tug_desk`)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable

from textual import on
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.css.query import NoMatches
from textual.widgets import Input

from kiosk.core.tug.step import GET_UP_GO, WALKING_AIDS, TugStage, TugStepError
from kiosk.core.tug.visit import SPOTS
from kiosk.ui.screens.base import ClinicianScreen, staff_nav
from kiosk.ui.tug_desk import TugDesk
from kiosk.ui.widgets.literal import Button, Label, Static
from kiosk.ui.widgets.stick_figure import stick_figure

_SPOT_NAMES = {"chair": "at the chair", "line": "at the 3 m line"}


class TugStaffScreen(ClinicianScreen):
    """The set-up and the decision of the TUG under way (sections shown by its stage)."""

    DEFAULT_CSS = """
    TugStaffScreen Horizontal, TugStaffScreen Vertical { height: auto; }
    TugStaffScreen #tug-preview { width: auto; height: auto; }
    TugStaffScreen #tug-message { color: #a4161a; }
    TugStaffScreen Input { width: 24; }
    """
    AUTO_FOCUS = ""

    def __init__(self, desk: TugDesk) -> None:
        super().__init__()
        self.desk = desk
        self._rating: int | None = None
        self._aid: str | None = None

    def compose(self) -> ComposeResult:
        with VerticalScroll(classes="staff-body"):
            yield Static("Timed Up and Go", classes="heading", id="tug-heading")
            yield Label("", id="tug-camera")
            with Vertical(id="tug-setup"):
                with Horizontal():
                    yield Static("", id="tug-preview")
                    with Vertical():
                        yield Label("", id="tug-framing")
                        for spot in SPOTS:
                            yield Button(f"Check the whole body {_SPOT_NAMES[spot]}", id=f"tug-check-{spot}")
                        yield Label("", id="tug-checks")
                with Horizontal():
                    yield Input(placeholder="staff name or code", id="tug-staff")
                    yield Button("I am beside the patient: confirm", id="tug-confirm", variant="success")
                with Horizontal():
                    yield Input(placeholder="why skip it", id="tug-skip-reason")
                    yield Button("Skip the test", id="tug-skip", variant="error")
            with Vertical(id="tug-decision"):
                yield Static("", id="tug-result")
                with Horizontal():
                    yield Label("Get Up & Go (1 normal .. 5 severely abnormal):")
                    for rating in GET_UP_GO:
                        yield Button(str(rating), id=f"tug-rating-{rating}")
                with Horizontal():
                    yield Label("Walking aid:")
                    for aid in WALKING_AIDS:
                        yield Button(aid, id=f"tug-aid-{aid}")
                yield Label("", id="tug-items")
                with Horizontal():
                    yield Input(placeholder="staff name or code", id="tug-decided-by")
                    yield Input(placeholder="stopwatch seconds", id="tug-stopwatch")
                with Horizontal():
                    yield Button("Accept the camera's time", id="tug-accept", variant="success")
                    yield Button("Use the stopwatch time", id="tug-use-stopwatch", variant="primary")
                    yield Button("Reject", id="tug-reject", variant="error")
            yield Label("", id="tug-message")
        yield from staff_nav()

    def on_mount(self) -> None:
        self.tick()

    def tick(self) -> None:
        """Redraw what changes (the app calls it at every poll); nothing while the screen goes."""
        with contextlib.suppress(NoMatches):  # composed not yet, or being taken down
            self._tick()

    def _tick(self) -> None:
        """Redraw the live preview, the checks and the stage (the app calls it at every poll)."""
        run = self.desk.run
        if run is None or not self.query("#tug-heading"):  # gone, or not composed yet
            return
        number, count = run.part
        self.query_one("#tug-heading", Static).update(f"Timed Up and Go: part {number} of {count} of the visit")
        self.query_one("#tug-camera", Label).update(
            "Timed by the camera (landmarks only; no picture is kept)."
            if run.timed_by_camera
            else f"Camera off ({run.camera_off}): time the test with a stopwatch, or skip it."
        )
        stage = run.stage
        self.query_one("#tug-setup").display = stage is TugStage.SETUP
        self.query_one("#tug-decision").display = stage is TugStage.ANALYSED
        if stage is TugStage.SETUP:
            if run.timed_by_camera:
                self.query_one("#tug-preview", Static).update(stick_figure(run.step.last_landmarks, 20, 10))
                self.query_one("#tug-framing", Label).update(
                    "Live: the whole body is in the picture" if not run.framing else f"Live: {run.framing}"
                )
            else:
                self.query_one("#tug-preview", Static).update("")
                self.query_one("#tug-framing", Label).update("No preview: no camera.")
            for spot in SPOTS:
                self.query_one(f"#tug-check-{spot}", Button).display = run.timed_by_camera
            checks = [
                f"{_SPOT_NAMES[s]}: " + ("not checked" if s not in run.checked else run.checked[s] or "whole body seen")
                for s in SPOTS
            ]
            self.query_one("#tug-checks", Label).update("; ".join(checks) if run.timed_by_camera else "")
        elif stage is TugStage.ANALYSED:
            self.query_one("#tug-result", Static).update(self._result_text())
            self.query_one("#tug-accept", Button).display = bool(
                run.timed_by_camera and run.step.analysis is not None and run.step.analysis.valid
            )
            self.query_one("#tug-items", Label).update(
                f"Rating: {self._rating or 'not given'}; walking aid: {self._aid or 'not given'}"
            )

    def _result_text(self) -> str:
        run = self.desk.run
        if run is None or run.step.analysis is None:
            return ""
        analysis, threshold = run.step.analysis, run.step.settings.threshold_s
        if not run.timed_by_camera:
            return "No camera time: enter the stopwatch time, or reject."
        if not analysis.valid or analysis.total_s is None:
            return "The camera gave no valid time: " + "; ".join(analysis.reasons)
        side = "above" if analysis.total_s > threshold else "not above"
        phases = ", ".join(f"{p.name.replace('_', ' ')} {p.duration_s:.1f} s" for p in analysis.phases)
        return f"Camera: {analysis.total_s:.1f} s, {side} the site's threshold ({threshold:g} s). Phases: {phases}."

    # -- staff's actions ------------------------------------------------------------------------

    def _value(self, selector: str) -> str:
        return self.query_one(selector, Input).value.strip()

    def _act(self, action: Callable[[], object], done: bool = False) -> None:
        try:
            action()
        except (TugStepError, ValueError) as refused:
            self.query_one("#tug-message", Label).update(str(refused))
            return
        self.query_one("#tug-message", Label).update("")
        if done:
            self.kiosk.close_clinician()
        else:
            self.tick()

    @on(Button.Pressed)
    def _pressed(self, event: Button.Pressed) -> None:
        button = event.button.id or ""
        run = self.desk.run
        if button == "back":
            event.stop()
            self.kiosk.close_clinician()
        if not button.startswith("tug-") or run is None:
            return
        event.stop()
        if button.startswith("tug-check-"):
            self._act(lambda: run.check_spot(button.removeprefix("tug-check-")))
        elif button == "tug-confirm":
            self._act(lambda: self.desk.confirm(self._value("#tug-staff")), done=True)
        elif button == "tug-skip":
            self._act(lambda: self.desk.skip(self._value("#tug-staff"), self._value("#tug-skip-reason")), done=True)
        elif button.startswith("tug-rating-"):
            self._rating = int(button.removeprefix("tug-rating-"))
            self.tick()
        elif button.startswith("tug-aid-"):
            self._aid = button.removeprefix("tug-aid-")
            self.tick()
        elif button in ("tug-accept", "tug-use-stopwatch", "tug-reject"):
            self._act(lambda: self._decide(button), done=True)

    def _decide(self, button: str) -> None:
        decision = {"tug-accept": "accepted", "tug-use-stopwatch": "stopwatch", "tug-reject": "rejected"}[button]
        stopwatch = None
        if decision == "stopwatch":
            try:
                stopwatch = float(self._value("#tug-stopwatch").replace(",", "."))
            except ValueError:
                raise ValueError("the stopwatch time: a number of seconds, such as 12.4") from None
        by = self._value("#tug-decided-by")
        self.desk.decide(decision, by, stopwatch_s=stopwatch, get_up_go=self._rating, walking_aid=self._aid)
